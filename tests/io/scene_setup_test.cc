// Environment lights fixed in the world or in each view's camera (src/io/scene_setup.h,
// ViewWorldFromEnv and MakeDatasetViews; docs/dataset.md, "frame"): the frame round-trips through
// scene.json, and a camera-fixed map is turned with each view's camera. A world-fixed map's
// `ground_normal` hides it below the ground's horizon, in the world whatever the map's rotation.
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

// MinimalScene's probe lighting both views, world-fixed, turned by `world_from_env`, with a ground
// whose up is world +z.
json GroundScene(const Eigen::Matrix3d& world_from_env) {
  json scene = testing::MinimalScene();
  json matrix = json::array();
  for (int r = 0; r < 3; ++r) {
    matrix.push_back({world_from_env(r, 0), world_from_env(r, 1), world_from_env(r, 2)});
  }
  scene["lights"][1]["world_from_env"] = matrix;
  scene["lights"][1]["scale"] = 1.0;
  scene["lights"][1]["ground_normal"] = {0, 0, 2};  // normalized on read.
  scene["views"][0]["lights"] = {"probe"};
  scene["views"][1]["lights"] = {"probe"};
  return scene;
}

// Known answer: a uniform map of radiance 1 over an infinite black floor is 1 above the horizon
// and 0 below it (beyond the one texel across the horizon that blends both), for a map turned
// about any axis: the ground is in the world, not in the map.
TEST(SceneSetupTest, GroundHidesAWorldFixedMapBelowItsHorizon) {
  const Eigen::Matrix3d turns[] = {
      Eigen::Matrix3d::Identity(),
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix(),
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix()};
  for (const Eigen::Matrix3d& world_from_env : turns) {
    testing::TempDir dir;
    testing::WriteDataset(dir, GroundScene(world_from_env));
    ASSERT_TRUE(WriteExr(dir.Join("probes/env.exr"), Image(64, 32, 3, 1.0f)).ok());
    Dataset dataset;
    ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
    EXPECT_TRUE(dataset.lights[1].ground_normal.isApprox(Eigen::Vector3d::UnitZ()));
    DatasetViews views;
    ASSERT_TRUE(MakeDatasetViews(dataset, &views).ok());
    const EnvironmentMap& map = *views.views[0].environment;
    EXPECT_EQ(&map, views.views[1].environment);  // one shared world-fixed map.
    // A texel spans 180°/32 = 5.6° in elevation: 15° clears the blended band.
    for (double azimuth = 0; azimuth < 2 * M_PI; azimuth += 0.5) {
      for (double elevation : {-80.0, -40.0, -15.0, 15.0, 40.0, 80.0}) {
        const double e = elevation * M_PI / 180;
        const Eigen::Vector3d dir(std::cos(e) * std::cos(azimuth), std::cos(e) * std::sin(azimuth),
                                  std::sin(e));
        EXPECT_NEAR(map.Radiance(dir).x(), elevation > 0 ? 1.0 : 0.0, 1e-6)
            << "elevation " << elevation << " azimuth " << azimuth;
      }
    }
    // Importance sampling draws only from above the ground.
    for (int k = 0; k < 200; ++k) {
      Eigen::Vector3d dir, radiance;
      double pdf = 0;
      ASSERT_TRUE(map.Sample((k + 0.5) / 200, std::fmod(0.618 * k, 1.0), &dir, &radiance, &pdf));
      EXPECT_GT(dir.z(), -0.1) << k;
    }
  }
}

TEST(SceneSetupTest, GroundNormalRoundTripsAndIsRefusedWhereItCannotHold) {
  testing::TempDir dir;
  testing::WriteDataset(dir, GroundScene(Eigen::Matrix3d::Identity()));
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  testing::TempDir copy;
  ASSERT_TRUE(WriteSceneJson(dataset, copy.path()).ok());
  const json written = json::parse(testing::ReadTestFile(copy.Join("scene.json")));
  EXPECT_EQ(written["lights"][1]["ground_normal"], json({0.0, 0.0, 1.0}));
  // Without the key nothing is written (files before it read and write the same).
  dataset.lights[1].ground_normal.setZero();
  testing::TempDir plain;
  ASSERT_TRUE(WriteSceneJson(dataset, plain.path()).ok());
  EXPECT_FALSE(json::parse(testing::ReadTestFile(plain.Join("scene.json")))["lights"][1].contains(
      "ground_normal"));
  // Bad values: one error naming the field.
  for (const json& bad : {json({0, 0, 0}), json({0, 1}), json("up")}) {
    json scene = GroundScene(Eigen::Matrix3d::Identity());
    scene["lights"][1]["ground_normal"] = bad;
    testing::TempDir d;
    testing::WriteDataset(d, scene);
    Dataset ignored;
    const Status status = ReadDataset(d.path(), &ignored);
    ASSERT_FALSE(status.ok()) << bad.dump();
    EXPECT_NE(status.message().find("lights[1].ground_normal"), std::string::npos)
        << status.message();
  }
  json camera = GroundScene(Eigen::Matrix3d::Identity());
  camera["lights"][1]["frame"] = "camera";
  testing::TempDir d;
  testing::WriteDataset(d, camera);
  Dataset ignored;
  const Status status = ReadDataset(d.path(), &ignored);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("only a world-fixed environment"), std::string::npos)
      << status.message();
}

// A finite ground (ground_radius, ground_point): the map keeps its texels below the horizon (each
// ray is tested on the disc instead, tests/render/support_disc_test.cc), every view carries the
// disc, the keys round-trip, and bad values are one error naming the field.
TEST(SceneSetupTest, GroundDiscKeepsTheMapAndReachesEveryView) {
  json scene = GroundScene(Eigen::Matrix3d::Identity());
  scene["lights"][1]["ground_radius"] = 2.5;
  scene["lights"][1]["ground_point"] = {0.1, -0.2, -0.5};
  testing::TempDir dir;
  testing::WriteDataset(dir, scene);
  ASSERT_TRUE(WriteExr(dir.Join("probes/env.exr"), Image(64, 32, 3, 1.0f)).ok());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  EXPECT_EQ(dataset.lights[1].ground_radius, 2.5);
  DatasetViews views;
  ASSERT_TRUE(MakeDatasetViews(dataset, &views).ok());
  for (const ViewSetup& view : views.views) {
    EXPECT_NEAR(view.environment->Radiance(Eigen::Vector3d(0.3, 0.1, -0.9).normalized()).x(), 1.0,
                1e-6);
    EXPECT_EQ(view.support.radius, 2.5);
    EXPECT_TRUE(view.support.centre.isApprox(Eigen::Vector3d(0.1, -0.2, -0.5)));
    EXPECT_TRUE(view.support.normal.isApprox(Eigen::Vector3d::UnitZ()));
  }
  testing::TempDir copy;
  ASSERT_TRUE(WriteSceneJson(dataset, copy.path()).ok());
  const json written = json::parse(testing::ReadTestFile(copy.Join("scene.json")));
  EXPECT_EQ(written["lights"][1]["ground_radius"], 2.5);
  EXPECT_EQ(written["lights"][1]["ground_point"], json({0.1, -0.2, -0.5}));

  struct Bad {
    const char* key;
    json value;
    const char* field;
  };
  const Bad bads[] = {{"ground_radius", 0.0, "ground_radius"},
                      {"ground_radius", -1.0, "ground_radius"},
                      {"ground_radius", "far", "ground_radius"},
                      {"ground_point", json({0, 1}), "ground_point"},
                      {"ground_point", nullptr, "ground_point"}};
  for (const Bad& bad : bads) {
    json b = scene;
    if (bad.value.is_null()) {
      b["lights"][1].erase(bad.key);
    } else {
      b["lights"][1][bad.key] = bad.value;
    }
    testing::TempDir d;
    testing::WriteDataset(d, b);
    Dataset ignored;
    const Status status = ReadDataset(d.path(), &ignored);
    ASSERT_FALSE(status.ok()) << bad.key << " " << bad.value.dump();
    EXPECT_NE(status.message().find(std::string("lights[1].") + bad.field), std::string::npos)
        << status.message();
  }
  json no_normal = scene;
  no_normal["lights"][1].erase("ground_normal");
  testing::TempDir d;
  testing::WriteDataset(d, no_normal);
  Dataset ignored;
  const Status status = ReadDataset(d.path(), &ignored);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("needs ground_normal"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace sft
