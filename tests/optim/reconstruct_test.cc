// The reconstruction layer on small synthesized datasets: the render cache's pyramids and rows
// against finite differences, the residual blocks' Jacobians, the adjoint gradient, and the
// solvers recovering a known material.
#include "src/optim/reconstruct.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "cost_functions/pyramid_pixel.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/config.h"
#include "src/optim/problem.h"
#include "src/render/render.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// A textured icosphere seen by 3 cameras at 24², lit by the camera flash, one path segment,
// no gloss: the image is exactly linear in albedo and light scales (same seed), so finite
// differences of it are exact up to float rounding. Flat shading, as these tests were measured
// with (under smooth shading dogleg lowers the texture cost by 23% in 5 steps, not by half).
class ReconstructTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    ASSERT_EQ(testing::SynthIcosphere(
                  dir_->Join("ds"),
                  "--cameras 3 --zooms 1 --res 24 --spp 64 --bounces 1 --shading flat --material "
                  "'{\"procedural\": \"noise\", \"colors\": [[0.8, 0.3, 0.2], [0.2, 0.5, 0.7]], "
                  "\"roughness\": 0.5, \"specular\": 0, \"resolution\": 2}'"),
              "");
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
    options_.phases = PhaseSchedule::kTexture;
    options_.outer_iterations = 1;
  }

  static testing::TempDir* dir_;
  Dataset dataset_;
  TriMesh mesh_;
  Material truth_, guess_;
  ReconstructOptions options_;
};

testing::TempDir* ReconstructTest::dir_ = nullptr;

// A state and cache over every view of the dataset for `material`.
struct FitSetup {
  DatasetViews views;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  SceneParameters params;
  std::unique_ptr<RenderCache> cache;
};

void MakeSetup(const Dataset& dataset, const TriMesh& mesh, const Material& material,
               const RenderCacheOptions& options, const ActiveParameters& active, FitSetup* s) {
  ASSERT_TRUE(MakeDatasetViews(dataset, &s->views).ok());
  MeshToArrays(mesh, &s->positions, &s->faces);
  s->params = SceneParameters(s->positions, material, static_cast<int>(dataset.lights.size()));
  std::vector<int> all(dataset.views.size());
  for (size_t v = 0; v < all.size(); ++v) all[v] = static_cast<int>(v);
  ASSERT_TRUE(RenderCache::Create(dataset, &s->views, all, s->faces, material, &s->params, options,
                                  &s->cache)
                  .ok());
  s->cache->SetActive(active);
  s->cache->SetSeed(5);
}

std::vector<double> RandomDirection(const SceneParameters& params, ParameterKind kind, int seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> delta(params.layout().size(), 0.0);
  for (int i = 0; i < params.layout().size(); ++i) {
    if (params.layout().KindOf(i) == kind) delta[i] = u(rng);
  }
  return delta;
}

// A light scale whose renders overflow (samples of infinite radiance are dropped, pixel values
// overflow float): the render reports it (RenderStats), the cache is not finite and counts the
// values, and the adjoint gradient fails, so the solver rejects such a step.
TEST_F(ReconstructTest, NonFiniteRenderFailsTheEvaluation) {
  FitSetup s;
  ActiveParameters active;
  active.albedo = true;
  MakeSetup(dataset_, mesh_, truth_, options_.cache, active, &s);
  s.cache->Render(true);
  ASSERT_TRUE(*s.cache->finite());
  EXPECT_EQ(s.cache->non_finite_values(), 0);
  const int light = s.params.layout().LightOffset();
  for (double scale : {1e300, std::numeric_limits<double>::infinity()}) {
    s.params.values()[light] = scale;
    s.cache->Render(true);
    EXPECT_FALSE(*s.cache->finite()) << scale;
    EXPECT_GT(s.cache->non_finite_values(), 0) << scale;
    std::vector<double> gradient(s.params.layout().size(), 0.0);
    EXPECT_FALSE(s.cache->AddAdjointGradient(0, s.cache->AdjointWeights(0), &gradient)) << scale;
  }
  s.params.values()[light] = 1.0;
  s.cache->Render(true);
  EXPECT_TRUE(*s.cache->finite());
}

// Every level's rows applied to δ equal the central difference of that level's image along δ
// (albedo and light scale: the image is linear in them, so the difference is exact).
TEST_F(ReconstructTest, CacheRowsMatchFiniteDifferencesOnEveryLevel) {
  for (const auto& [filter, kind] : std::vector<std::pair<PyramidFilter, ParameterKind>>{
           {PyramidFilter::kBox, ParameterKind::kAlbedo},
           {PyramidFilter::kBox, ParameterKind::kLight},
           {PyramidFilter::kBinomial, ParameterKind::kAlbedo}}) {
    SCOPED_TRACE(PyramidFilterName(filter));
    FitSetup s;
    ActiveParameters active;
    active.lights = true;
    options_.cache.pyramid_filter = filter;
    MakeSetup(dataset_, mesh_, truth_, options_.cache, active, &s);
    const std::vector<double> delta = RandomDirection(s.params, kind, 11);
    const std::vector<double> x0 = s.params.values();
    const double h = 1e-3;
    std::vector<std::vector<Image>> images[2];
    for (int side = 0; side < 2; ++side) {
      for (size_t i = 0; i < x0.size(); ++i) {
        s.params.values()[i] = x0[i] + (side == 0 ? h : -h) * delta[i];
      }
      s.cache->Render(false);
      images[side].resize(s.cache->num_views());
      for (int v = 0; v < s.cache->num_views(); ++v) {
        for (int l = 0; l < s.cache->num_levels(v); ++l) {
          images[side][v].push_back(s.cache->level(v, l).render);
        }
      }
    }
    s.params.values() = x0;
    s.cache->Render(true);
    double err = 0.0, norm = 0.0;
    for (int v = 0; v < s.cache->num_views(); ++v) {
      ASSERT_EQ(s.cache->num_levels(v), 3);
      for (int l = 0; l < s.cache->num_levels(v); ++l) {
        const LevelRows& rows = s.cache->level(v, l).rows;
        for (int p = 0; p < rows.width * rows.height; ++p) {
          double jd[3] = {0, 0, 0};
          for (uint64_t i = rows.offsets[p]; i < rows.offsets[p + 1]; ++i) {
            for (int c = 0; c < 3; ++c)
              jd[c] += rows.entries[i].d[c] * delta[rows.entries[i].param];
          }
          for (int c = 0; c < 3; ++c) {
            const double fd =
                (images[0][v][l].data[3 * p + c] - images[1][v][l].data[3 * p + c]) / (2 * h);
            err += (jd[c] - fd) * (jd[c] - fd);
            norm += fd * fd;
          }
        }
      }
    }
    ASSERT_GT(norm, 0.0);
    // Float images: the difference quotient carries ~1e-7/h relative rounding noise.
    EXPECT_LT(std::sqrt(err / norm), 1e-3) << ParameterKindName(kind);
  }
}

// The mean of the pyramids of independent low-spp renders equals (within noise) the pyramid of
// a high-spp render: the expected rendered pyramid is the pyramid of the expected image.
TEST_F(ReconstructTest, ExpectedPyramidIsPyramidOfExpectedImage) {
  FitSetup s;
  RenderCacheOptions options = options_.cache;
  options.render.spp = 4;
  MakeSetup(dataset_, mesh_, truth_, options, ActiveParameters(), &s);
  const int kRenders = 16;
  std::vector<Image> mean;
  for (int k = 0; k < kRenders; ++k) {
    s.cache->SetSeed(100 + k);
    s.cache->Render(false);
    if (mean.empty()) {
      for (int l = 0; l < 3; ++l)
        mean.push_back(
            Image(s.cache->level(0, l).render.width, s.cache->level(0, l).render.height, 3));
    }
    for (int l = 0; l < 3; ++l) {
      for (size_t i = 0; i < mean[l].data.size(); ++i) {
        mean[l].data[i] += s.cache->level(0, l).render.data[i] / kRenders;
      }
    }
  }
  FitSetup reference;
  options.render.spp = 256;
  MakeSetup(dataset_, mesh_, truth_, options, ActiveParameters(), &reference);
  reference.cache->Render(false);
  for (int l = 1; l < 3; ++l) {
    const Image& expected = reference.cache->level(0, l).render;
    double diff = 0.0, sum = 0.0;
    for (size_t i = 0; i < expected.data.size(); ++i) {
      diff += std::abs(mean[l].data[i] - expected.data[i]);
      sum += expected.data[i];
    }
    ASSERT_GT(sum, 0.0);
    // 64 vs 256 samples per pixel, coarse pixels average 4^l of them: ~1% noise.
    EXPECT_LT(diff / sum, 0.03) << "level " << l;
  }
}

// The residual block copies its pixel's residual and the entries of its superset, in the right
// columns; entries outside the superset are dropped; untouched blocks get zeros; a non-finite
// render makes Evaluate fail.
TEST(PyramidPixelCostTest, CopiesRowsIntoBlocks) {
  LevelCache level;
  level.render = Image(2, 1, 3, 0.5f);
  level.target = Image(2, 1, 3, 0.25f);
  level.sqrt_weight = 2.0;
  level.rows.width = 2;
  level.rows.height = 1;
  level.rows.entries = {{1, {1, 2, 3}}, {4, {4, 5, 6}}, {9, {7, 8, 9}}, {12, {0, 0, 1}}};
  level.rows.offsets = {0, 0, 4};  // pixel 1 has all four entries.
  bool finite = true;
  // Blocks: [0, 3) vertex-like, [3, 6), [12, 13); parameter 9 is outside (dropped).
  PyramidPixelCost cost(&level, &finite, 1, {0, 3, 12}, {3, 3, 1});
  double a[3] = {0, 0, 0}, b[3] = {0, 0, 0}, c[1] = {0};
  const double* params[] = {a, b, c};
  double residuals[3];
  double ja[9], jb[9], jc[3];
  double* jacobians[] = {ja, jb, jc};
  ASSERT_TRUE(cost.Evaluate(params, residuals, jacobians));
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(residuals[k], 2.0 * 0.25);
  // Row c of block 0: parameter 1 is column 1.
  EXPECT_DOUBLE_EQ(ja[0 * 3 + 1], 2.0 * 1);
  EXPECT_DOUBLE_EQ(ja[2 * 3 + 1], 2.0 * 3);
  EXPECT_DOUBLE_EQ(ja[0], 0.0);
  // Parameter 4 is column 1 of block [3, 6).
  EXPECT_DOUBLE_EQ(jb[1 * 3 + 1], 2.0 * 5);
  EXPECT_DOUBLE_EQ(jc[2], 2.0 * 1);
  double sum = 0.0;
  for (double v : jb) sum += v;
  EXPECT_DOUBLE_EQ(sum, 2.0 * (4 + 5 + 6));  // parameter 9 did not land anywhere.
  // Constant blocks have no Jacobian.
  double* some[] = {nullptr, jb, nullptr};
  ASSERT_TRUE(cost.Evaluate(params, residuals, some));
  finite = false;
  EXPECT_FALSE(cost.Evaluate(params, residuals, jacobians));
}

// A pixel weight scales the residual and every Jacobian entry of its block.
TEST(PyramidPixelCostTest, PixelWeightScalesResidualAndRow) {
  LevelCache level;
  level.render = Image(2, 1, 3, 0.5f);
  level.target = Image(2, 1, 3, 0.25f);
  level.sqrt_weight = 2.0;
  level.pixel_sqrt_weight = {1.0f, 0.25f};
  level.rows.width = 2;
  level.rows.height = 1;
  level.rows.entries = {{0, {1, 2, 3}}};
  level.rows.offsets = {0, 0, 1};
  bool finite = true;
  PyramidPixelCost cost(&level, &finite, 1, {0}, {1});
  double a[1] = {0};
  const double* params[] = {a};
  double residuals[3], ja[3];
  double* jacobians[] = {ja};
  ASSERT_TRUE(cost.Evaluate(params, residuals, jacobians));
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(residuals[k], 2.0 * 0.25 * 0.25);
  EXPECT_DOUBLE_EQ(ja[0], 2.0 * 0.25 * 1);
  EXPECT_DOUBLE_EQ(ja[2], 2.0 * 0.25 * 3);
}

// The relative loss weighs a pixel at the view's median 1 and a pixel k times brighter
// 2/(k + 1), on every level; the L2 loss leaves the weights empty.
TEST_F(ReconstructTest, RelativeLossWeightsFollowTheTarget) {
  options_.cache.image_loss = ImageLoss::kRelative;
  FitSetup s;
  MakeSetup(dataset_, mesh_, guess_, options_.cache, ActiveParameters(), &s);
  const RenderCache& cache = *s.cache;
  for (int l = 0; l < cache.num_levels(0); ++l) {
    const LevelCache& level = cache.level(0, l);
    ASSERT_EQ(level.pixel_sqrt_weight.size(),
              static_cast<size_t>(level.target.width) * level.target.height);
  }
  // Recover m from any pixel: w = 2m/(m + y) ⇒ m = w·y/(2 − w); every pixel must agree.
  const LevelCache& level0 = cache.level(0, 0);
  std::vector<double> ms;
  for (int p = 0; p < level0.target.width * level0.target.height; ++p) {
    const int x = p % level0.target.width, y = p / level0.target.width;
    const double mean =
        (level0.target.at(x, y, 0) + level0.target.at(x, y, 1) + level0.target.at(x, y, 2)) / 3.0;
    const double w = level0.pixel_sqrt_weight[p];
    EXPECT_GT(w, 0.0);
    EXPECT_LE(w, 2.0 + 1e-6);
    if (mean > 1e-3) ms.push_back(w * mean / (2.0 - w));
  }
  ASSERT_FALSE(ms.empty());
  for (double m : ms) EXPECT_NEAR(m / ms[0], 1.0, 1e-4);
  // m is the median of the active, non-black pixels' means: about half of them weigh more than 1.
  int above = 0, active = 0;
  for (int p = 0; p < level0.target.width * level0.target.height; ++p) {
    const int x = p % level0.target.width, y = p / level0.target.width;
    const float sum =
        level0.target.at(x, y, 0) + level0.target.at(x, y, 1) + level0.target.at(x, y, 2);
    if (!cache.targets(0).active[0][p] || !(sum > 0.0f)) continue;
    ++active;
    above += level0.pixel_sqrt_weight[p] > 1.0f;
  }
  EXPECT_NEAR(static_cast<double>(above) / active, 0.5, 0.05);

  options_.cache.image_loss = ImageLoss::kL2;
  FitSetup plain;
  MakeSetup(dataset_, mesh_, guess_, options_.cache, ActiveParameters(), &plain);
  EXPECT_TRUE(plain.cache->level(0, 0).pixel_sqrt_weight.empty());
}

// The adjoint objective's gradient (lbfgs, adam) against the central difference of its cost,
// which is exactly quadratic in albedo here; and the trust-region problem's gradient Jᵀr against
// the same, up to the Jacobian mass its frozen supersets drop.
TEST_F(ReconstructTest, GradientsMatchFiniteDifferencesOfTheCost) {
  // Both pyramid filters: the adjoint weights (DownsampleMeanAdjoint) and the coarse rows
  // (DownsampleRows) must follow the filter of the levels.
  // And both image losses: the relative loss's pixel weights must reach the adjoint and the rows.
  const std::pair<PyramidFilter, ImageLoss> cases[] = {{PyramidFilter::kBox, ImageLoss::kL2},
                                                       {PyramidFilter::kBinomial, ImageLoss::kL2},
                                                       {PyramidFilter::kBox, ImageLoss::kRelative}};
  for (const auto& [filter, loss] : cases) {
    SCOPED_TRACE(std::string(PyramidFilterName(filter)) + " " + ImageLossName(loss));
    options_.cache.pyramid_filter = filter;
    options_.cache.image_loss = loss;
    FitSetup s;
    ActiveParameters active;  // albedo and roughness.
    MakeSetup(dataset_, mesh_, guess_, options_.cache, active, &s);
    ceres::Problem empty;
    AdjointObjective objective(s.cache.get(), &s.params, ParameterBounds(), nullptr);
    std::vector<double> x = objective.Current();
    std::vector<double> gradient(x.size());
    double cost = 0.0;
    ASSERT_TRUE(objective.Evaluate(x.data(), &cost, gradient.data()));
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> delta(x.size(), 0.0);
    for (size_t k = 0; k < x.size(); ++k) {
      if (s.params.layout().KindOf(objective.active_indices()[k]) == ParameterKind::kAlbedo) {
        delta[k] = u(rng);
      }
    }
    const double h = 1e-3;
    double costs[2];
    for (int side = 0; side < 2; ++side) {
      std::vector<double> y = x;
      for (size_t k = 0; k < x.size(); ++k) y[k] += (side == 0 ? h : -h) * delta[k];
      ASSERT_TRUE(objective.Evaluate(y.data(), &costs[side], nullptr));
    }
    const double fd = (costs[0] - costs[1]) / (2 * h);
    double directional = 0.0;
    for (size_t k = 0; k < x.size(); ++k) directional += gradient[k] * delta[k];
    ASSERT_GT(std::abs(fd), 0.0);
    EXPECT_NEAR(directional / fd, 1.0, 1e-3);

    // The Ceres problem at the same point and seed.
    objective.Store(x.data());
    std::unique_ptr<ReconstructionProblem> problem;
    ProblemOptions problem_options;
    problem_options.superset_renders = 4;
    ASSERT_TRUE(
        ReconstructionProblem::Build(s.cache.get(), &s.params, problem_options, &problem).ok());
    std::vector<double*> blocks;
    problem->problem()->GetParameterBlocks(&blocks);
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.parameter_blocks = blocks;
    double problem_cost = 0.0;
    std::vector<double> problem_gradient;
    ASSERT_TRUE(
        problem->problem()->Evaluate(evaluate, &problem_cost, nullptr, &problem_gradient, nullptr));
    // Measured at the rows of this evaluation (not of the superset renders).
    const double dropped = problem->DroppedJacobianFraction(*s.cache);
    double problem_directional = 0.0;
    size_t k = 0;
    for (double* block : blocks) {
      const int offset = static_cast<int>(block - s.params.data());
      for (int i = 0; i < problem->problem()->ParameterBlockSize(block); ++i, ++k) {
        const auto it = std::lower_bound(objective.active_indices().begin(),
                                         objective.active_indices().end(), offset + i);
        problem_directional += problem_gradient[k] * delta[it - objective.active_indices().begin()];
      }
    }
    // Pixels with no parameters are left out of the problem but are constant: same cost up to them.
    EXPECT_LE(problem_cost, cost * (1 + 1e-9));
    EXPECT_LT(dropped, 0.05);
    EXPECT_NEAR(problem_directional / fd, 1.0, 1e-3 + 2 * std::sqrt(dropped)) << dropped;
  }
}

// A problem whose Jacobian would pass the allowed size is refused with one line that names what to
// change, and nothing is built; at exactly its size it builds.
TEST_F(ReconstructTest, OversizedJacobianIsRefusedWithOneLine) {
  FitSetup s;
  MakeSetup(dataset_, mesh_, guess_, options_.cache, ActiveParameters(), &s);
  std::unique_ptr<ReconstructionProblem> problem;
  ProblemOptions problem_options;
  ASSERT_TRUE(
      ReconstructionProblem::Build(s.cache.get(), &s.params, problem_options, &problem).ok());
  const int64_t values = kPixelResiduals * problem->stats().superset_entries;
  ASSERT_GT(values, 1000);
  problem_options.max_jacobian_values = values - 1;
  std::unique_ptr<ReconstructionProblem> refused;
  const Status status =
      ReconstructionProblem::Build(s.cache.get(), &s.params, problem_options, &refused);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(refused, nullptr);
  EXPECT_NE(status.message().find("would hold " + std::to_string(values) + " values"),
            std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find("image_scale"), std::string::npos);
  EXPECT_NE(status.message().find("\"adam\""), std::string::npos);
  EXPECT_EQ(status.message().find('\n'), std::string::npos);
  problem_options.max_jacobian_values = values;
  EXPECT_TRUE(
      ReconstructionProblem::Build(s.cache.get(), &s.params, problem_options, &refused).ok());
  problem_options.max_jacobian_values = 0;
  EXPECT_FALSE(
      ReconstructionProblem::Build(s.cache.get(), &s.params, problem_options, &refused).ok());
}

// A minibatch of the adjoint objective (Adam's views_per_step) is the batch views' part of the
// full objective scaled by views / batch: cost and gradient, at the same point and seed.
TEST_F(ReconstructTest, MinibatchObjectiveIsTheScaledPartOfItsViews) {
  FitSetup s;
  MakeSetup(dataset_, mesh_, guess_, options_.cache, ActiveParameters(), &s);
  ASSERT_GE(s.cache->num_views(), 2);
  AdjointObjective objective(s.cache.get(), &s.params, ParameterBounds(), nullptr);
  const std::vector<double> x = objective.Current();
  std::vector<double> full(x.size()), part(x.size()), all(x.size());
  double full_cost = 0.0, part_cost = 0.0, all_cost = 0.0;
  ASSERT_TRUE(objective.Evaluate(x.data(), &full_cost, full.data()));
  const double view0 = s.cache->ViewImageCost(0);
  ASSERT_TRUE(objective.EvaluateViews(x.data(), {0}, &part_cost, part.data()));
  const double views = s.cache->num_views();
  EXPECT_NEAR(part_cost, views * view0, 1e-9 * part_cost);
  // Explicitly listing every view is the full objective.
  std::vector<int> every;
  for (int v = 0; v < s.cache->num_views(); ++v) every.push_back(v);
  ASSERT_TRUE(objective.EvaluateViews(x.data(), every, &all_cost, all.data()));
  EXPECT_NEAR(all_cost, full_cost, 1e-9 * full_cost);
  double norm = 0.0;
  for (size_t k = 0; k < x.size(); ++k) {
    EXPECT_NEAR(all[k], full[k], 1e-9 * (1.0 + std::abs(full[k])));
    norm += part[k] * part[k];
  }
  EXPECT_GT(norm, 0.0);  // the single view's gradient is not empty.
}

// Texture only, from a constant grey guess: Levenberg–Marquardt recovers the albedo texels that
// the views see; L-BFGS and Adam lower the cost.
TEST_F(ReconstructTest, TexturePhaseRecoversAlbedo) {
  for (SolverKind kind : {SolverKind::kLevenbergMarquardt, SolverKind::kDogleg, SolverKind::kLbfgs,
                          SolverKind::kAdam}) {
    ReconstructOptions options = options_;
    options.solver.kind = kind;
    options.solver.steps = kind == SolverKind::kAdam ? 10 : 5;
    if (kind == SolverKind::kDogleg) {
      options.solver.trust_region.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    }
    std::unique_ptr<Reconstruction> r;
    ASSERT_TRUE(Reconstruction::Create(dataset_, mesh_, guess_, {}, options, &r).ok());
    std::vector<IterationRecord> records;
    ASSERT_TRUE(r->RunOuter(0, [&](const IterationRecord& rec) {
                   records.push_back(rec);
                   return true;
                 }).ok());
    ASSERT_FALSE(records.empty()) << SolverKindName(kind);
    EXPECT_LT(records.back().cost, 0.5 * records.front().cost) << SolverKindName(kind);
    if (kind == SolverKind::kLevenbergMarquardt) {
      // The albedo seen in the views (albedo pass, where texels are observed) moves towards
      // the truth, and stays in [0, 1].
      const Material fitted = r->CurrentMaterial();
      for (double a : fitted.albedo.values()) {
        EXPECT_GE(a, 0.0);
        EXPECT_LE(a, 1.0);
      }
      DatasetViews views;
      ASSERT_TRUE(MakeDatasetViews(dataset_, &views).ok());
      const RenderScene scene(mesh_);
      RenderOptions pass;
      pass.pass = RenderPass::kAlbedo;
      pass.spp = 16;
      double err_fit = 0.0, err_guess = 0.0;
      for (const ViewSetup& view : views.views) {
        Image truth, fit, guess;
        RenderView(scene, truth_, view, pass, &truth);
        RenderView(scene, fitted, view, pass, &fit);
        RenderView(scene, guess_, view, pass, &guess);
        for (size_t i = 0; i < truth.data.size(); ++i) {
          if (i % 4 == 3) continue;
          err_fit += std::abs(fit.data[i] - truth.data[i]);
          err_guess += std::abs(guess.data[i] - truth.data[i]);
        }
      }
      EXPECT_LT(err_fit, 0.5 * err_guess);
    }
  }
}

TEST(ReconstructConfigTest, KeysRoundTripAndUnknownKeysAreErrors) {
  ReconstructOptions options;
  ASSERT_TRUE(ApplyReconstructConfig({{"solver", "dogleg"},
                                      {"steps", 7},
                                      {"laplacian", "cotangent"},
                                      {"linear_solver", "dense_qr"},
                                      {"views", {0, 2}},
                                      {"fit_lights", true},
                                      {"shading", "smooth"},
                                      {"normal_sliding", false}},
                                     "cfg.json", &options)
                  .ok());
  EXPECT_EQ(options.solver.kind, SolverKind::kDogleg);
  EXPECT_EQ(options.shading, "smooth");
  EXPECT_FALSE(options.cache.edges.normal_sliding);
  EXPECT_EQ(options.solver.steps, 7);
  EXPECT_TRUE(options.regularizers.cotangent);
  const nlohmann::json all = ReconstructConfigJson(options);
  ReconstructOptions copy;
  ASSERT_TRUE(ApplyReconstructConfig(all, "x", &copy).ok());
  EXPECT_EQ(ReconstructConfigJson(copy), all);

  Status status = ApplyReconstructConfig({{"stepz", 3}}, "cfg.json", &options);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::HasSubstr("cfg.json: stepz: unknown key"));
  status = ApplyReconstructConfig({{"steps", 0}}, "cfg.json", &options);
  EXPECT_THAT(status.message(), ::testing::HasSubstr("steps: expected an integer in [1, 1000]"));
  status = ApplyReconstructConfig({{"spp", 2.5}}, "cfg.json", &options);
  EXPECT_FALSE(status.ok());
  status = ApplyReconstructConfig({{"solver", "newton"}}, "cfg.json", &options);
  EXPECT_THAT(status.message(), ::testing::HasSubstr("solver"));
  status = ApplyReconstructConfig({{"shading", "phong"}}, "cfg.json", &options);
  EXPECT_THAT(status.message(), ::testing::HasSubstr("shading: expected auto, flat or smooth"));
}

TEST(FillUnsampledTexelsTest, CopiesInFaceNeighbours) {
  MeshColors colors(1, 2, 1);
  for (int k = 0; k < colors.num_texels(); ++k) *colors.texel(k) = k;
  FillUnsampledTexels(&colors);
  // r = 2: (0,2) <- (0,1); (1,1) <- (1,0); (2,0) <- (1,0).
  EXPECT_EQ(*colors.texel(MeshColors::LocalIndex(2, 0, 2)), MeshColors::LocalIndex(2, 0, 1));
  EXPECT_EQ(*colors.texel(MeshColors::LocalIndex(2, 1, 1)), MeshColors::LocalIndex(2, 1, 0));
  EXPECT_EQ(*colors.texel(MeshColors::LocalIndex(2, 2, 0)), MeshColors::LocalIndex(2, 1, 0));
  EXPECT_EQ(*colors.texel(MeshColors::LocalIndex(2, 0, 0)), 0);
}

}  // namespace
}  // namespace sft
