// Directional lights in scene.json (docs/dataset.md, "Directional light"): read with the direction
// normalized, written back, turned with the camera when camera-fixed (MakeDatasetViews), and each
// bad field refused with one error line naming its JSON path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "tests/testing/dataset_scenes.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using json = nlohmann::json;
using testing::MinimalScene;
using testing::ReadError;

// MinimalScene with a third light, a directional "sun" travelling along (0, 3, −4)/5 with a grey
// irradiance, that both views list.
json SunScene() {
  json scene = MinimalScene();
  scene["lights"].push_back(
      {{"id", "sun"}, {"type", "directional"}, {"direction", {0, 3, -4}}, {"irradiance", 2.5}});
  scene["views"][0]["lights"] = {"sun"};
  scene["views"][1]["lights"] = {"sun"};
  return scene;
}

Status Read(const json& scene, Dataset* dataset) {
  testing::TempDir dir;
  testing::WriteDataset(dir, scene);
  return ReadDataset(dir.path(), dataset);
}

TEST(DirectionalLightDataset, ReadsANormalizedDirectionAndAGreyIrradiance) {
  Dataset dataset;
  ASSERT_TRUE(Read(SunScene(), &dataset).ok());
  const LightSpec& sun = dataset.lights[2];
  EXPECT_EQ(sun.type, LightType::kDirectional);
  EXPECT_EQ(sun.frame, LightFrame::kWorld);
  EXPECT_NEAR((sun.direction - Eigen::Vector3d(0, 0.6, -0.8)).norm(), 0.0, 1e-15);
  EXPECT_EQ(sun.irradiance, Eigen::Vector3d::Constant(2.5));
  EXPECT_TRUE(sun.extra.is_null());
}

TEST(DirectionalLightDataset, RoundTripsThroughSceneJson) {
  json scene = SunScene();
  scene["lights"][2]["frame"] = "camera";
  scene["lights"][2]["comment"] = "kept";
  Dataset dataset;
  ASSERT_TRUE(Read(scene, &dataset).ok());
  testing::TempDir copy;
  ASSERT_TRUE(WriteSceneJson(dataset, copy.path()).ok());
  const json written = json::parse(testing::ReadTestFile(copy.Join("scene.json")));
  const json& sun = written["lights"][2];
  EXPECT_EQ(sun["type"], "directional");
  EXPECT_EQ(sun["frame"], "camera");
  EXPECT_EQ(sun["irradiance"], json({2.5, 2.5, 2.5}));
  EXPECT_EQ(sun["comment"], "kept");
  Dataset again;
  ASSERT_TRUE(ReadDataset(copy.path(), &again).ok());
  EXPECT_EQ(again.lights[2].direction, dataset.lights[2].direction);  // unit: written exactly.
  EXPECT_EQ(again.lights[2].irradiance, dataset.lights[2].irradiance);
  EXPECT_EQ(again.lights[2].frame, LightFrame::kCamera);
}

// A camera-fixed direction is turned into the world by each view's rotation: direction_world =
// Rᵀ·direction_camera; a world-fixed one is the same in every view.
TEST(DirectionalLightDataset, CameraFixedDirectionTurnsWithEachView) {
  for (const char* frame : {"world", "camera"}) {
    json scene = SunScene();
    scene["lights"][2]["frame"] = frame;
    const double h = std::sqrt(0.5);
    scene["views"][1]["cam_from_world"]["rotation"] = {h, 0, h, 0};  // 90° about camera y.
    Dataset dataset;
    ASSERT_TRUE(Read(scene, &dataset).ok());
    DatasetViews views;
    ASSERT_TRUE(MakeDatasetViews(dataset, &views).ok());
    for (size_t v = 0; v < 2; ++v) {
      ASSERT_EQ(views.views[v].directional_lights.size(), 1u);
      const DirectionalLight& light = views.views[v].directional_lights[0];
      Eigen::Vector3d expected = dataset.lights[2].direction;
      if (std::string(frame) == "camera") {
        expected = dataset.views[v].cam_from_world.rotation.conjugate() * expected;
      }
      EXPECT_NEAR((light.direction - expected).norm(), 0.0, 1e-12) << frame << " view " << v;
      EXPECT_EQ(light.light_index, 2);
      EXPECT_EQ(light.camera_frame, std::string(frame) == "camera");
      EXPECT_TRUE(views.views[v].point_lights.empty());
    }
  }
}

TEST(DirectionalLightDataset, BadFieldsAreOneErrorNamingThePath) {
  const auto error = [](const char* key, const json& value) {
    json scene = SunScene();
    if (value.is_null()) {
      scene["lights"][2].erase(key);
    } else {
      scene["lights"][2][key] = value;
    }
    return ReadError(scene);
  };
  EXPECT_THAT(error("direction", json({0, 0, 0})),
              HasSubstr("lights[2].direction: must have a non-zero finite length"));
  EXPECT_THAT(error("direction", json({1, 0})),
              HasSubstr("lights[2].direction: expected 3 numbers, got 2"));
  EXPECT_THAT(error("direction", json()), HasSubstr("lights[2].direction: missing"));
  EXPECT_THAT(error("irradiance", json({1, -1, 1})),
              HasSubstr("lights[2].irradiance: must be non-negative"));
  EXPECT_THAT(error("irradiance", json()), HasSubstr("lights[2].irradiance: missing"));
  EXPECT_THAT(error("irradiance", json("bright")), HasSubstr("lights[2].irradiance: "));
  EXPECT_THAT(error("frame", json("object")),
              AllOf(HasSubstr("lights[2].frame: "), HasSubstr("object")));
  // A point light's position is not a directional light's key: kept as an extra, not an error.
  Dataset dataset;
  json scene = SunScene();
  scene["lights"][2]["position"] = {1, 2, 3};
  ASSERT_TRUE(Read(scene, &dataset).ok());
  EXPECT_EQ(dataset.lights[2].extra["position"], json({1, 2, 3}));
  for (const std::string& message :
       {error("direction", json({0, 0, 0})), error("irradiance", json({1, -1, 1}))}) {
    EXPECT_EQ(message.find('\n'), std::string::npos);
    EXPECT_THAT(message, HasSubstr("scene.json"));
  }
}

}  // namespace
}  // namespace sft
