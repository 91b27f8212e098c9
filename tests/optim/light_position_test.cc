// Fitted point-light positions (`fit_light_positions`; issue 22): the parameter layout, lights.json
// with positions (written, read back, refused when malformed), the config key, and fits on small
// synthetic datasets where the light starts displaced by 20% of the object's size — a camera
// flash (its offset in the camera frame) and a world-frame light — and ends measurably closer.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "src/core/file_util.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/light_scales.h"
#include "src/io/scene_setup.h"
#include "src/optim/config.h"
#include "src/optim/parameters.h"
#include "src/optim/reconstruct.h"
#include "src/optim/run_outputs.h"
#include "src/optim/schedule.h"
#include "src/optim/schedule_config.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/light_fits.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// The true lights: the flash to the upper right of the camera (camera frame: +x right, +y down),
// and a world-frame light above one side of the object (bounding-box diagonal 1, centred at 0).
const Eigen::Vector3d kTrueFlash(0.35, -0.25, 0.0);
const Eigen::Vector3d kTrueWorld(0.9, -0.7, 1.1);
// Where the fits start: the truth moved by 0.2 (20% of the object's size).
const Eigen::Vector3d kDisplacement = 0.2 * Eigen::Vector3d(-0.6, 0.6, 0.5).normalized();

TEST(LightPositionParametersTest, LayoutBlocksAndValues) {
  SceneParameters params = testing::LayoutTestParameters();
  const int size = params.size();
  EXPECT_FALSE(params.has_light_positions());
  EXPECT_TRUE(params.LightPositions().empty());
  params.AddLightPositions({{0.1, 0.2, 0.3}, {4, 5, 6}});
  const ParameterLayout& layout = params.layout();
  ASSERT_TRUE(layout.light_positions);
  EXPECT_EQ(params.size(), size + 6);
  EXPECT_EQ(layout.KindOf(layout.LightPositionOffset() + 4), ParameterKind::kLightPosition);
  EXPECT_EQ(layout.Describe(layout.LightPositionOffset() + 4), "light_position[1].y");
  EXPECT_EQ(params.LightPositions()[1], Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(params.Gains(1).z(), 1.5) << "the gains keep their values";
  const BlockSpan block = params.BlockOf(layout.LightPositionOffset() + 4);
  EXPECT_EQ(block.offset, layout.LightPositionOffset() + 3);
  EXPECT_EQ(block.size, 3);
  EXPECT_EQ(block.kind, ParameterKind::kLightPosition);
  EXPECT_TRUE(std::isinf(params.Lower(block.offset, ParameterBounds())));
  int position_blocks = 0;
  for (const BlockSpan& b : params.Blocks())
    position_blocks += b.kind == ParameterKind::kLightPosition;
  EXPECT_EQ(position_blocks, 2);
  ParameterKind kind;
  ASSERT_TRUE(ParameterKindFromName("light_position", &kind));
  EXPECT_EQ(kind, ParameterKind::kLightPosition);
}

// The keys of fitted point-light positions, directional-light directions and probe rotations.
TEST(LightConfigTest, PositionDirectionAndRotationKeysAreParsedAndWritten) {
  for (const std::string key :
       {"fit_light_positions", "fit_light_directions", "fit_environment_rotation"}) {
    ReconstructOptions options;
    const bool& value = key == "fit_light_positions"    ? options.fit_light_positions
                        : key == "fit_light_directions" ? options.fit_light_directions
                                                        : options.fit_environment_rotation;
    EXPECT_FALSE(value) << key;
    ASSERT_TRUE(ApplyReconstructConfig({{key, true}}, "c.json", &options).ok()) << key;
    EXPECT_TRUE(value) << key;
    EXPECT_EQ(ReconstructConfigJson(options)[key], true) << key;
    const Status status = ApplyReconstructConfig({{key, 1}}, "c.json", &options);
    EXPECT_THAT(status.message(),
                ::testing::HasSubstr("c.json: " + key + ": expected true or false"));
  }
}

class LightPositionFitTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    const std::string flash = "--light-offset " + std::to_string(kTrueFlash.x()) + "," +
                              std::to_string(kTrueFlash.y()) + "," + std::to_string(kTrueFlash.z());
    ASSERT_EQ(testing::SynthLightFitIcosphere(dir_->Join("flash"), flash), "");
    // A copy lit by a world-frame light at kTrueWorld instead of the flash.
    ASSERT_EQ(testing::RelightDataset(dir_->Join("flash"), dir_->Join("world"),
                                      [](Dataset* dataset) {
                                        LightSpec& light = dataset->lights.at(0);
                                        light.frame = LightFrame::kWorld;
                                        light.position = kTrueWorld;
                                        light.intensity *= 2.0;  // farther than the flash.
                                      }),
              "");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  // Fits `dataset_dir`'s light from kDisplacement off the truth (texture phases: LM over albedo,
  // roughness and the light position, from the true material) and returns the light's distance
  // to `truth` before and after; also checks that lights.json round-trips the fitted position.
  void Fit(const std::string& dataset_dir, const Eigen::Vector3d& truth, double* before,
           double* after) {
    testing::LightFit fit;
    ASSERT_EQ(testing::ReadLightFit(dataset_dir, &fit), "");
    fit.options.fit_light_positions = true;
    const Eigen::Vector3d start = truth + kDisplacement;
    std::unique_ptr<Reconstruction> r;
    ASSERT_EQ(testing::RunLightFit(fit, {start}, {}, &r), "");
    Dataset& dataset = fit.dataset;
    const std::vector<Eigen::Vector3d> fitted = r->LightPositions();
    ASSERT_EQ(fitted.size(), 1u);
    *before = (start - truth).norm();
    *after = (fitted[0] - truth).norm();
    std::printf("%s: light %.4f from the truth at the start, %.4f after (%.4f %.4f %.4f)\n",
                dataset_dir.c_str(), *before, *after, fitted[0].x(), fitted[0].y(), fitted[0].z());

    const std::string lights = JoinPath(dataset_dir, "lights.json");
    ASSERT_TRUE(WriteLightScales(lights, dataset, r->LightScales(), fitted).ok());
    std::vector<double> scales;
    std::vector<Eigen::Vector3d> read;
    ASSERT_TRUE(ReadLightScales(lights, dataset, &scales, &read).ok());
    ASSERT_EQ(read.size(), 1u);
    EXPECT_EQ(read[0], fitted[0]);
    ApplyLightPositions(read, &dataset);
    EXPECT_EQ(dataset.lights[0].position, fitted[0]);
  }

  static testing::TempDir* dir_;
};

testing::TempDir* LightPositionFitTest::dir_ = nullptr;

TEST_F(LightPositionFitTest, FlashOffsetMovesTowardsTheTruth) {
  double before = 0.0, after = 0.0;
  Fit(dir_->Join("flash"), kTrueFlash, &before, &after);
  EXPECT_LT(after, 0.5 * before);
}

TEST_F(LightPositionFitTest, WorldLightMovesTowardsTheTruth) {
  double before = 0.0, after = 0.0;
  Fit(dir_->Join("world"), kTrueWorld, &before, &after);
  EXPECT_LT(after, 0.5 * before);
}

// A schedule whose first stage fits the world light's position from a displaced start: the
// checkpoint's lights.json holds the fitted position (not the dataset's), a stop in the second
// stage (which no longer fits it) resumes from it, and the second stage keeps rendering with it.
TEST_F(LightPositionFitTest, CheckpointAndResumeKeepTheFittedPosition) {
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir_->Join("world"), &dataset).ok());
  ScheduleStart start;
  ASSERT_TRUE(ReadMesh(dir_->Join("world/gt/mesh.ply"), &start.mesh).ok());
  ASSERT_TRUE(LoadMaterial(dir_->Join("world/gt/material.json"), start.mesh, &start.material).ok());
  start.light_positions = {kTrueWorld + kDisplacement};
  ScheduleConfig config;
  ASSERT_TRUE(MergeScheduleConfig(nlohmann::json::parse(R"({"spp": 4, "bounces": 1, "steps": 3,
      "phases": "texture", "shading": "flat", "effects": "direct,shadows",
      "stages": [{"name": "a", "outer_iterations": 1, "fit_light_positions": true},
                 {"name": "b", "outer_iterations": 2}]})"),
                                  "test", &config)
                  .ok());
  std::vector<StageOptions> stages;
  ASSERT_TRUE(ResolveStages(config, false, &stages).ok());
  const std::string out = dir_->Join("run");
  std::unique_ptr<Schedule> schedule;
  ASSERT_TRUE(Schedule::Start(dataset, out, stages, start, {{"dataset", "world"}}, &schedule).ok());
  ScheduleCallbacks callbacks;
  callbacks.on_iteration = [](const IterationRecord& r) {
    return !(r.stage == "b" && r.outer == 2);
  };
  ASSERT_TRUE(schedule->Run(callbacks).ok());
  ASSERT_TRUE(schedule->stopped());
  const std::vector<Eigen::Vector3d> fitted = schedule->reconstruction()->LightPositions();
  ASSERT_EQ(fitted.size(), 1u);
  EXPECT_LT((fitted[0] - kTrueWorld).norm(), 0.75 * kDisplacement.norm());

  TriMesh mesh;
  Material material;
  std::vector<double> scales;
  std::vector<Eigen::Vector3d> saved;
  ASSERT_TRUE(ReadRunSnapshot(out, dataset, &mesh, &material, &scales, &saved).ok());
  ASSERT_EQ(saved.size(), 1u);
  EXPECT_EQ(saved[0], fitted[0]);

  RunState state;
  ASSERT_TRUE(ReadRunState(out, &state).ok());
  std::unique_ptr<Schedule> resumed;
  ASSERT_TRUE(Schedule::Resume(dataset, out, stages, state.run_info, state.progress,
                               state.view_gains, &resumed)
                  .ok());
  callbacks.on_iteration = nullptr;
  ASSERT_TRUE(resumed->Run(callbacks).ok());
  ASSERT_TRUE(resumed->finished());
  const std::vector<Eigen::Vector3d> after = resumed->reconstruction()->LightPositions();
  ASSERT_EQ(after.size(), 1u);
  EXPECT_EQ(after[0], fitted[0]) << "stage b does not fit the position but renders with it";
}

// Malformed positions in lights.json are refused with the file and the entry named.
TEST_F(LightPositionFitTest, LightsFileRefusesBadPositions) {
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir_->Join("flash"), &dataset).ok());
  const std::string path = dir_->Join("bad_lights.json");
  const auto read_error = [&](const std::string& members) {
    return testing::LightsFileError(path, dataset, members);
  };
  EXPECT_THAT(read_error(R"("frame": "camera", "position": [1, 2])"),
              ::testing::HasSubstr("bad_lights.json: lights[0].position: expected 3 numbers"));
  EXPECT_THAT(read_error(R"("frame": "world", "position": [1, 2, 3])"),
              ::testing::HasSubstr("lights[0].frame: expected \"camera\""));
  std::vector<double> scales;
  std::vector<Eigen::Vector3d> positions = {Eigen::Vector3d::Ones()};
  read_error("");
  ASSERT_TRUE(ReadLightScales(path, dataset, &scales, &positions).ok());
  EXPECT_TRUE(positions.empty()) << "no positions in the file: none read";
}

}  // namespace
}  // namespace sft
