// Environment lights fixed in the world or in each view's camera (src/io/scene_setup.h,
// ViewWorldFromEnv and MakeDatasetViews; docs/dataset.md, "frame"): the frame round-trips through
// scene.json, and a camera-fixed map is turned with each view's camera.
#include "src/io/scene_setup.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "tests/testing/dataset_scenes.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using json = nlohmann::json;

// A probe that is black but for one bright texel, at env direction (1, 0, 0) (u = 0.5, v = 0.5:
// the image centre looks along +x in the env frame).
Image OneBrightTexel() {
  Image probe(16, 8, 3, 0.0f);
  for (int c = 0; c < 3; ++c) {
    probe.at(8, 3, c) = 100.0f;
    probe.at(7, 3, c) = 100.0f;
    probe.at(8, 4, c) = 100.0f;
    probe.at(7, 4, c) = 100.0f;
  }
  return probe;
}

// MinimalScene with its probe camera-fixed, world_from_env = identity (env axes = camera axes),
// and both views lit by it alone; view 1 is turned 90° about the camera's y axis.
json CameraFixedScene() {
  json scene = testing::MinimalScene();
  scene["lights"][1]["frame"] = "camera";
  scene["lights"][1]["world_from_env"] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  scene["lights"][1]["scale"] = 1.0;
  const double h = std::sqrt(0.5);
  scene["views"][0]["lights"] = {"probe"};
  scene["views"][1]["lights"] = {"probe"};
  scene["views"][1]["cam_from_world"]["rotation"] = {h, 0, h, 0};  // w, x, y, z.
  return scene;
}

TEST(SceneSetupTest, EnvironmentFrameRoundTripsThroughSceneJson) {
  testing::TempDir dir;
  testing::WriteDataset(dir, CameraFixedScene());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  EXPECT_EQ(dataset.lights[1].frame, LightFrame::kCamera);
  testing::TempDir copy;
  ASSERT_TRUE(WriteSceneJson(dataset, copy.path()).ok());
  Dataset again;
  ASSERT_TRUE(ReadDataset(copy.path(), &again).ok());
  EXPECT_EQ(again.lights[1].frame, LightFrame::kCamera);
  // A world-fixed environment writes no frame (files before the key read the same).
  dataset.lights[1].frame = LightFrame::kWorld;
  testing::TempDir world;
  ASSERT_TRUE(WriteSceneJson(dataset, world.path()).ok());
  const json written = json::parse(testing::ReadTestFile(world.Join("scene.json")));
  EXPECT_FALSE(written["lights"][1].contains("frame")) << written["lights"][1].dump();
}

TEST(SceneSetupTest, ViewWorldFromEnvTurnsACameraFixedMapWithTheCamera) {
  LightSpec light;
  light.world_from_env = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Rigid3d cam_from_world;
  cam_from_world.rotation = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 3).normalized());
  EXPECT_TRUE(ViewWorldFromEnv(light, cam_from_world).isApprox(light.world_from_env));
  light.frame = LightFrame::kCamera;
  const Eigen::Matrix3d expected =
      cam_from_world.rotation.conjugate().toRotationMatrix() * light.world_from_env;
  EXPECT_TRUE(ViewWorldFromEnv(light, cam_from_world).isApprox(expected, 1e-12));
}

// Known answer: the bright texel looks along env +x; with env axes = camera axes it shines from
// the camera's right (+x in camera coordinates), which is a different world direction in each
// view (view 1 is turned 90° about y). Each view's map is bright there and black elsewhere.
TEST(SceneSetupTest, CameraFixedEnvironmentShinesFromTheSameCameraDirectionInEveryView) {
  testing::TempDir dir;
  testing::WriteDataset(dir, CameraFixedScene());
  ASSERT_TRUE(WriteExr(dir.Join("probes/env.exr"), OneBrightTexel()).ok());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  DatasetViews views;
  ASSERT_TRUE(MakeDatasetViews(dataset, &views).ok());
  ASSERT_EQ(views.views.size(), 2u);
  EXPECT_EQ(views.environments[1], nullptr);  // no shared world-fixed map.
  ASSERT_NE(views.views[0].environment, nullptr);
  ASSERT_NE(views.views[1].environment, nullptr);
  EXPECT_NE(views.views[0].environment, views.views[1].environment);
  for (int v = 0; v < 2; ++v) {
    const Eigen::Matrix3d world_from_cam =
        dataset.views[v].cam_from_world.rotation.conjugate().toRotationMatrix();
    const Eigen::Vector3d camera_right = world_from_cam * Eigen::Vector3d::UnitX();
    const EnvironmentMap& map = *views.views[v].environment;
    EXPECT_GT(map.Radiance(camera_right).x(), 50.0) << "view " << v;
    EXPECT_NEAR(map.Radiance(-camera_right).x(), 0.0, 1e-9) << "view " << v;
    const Eigen::Vector3d camera_up = world_from_cam * Eigen::Vector3d::UnitY();
    EXPECT_NEAR(map.Radiance(camera_up).x(), 0.0, 1e-9) << "view " << v;
  }
  // The two views' right-hand directions differ in the world, so a world-fixed map could not
  // light both from there.
  const Eigen::Vector3d right0 =
      dataset.views[0].cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d right1 =
      dataset.views[1].cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitX();
  EXPECT_LT(right0.dot(right1), 0.5);
}

}  // namespace
}  // namespace sft
