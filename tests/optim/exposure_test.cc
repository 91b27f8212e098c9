// Per-view exposure gains (src/optim/parameters.h, render_cache.h "Exposure gains"): their Jacobian
// rows and adjoint gradient against finite differences, the prior, the fit recovering known
// gains of photographs whose exposure was changed, and the config keys.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/optim/config.h"
#include "src/optim/problem.h"
#include "src/optim/reconstruct.h"
#include "src/optim/run_outputs.h"
#include "src/render/render.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// The photographs' true gains per view: view 0 is the gauge (1); the others are changed by
// per-channel factors in [0.7, 1.3], as a camera's auto exposure and white balance would.
const Eigen::Vector3d kTrueGains[] = {
    {1.0, 1.0, 1.0}, {1.25, 0.9, 0.75}, {0.8, 1.15, 1.3}, {0.7, 0.85, 1.1}};

// A textured icosphere seen by 4 cameras at 24², lit by the camera flash, one path segment,
// no gloss: the image is linear in albedo and g ⊙ I bilinear in (albedo, gain), so central
// differences of the image along any direction are exact up to float rounding. `exposed/` holds a
// constant-albedo dataset (below) with view v's photograph multiplied by kTrueGains[v].
class ExposureTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    ASSERT_EQ(testing::SynthIcosphere(
                  dir_->Join("ds"),
                  "--cameras 4 --zooms 1 --res 24 --spp 64 --bounces 1 --shading flat --material "
                  "'{\"procedural\": \"noise\", \"colors\": [[0.8, 0.3, 0.2], [0.2, 0.5, 0.7]], "
                  "\"roughness\": 0.5, \"specular\": 0, \"resolution\": 2}'"),
              "");
    // The fit's dataset: a constant albedo (the texels then agree across views and every view's
    // gains are identifiable from the others) at 32², so that views overlap in many pixels.
    ASSERT_EQ(testing::SynthIcosphere(
                  dir_->Join("exposed"),
                  "--cameras 4 --zooms 1 --res 32 --spp 64 --bounces 1 --shading flat --material "
                  "'{\"albedo\": [0.6, 0.5, 0.4], \"roughness\": 0.5, \"specular\": 0}'"),
              "");
    Dataset exposed;
    ASSERT_TRUE(ReadDataset(dir_->Join("exposed"), &exposed).ok());
    ASSERT_EQ(exposed.views.size(), 4u);
    for (int v = 0; v < 4; ++v) {
      Image image;
      ASSERT_TRUE(LoadViewImage(exposed, v, &image).ok());
      for (size_t i = 0; i < image.data.size(); ++i) {
        image.data[i] *= static_cast<float>(kTrueGains[v][i % 3]);
      }
      ASSERT_TRUE(WriteImage(dir_->Join("exposed/" + exposed.views[v].image), image).ok());
    }
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  void SetUp() override {
    ASSERT_TRUE(ReadDataset(dir_->Join("ds"), &dataset_).ok());
    ASSERT_TRUE(ReadMesh(dir_->Join("ds/gt/mesh.ply"), &mesh_).ok());
    ASSERT_TRUE(LoadMaterial(dir_->Join("ds/gt/material.json"), mesh_, &truth_).ok());
    ASSERT_TRUE(LoadMaterial(R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5,
                                 "resolution": 2})",
                             mesh_, &guess_)
                    .ok());
    options_.cache.render.spp = 8;
    options_.cache.render.bounces = 1;
    options_.cache.pyramid_levels = 3;
  }

  // Parameters with gains for every view (view v's = kTrueGains[v] scaled a little away from
  // them, so that rows are taken at gains ≠ 1) and a cache fitting albedo and exposure.
  void MakeCache(const Material& material) {
    ASSERT_TRUE(MakeDatasetViews(dataset_, &views_).ok());
    MeshToArrays(mesh_, &positions_, &faces_);
    const int num_views = static_cast<int>(dataset_.views.size());
    params_ =
        SceneParameters(positions_, material, static_cast<int>(dataset_.lights.size()), num_views);
    for (int v = 1; v < num_views; ++v) {
      for (int c = 0; c < 3; ++c) params_.values()[params_.GainIndex(v, c)] = kTrueGains[v][c];
    }
    std::vector<int> all(num_views);
    for (int v = 0; v < num_views; ++v) all[v] = v;
    ASSERT_TRUE(RenderCache::Create(dataset_, &views_, all, faces_, material, &params_,
                                    options_.cache, &cache_)
                    .ok());
    ActiveParameters active;
    active.albedo = true;
    active.roughness = false;
    active.exposure = true;
    cache_->SetActive(active);
    cache_->SetSeed(5);
  }

  // A random direction in the albedo texels and the fitted gains.
  std::vector<double> RandomDirection(int seed) const {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> delta(params_.size(), 0.0);
    for (int i = 0; i < params_.size(); ++i) {
      const bool albedo =
          !params_.IsExposure(i) && params_.layout().KindOf(i) == ParameterKind::kAlbedo;
      const bool gain =
          params_.IsExposure(i) && params_.GainFitted((i - params_.ExposureOffset()) / 3);
      if (albedo || gain) delta[i] = u(rng);
    }
    return delta;
  }

  static testing::TempDir* dir_;
  Dataset dataset_;
  TriMesh mesh_;
  Material truth_, guess_;
  ReconstructOptions options_;
  DatasetViews views_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<Eigen::Vector3i> faces_;
  SceneParameters params_;
  std::unique_ptr<RenderCache> cache_;
};

testing::TempDir* ExposureTest::dir_ = nullptr;

// Every level's rows (albedo entries scaled by the gain, plus the gain entries I_c) applied to a
// direction in albedo and gains equal the central difference of that level's image. The gauge
// view has no gain entries.
TEST_F(ExposureTest, RowsMatchFiniteDifferencesOnEveryLevel) {
  MakeCache(guess_);
  const std::vector<double> delta = RandomDirection(11);
  const std::vector<double> x0 = params_.values();
  const double h = 1e-3;
  std::vector<std::vector<Image>> images[2];
  for (int side = 0; side < 2; ++side) {
    for (size_t i = 0; i < x0.size(); ++i) {
      params_.values()[i] = x0[i] + (side == 0 ? h : -h) * delta[i];
    }
    cache_->Render(false);
    images[side].resize(cache_->num_views());
    for (int v = 0; v < cache_->num_views(); ++v) {
      for (int l = 0; l < cache_->num_levels(v); ++l) {
        images[side][v].push_back(cache_->level(v, l).render);
      }
    }
  }
  params_.values() = x0;
  cache_->Render(true);
  for (int v = 0; v < cache_->num_views(); ++v) {
    double err = 0.0, norm = 0.0;
    int gain_entries = 0;
    for (int l = 0; l < cache_->num_levels(v); ++l) {
      const LevelRows& rows = cache_->level(v, l).rows;
      for (int p = 0; p < rows.width * rows.height; ++p) {
        double jd[3] = {0, 0, 0};
        for (uint64_t i = rows.offsets[p]; i < rows.offsets[p + 1]; ++i) {
          const RowEntry& e = rows.entries[i];
          gain_entries += params_.IsExposure(e.param);
          for (int c = 0; c < 3; ++c) jd[c] += e.d[c] * delta[e.param];
        }
        for (int c = 0; c < 3; ++c) {
          const double fd =
              (images[0][v][l].data[3 * p + c] - images[1][v][l].data[3 * p + c]) / (2 * h);
          err += (jd[c] - fd) * (jd[c] - fd);
          norm += fd * fd;
        }
      }
    }
    ASSERT_GT(norm, 0.0) << "view " << v;
    // The image is bilinear in (albedo, gain), so the central difference has no truncation
    // error; what is left is float rounding of the images, ~1e-7 relative over a step of
    // h = 1e-3, i.e. ~1e-4 of the derivative: 1e-3 leaves a margin of 10.
    EXPECT_LT(std::sqrt(err / norm), 1e-3) << "view " << v;
    if (v == kExposureGaugeView) {
      EXPECT_EQ(gain_entries, 0);
    } else {
      EXPECT_GT(gain_entries, 0) << "view " << v;
    }
  }
}

// The adjoint objective's gradient (L-BFGS, Adam; with the exposure prior) against the central
// difference of the cost along albedo and gains; and the trust-region problem's Jᵀr along the
// gains. (The LM rows of the albedo are checked with gains ≠ 1 above, and their problem assembly
// in reconstruct_test.cc: along albedo, Jᵀr also differs from the difference by the Jacobian mass
// the frozen supersets drop, which the residuals of mis-exposed views amplify.)
TEST_F(ExposureTest, GradientsMatchFiniteDifferencesOfTheCost) {
  MakeCache(guess_);
  RegularizerOptions regularizers;
  regularizers.exposure_prior = 0.5;  // large enough to matter in the difference.
  std::vector<Eigen::Vector3d> curvature;
  for (int v = 0; v < cache_->num_views(); ++v) curvature.push_back(cache_->GainCurvature(v));
  ceres::Problem prior_only;
  AddRegularizers(mesh_, cache_->active(), regularizers, ParameterBounds(), guess_, &params_,
                  &prior_only, curvature);
  ASSERT_EQ(prior_only.NumResidualBlocks(), 3);  // views 1..3; the gauge has no prior.
  AdjointObjective objective(cache_.get(), &params_, ParameterBounds(), &prior_only);
  const std::vector<double> x = objective.Current();
  std::vector<double> gradient(x.size());
  double cost = 0.0;
  ASSERT_TRUE(objective.Evaluate(x.data(), &cost, gradient.data()));
  const std::vector<int>& index = objective.active_indices();
  // Central difference of the cost along `full` (flat layout); the cost is a quartic polynomial in
  // the step (squares of the bilinear g ⊙ I, same seed): the truncation error is h²/6 of the
  // third derivative, measured 3.3e-3 relative at h = 1e-2, so ~3e-4 at h = 3e-3; float rounding
  // of the renders perturbs each cost by ~1e-7 of it, i.e. the quotient by ~1e-7·cost/(2h), ~1e-3
  // at h = 1e-3 (measured 1.1e-3), ~4e-4 at 3e-3. 2e-3 bounds their sum with a margin of 3.
  const double h = 3e-3;
  auto difference = [&](const std::vector<double>& full, double* fd, double* directional) {
    double costs[2];
    for (int side = 0; side < 2; ++side) {
      std::vector<double> y = x;
      for (size_t k = 0; k < x.size(); ++k) y[k] += (side == 0 ? h : -h) * full[index[k]];
      ASSERT_TRUE(objective.Evaluate(y.data(), &costs[side], nullptr));
    }
    *fd = (costs[0] - costs[1]) / (2 * h);
    *directional = 0.0;
    for (size_t k = 0; k < x.size(); ++k) *directional += gradient[k] * full[index[k]];
  };
  const std::vector<double> delta = RandomDirection(4);
  double fd = 0.0, directional = 0.0, gain_part = 0.0;
  difference(delta, &fd, &directional);
  for (size_t k = 0; k < x.size(); ++k) {
    if (params_.IsExposure(index[k])) gain_part += gradient[k] * delta[index[k]];
  }
  ASSERT_GT(std::abs(fd), 0.0);
  ASSERT_GT(std::abs(gain_part), 0.05 * std::abs(fd));  // the gains carry a real share.
  EXPECT_NEAR(directional / fd, 1.0, 2e-3);

  // Along the gains only: the adjoint gradient and the problem's Jᵀr (every pixel of a view has
  // its gain entries, so none are dropped).
  std::vector<double> gains_only = delta;
  for (int i = 0; i < params_.size(); ++i) {
    if (!params_.IsExposure(i)) gains_only[i] = 0.0;
  }
  double fd_gains = 0.0, directional_gains = 0.0;
  difference(gains_only, &fd_gains, &directional_gains);
  ASSERT_GT(std::abs(fd_gains), 0.0);
  EXPECT_NEAR(directional_gains / fd_gains, 1.0, 2e-3);

  objective.Store(x.data());
  std::unique_ptr<ReconstructionProblem> problem;
  ProblemOptions problem_options;
  problem_options.superset_renders = 4;
  ASSERT_TRUE(ReconstructionProblem::Build(cache_.get(), &params_, problem_options, &problem).ok());
  AddRegularizers(mesh_, cache_->active(), regularizers, ParameterBounds(), guess_, &params_,
                  problem->problem(), curvature);
  std::vector<double*> blocks;
  problem->problem()->GetParameterBlocks(&blocks);
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  double problem_cost = 0.0;
  std::vector<double> problem_gradient;
  ASSERT_TRUE(
      problem->problem()->Evaluate(evaluate, &problem_cost, nullptr, &problem_gradient, nullptr));
  double problem_directional = 0.0;
  size_t k = 0;
  int gain_blocks = 0;
  for (double* block : blocks) {
    const int offset = static_cast<int>(block - params_.data());
    gain_blocks += params_.IsExposure(offset);
    for (int i = 0; i < problem->problem()->ParameterBlockSize(block); ++i, ++k) {
      problem_directional += problem_gradient[k] * gains_only[offset + i];
    }
  }
  EXPECT_EQ(gain_blocks, 3);  // views 1..3.
  // Pixels with no parameters are left out but constant: the same cost up to them.
  EXPECT_LE(problem_cost, cost * (1 + 1e-9));
  EXPECT_NEAR(problem_directional / fd_gains, 1.0, 2e-3);
}

// Sum of |albedo pass − truth| over the dataset's views (where the texels are seen).
double AlbedoError(const Dataset& dataset, const TriMesh& mesh, const Material& truth,
                   const Material& fitted) {
  DatasetViews views;
  EXPECT_TRUE(MakeDatasetViews(dataset, &views).ok());
  const RenderScene scene(mesh);
  RenderOptions pass;
  pass.pass = RenderPass::kAlbedo;
  pass.spp = 16;
  double err = 0.0;
  for (const ViewSetup& view : views.views) {
    Image a, b;
    RenderView(scene, truth, view, pass, &a);
    RenderView(scene, fitted, view, pass, &b);
    for (size_t i = 0; i < a.data.size(); ++i) {
      if (i % 4 != 3) err += std::abs(a.data[i] - b.data[i]);
    }
  }
  return err;
}

// On photographs whose views 1–3 were re-exposed by known per-channel gains (constant albedo,
// 4 views at 32², grey start): LM with fit_exposure recovers the gains (relative to view 0, the
// gauge, which kept its exposure) and the albedo comes out closer to the truth than without it.
TEST_F(ExposureTest, FitRecoversKnownGains) {
  Dataset exposed;
  ASSERT_TRUE(ReadDataset(dir_->Join("exposed"), &exposed).ok());
  Material truth;
  ASSERT_TRUE(LoadMaterial(dir_->Join("exposed/gt/material.json"), mesh_, &truth).ok());
  options_.phases = PhaseSchedule::kTexture;
  options_.outer_iterations = 3;
  options_.solver.steps = 5;
  // Texels seen by one view alone could absorb any gain of it; the smoothness term (the truth is
  // constant) ties them to texels the other views see. Without it 15 LM steps leave the gains
  // 10–20% off; with it they converge.
  options_.regularizers.albedo_smoothness = 0.1;
  double albedo_error[2];
  for (int fit = 0; fit < 2; ++fit) {
    ReconstructOptions options = options_;
    options.fit_exposure = fit == 1;
    std::unique_ptr<Reconstruction> r;
    ASSERT_TRUE(Reconstruction::Create(exposed, mesh_, guess_, {}, options, &r).ok());
    for (int outer = 0; outer < options.outer_iterations; ++outer) {
      ASSERT_TRUE(r->RunOuter(outer, nullptr).ok());
    }
    albedo_error[fit] = AlbedoError(exposed, mesh_, truth, r->CurrentMaterial());
    const std::vector<Eigen::Vector3d> gains = r->ViewGains();
    ASSERT_EQ(gains.size(), 4u);
    for (int v = 0; v < 4; ++v) {
      for (int c = 0; c < 3; ++c) {
        if (fit == 0 || v == 0) {
          EXPECT_EQ(gains[v][c], 1.0) << "view " << v;
          continue;
        }
        // 8 spp renders of 32² views: the measured errors are 0.7–2.4% (all low: the smoothness
        // and the prior pull a little); 4% leaves room for other seeds.
        EXPECT_NEAR(gains[v][c] / kTrueGains[v][c], 1.0, 0.04)
            << "view " << v << " channel " << c << ": " << gains[v][c];
      }
    }
  }
  EXPECT_LT(albedo_error[1], 0.7 * albedo_error[0])
      << "with " << albedo_error[1] << " without " << albedo_error[0];
}

TEST(ExposureConfigTest, KeysAreCheckedAndNamed) {
  ReconstructOptions options;
  ASSERT_TRUE(
      ApplyReconstructConfig({{"fit_exposure", true}, {"exposure_prior", 3.5}}, "c.json", &options)
          .ok());
  EXPECT_TRUE(options.fit_exposure);
  EXPECT_EQ(options.regularizers.exposure_prior, 3.5);
  EXPECT_EQ(ReconstructConfigJson(options)["fit_exposure"], true);
  Status status = ApplyReconstructConfig({{"fit_exposure", "yes"}}, "c.json", &options);
  EXPECT_THAT(status.message(),
              ::testing::HasSubstr("c.json: fit_exposure: expected true or false"));
  status = ApplyReconstructConfig({{"exposure_prior", -1}}, "c.json", &options);
  EXPECT_THAT(status.message(), ::testing::HasSubstr("c.json: exposure_prior: expected a number"));
  RegularizerOptions regularizers;
  regularizers.exposure_prior = std::nan("");
  std::string why;
  EXPECT_FALSE(regularizers.Check(&why));
  EXPECT_THAT(why, ::testing::HasSubstr("exposure_prior"));
}

// state.json's exposure gains: written, read back, and a malformed entry is refused naming the
// key.
TEST(ExposureStateTest, GainsRoundTripAndBadGainsAreRefused) {
  testing::TempDir tmp;
  RunState state;
  state.run_info = {{"dataset", "ds"}};
  state.view_gains = {{1.0, 1.0, 1.0}, {0.5, 1.25, 2.0}};
  ASSERT_TRUE(WriteRunState(tmp.path(), state).ok());
  RunState read;
  ASSERT_TRUE(ReadRunState(tmp.path(), &read).ok());
  ASSERT_EQ(read.view_gains.size(), 2u);
  EXPECT_EQ(read.view_gains[1], Eigen::Vector3d(0.5, 1.25, 2.0));
  nlohmann::json j = nlohmann::json::parse(testing::ReadTestFile(tmp.Join("state.json")));
  j["exposure_gains"][1] = {0.5, -1.0, 2.0};
  testing::WriteTestFile(tmp.Join("state.json"), j.dump());
  const Status status = ReadRunState(tmp.path(), &read);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("exposure_gains"));
}

}  // namespace
}  // namespace sft

namespace sft {
namespace {

// Peak-1 PSNR of the albedo pass of `fitted` against `truth` over the covered pixels of every
// view of `dataset`.
double AlbedoPsnr(const Dataset& dataset, const TriMesh& mesh, const Material& truth,
                  const Material& fitted) {
  DatasetViews views;
  EXPECT_TRUE(MakeDatasetViews(dataset, &views).ok());
  const RenderScene scene(mesh);
  RenderOptions pass;
  pass.pass = RenderPass::kAlbedo;
  pass.spp = 16;
  double sum = 0.0;
  int64_t count = 0;
  for (const ViewSetup& view : views.views) {
    Image a, b;
    RenderView(scene, truth, view, pass, &a);
    RenderView(scene, fitted, view, pass, &b);
    for (int p = 0; p < a.width * a.height; ++p) {
      if (a.channels == 4 && a.data[4 * p + 3] < 0.999f) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = a.data[a.channels * p + c] - b.data[b.channels * p + c];
        sum += d * d;
        ++count;
      }
    }
  }
  return count > 0 ? PsnrFromMse(sum / count) : 0.0;
}

// The measurement of docs/design-notes.md ("Exposure and white balance"): a noise-textured
// icosphere, 8 views at 64², views 1–7 re-exposed by per-channel gains drawn from [0.7, 1.3];
// LM texture fits (8 outer × 5 steps, 16 spp) with and without fit_exposure: albedo PSNR, gain
// error and seconds per iteration. Long: about a minute on 2 cores.
TEST(ExposureLongTest, AlbedoPsnrWithAndWithoutExposureFit) {
  testing::TempDir dir;
  ASSERT_EQ(testing::SynthIcosphere(
                dir.Join("ds"),
                "--cameras 8 --zooms 1 --res 64 --spp 128 --bounces 1 --shading flat --material "
                "'{\"procedural\": \"noise\", \"colors\": [[0.8, 0.3, 0.2], [0.2, 0.5, 0.7]], "
                "\"roughness\": 0.5, \"specular\": 0, \"resolution\": 2}'"),
            "");
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.Join("ds"), &dataset).ok());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.7, 1.3);
  std::vector<Eigen::Vector3d> truth_gains(dataset.views.size(), Eigen::Vector3d::Ones());
  for (size_t v = 1; v < dataset.views.size(); ++v) {
    truth_gains[v] = Eigen::Vector3d(u(rng), u(rng), u(rng));
    Image image;
    ASSERT_TRUE(LoadViewImage(dataset, static_cast<int>(v), &image).ok());
    for (size_t i = 0; i < image.data.size(); ++i) {
      image.data[i] *= static_cast<float>(truth_gains[v][i % 3]);
    }
    ASSERT_TRUE(WriteImage(dir.Join("ds/" + dataset.views[v].image), image).ok());
  }
  TriMesh mesh;
  Material truth, guess;
  ASSERT_TRUE(ReadMesh(dir.Join("ds/gt/mesh.ply"), &mesh).ok());
  ASSERT_TRUE(LoadMaterial(dir.Join("ds/gt/material.json"), mesh, &truth).ok());
  ASSERT_TRUE(LoadMaterial(R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5, "resolution": 2})",
                           mesh, &guess)
                  .ok());
  ReconstructOptions options;
  options.cache.render.spp = 16;
  options.cache.render.bounces = 1;
  options.cache.pyramid_levels = 3;
  options.phases = PhaseSchedule::kTexture;
  options.outer_iterations = 8;
  options.solver.steps = 5;
  options.regularizers.albedo_smoothness = 0.1;
  double psnr[2];
  for (int fit = 0; fit < 2; ++fit) {
    options.fit_exposure = fit == 1;
    std::unique_ptr<Reconstruction> r;
    ASSERT_TRUE(Reconstruction::Create(dataset, mesh, guess, {}, options, &r).ok());
    for (int outer = 0; outer < options.outer_iterations; ++outer) {
      ASSERT_TRUE(r->RunOuter(outer, nullptr).ok());
    }
    double seconds = 0.0, render = 0.0;
    int iterations = 0;
    for (const PhaseRecord& p : r->phases()) {
      seconds += p.stats.seconds;
      render += p.stats.time.render;
      iterations += p.stats.iterations;
    }
    double max_gain_error = 0.0, sum_gain_error = 0.0;
    const std::vector<Eigen::Vector3d> gains = r->ViewGains();
    for (size_t v = 0; v < gains.size(); ++v) {
      for (int c = 0; c < 3; ++c) {
        const double error = std::abs(gains[v][c] / truth_gains[v][c] - 1);
        max_gain_error = std::max(max_gain_error, error);
        sum_gain_error += error / (3.0 * (gains.size() - 1));
      }
    }
    psnr[fit] = AlbedoPsnr(dataset, mesh, truth, r->CurrentMaterial());
    std::printf(
        "fit_exposure=%d: albedo PSNR %.2f dB, gain error mean %.4f max %.4f, %d iterations, "
        "%.3f s/iteration (render %.3f s/iteration)\n",
        fit, psnr[fit], sum_gain_error, max_gain_error, iterations, seconds / iterations,
        render / iterations);
  }
  EXPECT_GT(psnr[1], psnr[0] + 1.0);
}

}  // namespace
}  // namespace sft
