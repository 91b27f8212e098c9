// Unknown lighting as a fitted environment (src/optim/fitted_environment.h): the start map and its
// gauge, the dataset it makes, a fit that recovers the lighting of a probe it was not given, and
// the fitted map's error against a true probe.
// (The renderer's environment-texel derivatives are checked against finite differences in
// tests/render/derivatives_test.cc.)
#include "src/optim/fitted_environment.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/optim/reconstruct.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

// A texture fit of the map jointly with the albedo on these tests' 6 views at 32²: 8 spp, one
// bounce, a nearly constant albedo (on a convex object a varying albedo could otherwise explain
// the shading: the ambiguity docs/reconstruct.md describes), and a light map prior (its default
// suits captures of many more pixels).
ReconstructOptions JointMapFitOptions() {
  ReconstructOptions options;
  options.phases = PhaseSchedule::kTexture;
  options.fit_environment = true;
  options.cache.render.spp = 8;
  options.cache.render.bounces = 1;
  options.cache.pyramid_levels = 2;
  options.planner.enabled = false;
  options.regularizers.albedo_smoothness = 100.0;
  options.regularizers.environment_smoothness = 0.01;
  return options;
}

// A probe whose left half (u < 0.5) is 10× as bright as its right half, slightly warm.
Image TwoSidedProbe() {
  Image probe(16, 8, 3);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 16; ++x) {
      const float v = x < 8 ? 2.0f : 0.2f;
      probe.at(x, y, 0) = 1.1f * v;
      probe.at(x, y, 1) = v;
      probe.at(x, y, 2) = 0.9f * v;
    }
  }
  return probe;
}

// An icosphere of albedo 0.6 in 6 views at 32², lit by TwoSidedProbe only (one bounce, no gloss);
// the dataset read back with its lights removed: unknown lighting.
class FittedEnvironmentTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    ASSERT_TRUE(WriteExr(dir_->Join("probe.exr"), TwoSidedProbe()).ok());
    ASSERT_EQ(testing::SynthIcosphere(dir_->Join("ds"),
                                      "--cameras 6 --zooms 1 --res 32 --spp 64 --bounces 1 "
                                      "--shading flat --envmap " +
                                          dir_->Join("probe.exr") +
                                          " --material '{\"albedo\": [0.6, 0.6, 0.6], "
                                          "\"roughness\": 0.6, \"specular\": 0}'"),
              "");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    ASSERT_TRUE(ReadDataset(dir_->Join("ds"), &dataset_).ok());
    ASSERT_FALSE(LightingUnknown(dataset_));
    testing::RemoveLights(&dataset_);
    ASSERT_TRUE(ReadMesh(dir_->Join("ds/gt/mesh.ply"), &mesh_).ok());
  }

  static testing::TempDir* dir_;
  Dataset dataset_;
  TriMesh mesh_;
};

testing::TempDir* FittedEnvironmentTest::dir_ = nullptr;

// A resumed run's environment.exr that is not a fitted map stops the resume with one error naming
// the file: not an image, too small, a texel that is not finite or is negative.
TEST_F(FittedEnvironmentTest, BadSavedEnvironmentNamesTheFile) {
  testing::TempDir run;
  const std::string saved = run.Join(kFittedEnvironmentFile);
  const EnvironmentEstimateOptions options;
  std::string note;
  testing::WriteTestFile(saved, "not an EXR");
  Dataset dataset = dataset_;
  Status status = PrepareUnknownLighting(run.path(), options, &dataset, &note);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(saved));

  ASSERT_TRUE(WriteExr(saved, Image(1, 1, 3)).ok());
  dataset = dataset_;
  status = PrepareUnknownLighting(run.path(), options, &dataset, &note);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("not a fitted environment"));

  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), -0.5f}) {
    Image map(4, 2, 3);
    map.data.assign(map.data.size(), 0.3f);
    map.at(3, 1, 2) = bad;
    ASSERT_TRUE(WriteExr(saved, map).ok());
    dataset = dataset_;
    status = PrepareUnknownLighting(run.path(), options, &dataset, &note);
    ASSERT_FALSE(status.ok()) << bad;
    EXPECT_THAT(status.message(), HasSubstr(saved + ": texel (3, 1)"));
  }

  // A good map continues, and says so.
  Image map(4, 2, 3);
  map.data.assign(map.data.size(), 0.3f);
  ASSERT_TRUE(WriteExr(saved, map).ok());
  dataset = dataset_;
  ASSERT_TRUE(PrepareUnknownLighting(run.path(), options, &dataset, &note).ok());
  EXPECT_THAT(note, HasSubstr("continuing the fitted 4×2 world-fixed environment"));
  EXPECT_FALSE(LightingUnknown(dataset));

  // The map's frame comes from environment.json beside it (none: world-fixed, as runs before it).
  const int light = FittedEnvironmentLight(dataset);
  ASSERT_GE(light, 0);
  EXPECT_EQ(dataset.lights[light].frame, LightFrame::kWorld);
  ASSERT_TRUE(WriteFittedEnvironment(run.path(), map, LightFrame::kCamera).ok());
  dataset = dataset_;
  ASSERT_TRUE(PrepareUnknownLighting(run.path(), options, &dataset, &note).ok());
  EXPECT_THAT(note, HasSubstr("camera-fixed environment"));
  EXPECT_EQ(dataset.lights[FittedEnvironmentLight(dataset)].frame, LightFrame::kCamera);
  const std::string info = run.Join(kFittedEnvironmentInfoFile);
  for (const char* bad : {"{\"format\": \"sft-fitted-environment/1\", \"frame\": \"object\"}",
                          "{\"format\": \"other\"}", "not json"}) {
    testing::WriteTestFile(info, bad);
    dataset = dataset_;
    status = PrepareUnknownLighting(run.path(), options, &dataset, &note);
    ASSERT_FALSE(status.ok()) << bad;
    EXPECT_THAT(status.message(), HasSubstr(info)) << bad;
  }
}

// The start map is constant: the photographs' mean over the masks over the assumed albedo; the
// fitted light becomes every view's only light, in memory.
TEST_F(FittedEnvironmentTest, StartsFromThePhotographsMeanOverTheAssumedAlbedo) {
  ASSERT_TRUE(LightingUnknown(dataset_));
  EnvironmentEstimateOptions options;
  options.width = 8;
  options.height = 4;
  Image texels;
  ASSERT_TRUE(InitialEnvironment(dataset_, options, &texels).ok());
  ASSERT_EQ(texels.width, 8);
  ASSERT_EQ(texels.height, 4);
  double sum = 0.0, count = 0.0;
  for (size_t v = 0; v < dataset_.views.size(); ++v) {
    Image rgb, mask;
    ASSERT_TRUE(LoadViewImage(dataset_, static_cast<int>(v), &rgb).ok());
    ASSERT_TRUE(LoadViewMask(dataset_, static_cast<int>(v), &mask).ok());
    for (int y = 0; y < rgb.height; ++y) {
      for (int x = 0; x < rgb.width; ++x) {
        if (mask.at(x, y, 0) > 0.5f) sum += rgb.at(x, y, 1), count += 1.0;
      }
    }
  }
  ASSERT_GT(count, 0.0);
  EXPECT_NEAR(texels.at(3, 2, 1), sum / count / 0.5, 1e-4);
  EXPECT_FLOAT_EQ(texels.at(0, 0, 1), texels.at(7, 3, 1));

  std::string note;
  ASSERT_TRUE(PrepareUnknownLighting("", options, &dataset_, &note).ok());
  EXPECT_THAT(note, HasSubstr("8×4"));
  const int light = FittedEnvironmentLight(dataset_);
  ASSERT_EQ(light, 0);
  for (const ViewSpec& view : dataset_.views) EXPECT_EQ(view.lights, std::vector<int>{light});
  EXPECT_FALSE(LightingUnknown(dataset_));
  // Known lighting is left alone.
  ASSERT_TRUE(PrepareUnknownLighting("", options, &dataset_, &note).ok());
  EXPECT_TRUE(note.empty());
  EXPECT_EQ(dataset_.lights.size(), 1u);
}

// Jointly with a (smoothed) albedo, from the constant start, the fit finds the bright side: the
// ratio of the map's left to right half goes from 1 towards the probe's 10, and the cost falls.
TEST_F(FittedEnvironmentTest, FitRecoversTheBrightSideOfAnUnknownProbe) {
  EnvironmentEstimateOptions estimate;
  estimate.width = 8;
  estimate.height = 4;
  std::string note;
  ASSERT_TRUE(PrepareUnknownLighting("", estimate, &dataset_, &note).ok());
  Material start;
  ASSERT_TRUE(LoadMaterial(R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.6, "resolution": 1})",
                           mesh_, &start)
                  .ok());
  // The probe's step between its halves is what the map must find, from a nearly constant albedo.
  const ReconstructOptions options = JointMapFitOptions();
  std::unique_ptr<Reconstruction> r;
  ASSERT_TRUE(Reconstruction::Create(dataset_, mesh_, start, {}, options, &r).ok());
  std::vector<IterationRecord> records;
  for (int outer = 0; outer < 2; ++outer) {
    ASSERT_TRUE(r->RunOuter(outer, [&](const IterationRecord& rec) {
                   records.push_back(rec);
                   return true;
                 }).ok());
  }
  ASSERT_FALSE(records.empty());
  EXPECT_LT(records.back().cost, records.front().cost);
  const Image env = r->EnvironmentTexels();
  ASSERT_EQ(env.width, 8);
  double left = 0.0, right = 0.0;
  for (int y = 1; y < 3; ++y) {  // the rows nearest the horizon, seen most.
    for (int x = 0; x < 8; ++x) {
      (x < 4 ? left : right) += env.at(x, y, 1);
      for (int c = 0; c < 3; ++c) EXPECT_GE(env.at(x, y, c), 0.0f);
    }
  }
  std::printf("cost %.4g -> %.4g over %zu iterations; left/right %.3g\n", records.front().cost,
              records.back().cost, records.size(), left / right);
  ASSERT_GT(right, 0.0);
  // Measured 7.2 (spp 8, two outer iterations); the start is 1.
  EXPECT_GT(left / right, 5.0) << "left " << left << " right " << right;
}

// Lights that ride with the camera (environment_frame "camera"): an icosphere lit only by a
// flash far to the camera's upper right, seen from 6 views around it. In every photograph the
// sphere is lit from the image's upper right, which no world-fixed map can give all views, and
// which a camera-fixed map can: its fit must explain the photographs far better, with its bright
// texels towards the flash.
class CameraFixedEnvironmentTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    ASSERT_EQ(testing::SynthIcosphere(dir_->Join("ds"),
                                      "--cameras 6 --zooms 1 --res 32 --spp 64 --bounces 1 "
                                      "--shading flat --light-offset 3,-3,0 "
                                      "--material '{\"albedo\": [0.6, 0.6, 0.6], "
                                      "\"roughness\": 0.6, \"specular\": 0}'"),
              "");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  // The final cost of a 2-outer texture fit of an 8×4 map fixed in `frame` (and its map).
  double Fit(LightFrame frame, Image* env) {
    Dataset dataset;
    EXPECT_TRUE(ReadDataset(dir_->Join("ds"), &dataset).ok());
    testing::RemoveLights(&dataset);
    TriMesh mesh;
    EXPECT_TRUE(ReadMesh(dir_->Join("ds/gt/mesh.ply"), &mesh).ok());
    EnvironmentEstimateOptions estimate;
    estimate.width = 8;
    estimate.height = 4;
    estimate.frame = frame;
    std::string note;
    EXPECT_TRUE(PrepareUnknownLighting("", estimate, &dataset, &note).ok());
    EXPECT_THAT(note, HasSubstr(frame == LightFrame::kCamera ? "camera-fixed" : "world-fixed"));
    Material start;
    EXPECT_TRUE(LoadMaterial(R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.6, "resolution": 1})",
                             mesh, &start)
                    .ok());
    const ReconstructOptions options = JointMapFitOptions();
    std::unique_ptr<Reconstruction> r;
    EXPECT_TRUE(Reconstruction::Create(dataset, mesh, start, {}, options, &r).ok());
    if (r == nullptr) return std::numeric_limits<double>::infinity();
    double cost = std::numeric_limits<double>::infinity();
    for (int outer = 0; outer < 2; ++outer) {
      EXPECT_TRUE(r->RunOuter(outer, [&](const IterationRecord& rec) {
                     cost = rec.cost;
                     return true;
                   }).ok());
    }
    *env = r->EnvironmentTexels();
    return cost;
  }

  static testing::TempDir* dir_;
};

testing::TempDir* CameraFixedEnvironmentTest::dir_ = nullptr;

TEST_F(CameraFixedEnvironmentTest, ExplainsAFlashThatAWorldFixedMapCannot) {
  Image world_env, camera_env;
  const double world = Fit(LightFrame::kWorld, &world_env);
  const double camera = Fit(LightFrame::kCamera, &camera_env);
  std::printf("final cost: world-fixed %.4g, camera-fixed %.4g\n", world, camera);
  EXPECT_LT(camera, 0.5 * world);
  // The flash sits at camera (3, −3, 0) from a camera about 3 units from the sphere: from the
  // sphere it is towards camera (+x, −y, −z), i.e. u in (0.5, 0.75) (atan2(y, x) < 0) and
  // v > 0.5 (z < 0). The map's brightest texel must be in that quadrant.
  int best_x = 0, best_y = 0;
  for (int y = 0; y < camera_env.height; ++y) {
    for (int x = 0; x < camera_env.width; ++x) {
      if (camera_env.at(x, y, 1) > camera_env.at(best_x, best_y, 1)) {
        best_x = x;
        best_y = y;
      }
    }
  }
  EXPECT_GE(best_x, 4) << best_x << "," << best_y;
  EXPECT_LE(best_x, 6) << best_x << "," << best_y;
  EXPECT_GE(best_y, 2) << best_x << "," << best_y;
}

// The map's error against the truth: 0 for the truth's own box filter, also when the map is
// brighter by the albedo's gauge; a constant map of the truth's mean radiance has both errors, the
// irradiance's smaller; a black truth or a zero gauge is an error.
TEST(FittedEnvironmentErrorTest, GaugeAndBoxFilter) {
  const Image truth = TwoSidedProbe();  // 16 × 8: each 8 × 4 texel is 2 × 2 pixels of one value.
  Image fitted(8, 4, 3);
  const Eigen::Vector3d gauge(2.0, 1.0, 0.5);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x) {
      for (int c = 0; c < 3; ++c) fitted.at(x, y, c) = truth.at(2 * x, 2 * y, c) * gauge[c];
    }
  }
  EnvironmentError error;
  ASSERT_TRUE(FittedEnvironmentError(fitted, truth, gauge, &error).ok());
  EXPECT_NEAR(error.radiance, 0.0, 1e-6);
  EXPECT_NEAR(error.irradiance, 0.0, 1e-6);
  ASSERT_TRUE(FittedEnvironmentError(fitted, truth, Eigen::Vector3d::Ones(), &error).ok());
  EXPECT_GT(error.radiance, 0.5);

  Image constant(8, 4, 3);
  constant.data.assign(constant.data.size(), 1.1f);  // the truth's mean green radiance.
  ASSERT_TRUE(FittedEnvironmentError(constant, truth, Eigen::Vector3d::Ones(), &error).ok());
  EXPECT_GT(error.radiance, 0.2);
  EXPECT_GT(error.irradiance, 0.2);
  EXPECT_LT(error.irradiance, error.radiance);  // the cosine lobe blurs the step.

  EXPECT_FALSE(
      FittedEnvironmentError(constant, Image(16, 8, 3), Eigen::Vector3d::Ones(), &error).ok());
  EXPECT_FALSE(FittedEnvironmentError(constant, truth, Eigen::Vector3d(1, 0, 1), &error).ok());
}

}  // namespace
}  // namespace sft
