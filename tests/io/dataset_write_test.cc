// WriteSceneJson (src/io/dataset_write.cc): round trips, documented normalizations, extras.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "src/core/memory.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "tests/testing/dataset_scenes.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using json = nlohmann::json;
using testing::CyclesDatasets;
using testing::MinimalScene;
using testing::SceneWithNestedExtras;
using testing::TempDir;
using testing::WriteJson;

constexpr int kWidth = testing::kMinimalSceneWidth;

void ExpectSameDataset(const Dataset& a, const Dataset& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (size_t i = 0; i < a.cameras.size(); ++i) {
    EXPECT_EQ(a.cameras[i].id, b.cameras[i].id);
    EXPECT_EQ(a.cameras[i].model, b.cameras[i].model);
    EXPECT_EQ(a.cameras[i].width, b.cameras[i].width);
    EXPECT_EQ(a.cameras[i].height, b.cameras[i].height);
    EXPECT_EQ(a.cameras[i].params, b.cameras[i].params);
  }
  EXPECT_EQ(a.camera_extra, b.camera_extra);
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) {
    EXPECT_EQ(a.lights[i].id, b.lights[i].id);
    EXPECT_EQ(a.lights[i].type, b.lights[i].type);
    EXPECT_EQ(a.lights[i].frame, b.lights[i].frame);
    EXPECT_EQ(a.lights[i].position, b.lights[i].position);
    EXPECT_EQ(a.lights[i].intensity, b.lights[i].intensity);
    EXPECT_EQ(a.lights[i].image, b.lights[i].image);
    EXPECT_EQ(a.lights[i].world_from_env, b.lights[i].world_from_env);
    EXPECT_EQ(a.lights[i].scale, b.lights[i].scale);
    EXPECT_EQ(a.lights[i].extra, b.lights[i].extra);
  }
  ASSERT_EQ(a.views.size(), b.views.size());
  for (size_t i = 0; i < a.views.size(); ++i) {
    EXPECT_EQ(a.views[i].image, b.views[i].image);
    EXPECT_EQ(a.views[i].mask, b.views[i].mask);
    EXPECT_EQ(a.views[i].camera_id, b.views[i].camera_id);
    EXPECT_EQ(a.views[i].camera, b.views[i].camera);
    EXPECT_EQ(a.views[i].light_ids, b.views[i].light_ids);
    EXPECT_EQ(a.views[i].lights, b.views[i].lights);
    EXPECT_EQ(a.views[i].cam_from_world.rotation.coeffs(),
              b.views[i].cam_from_world.rotation.coeffs());
    EXPECT_EQ(a.views[i].cam_from_world.translation, b.views[i].cam_from_world.translation);
    EXPECT_EQ(a.views[i].extra, b.views[i].extra);
    EXPECT_EQ(a.views[i].cam_from_world_extra, b.views[i].cam_from_world_extra);
  }
  EXPECT_EQ(a.background, b.background);
  EXPECT_EQ(a.gt_mesh, b.gt_mesh);
  EXPECT_EQ(a.ground_truth, b.ground_truth);
  EXPECT_EQ(a.extra, b.extra);
}

TEST(DatasetWrite, CyclesDatasetsRoundTrip) {
  for (const std::string& dir : CyclesDatasets()) {
    SCOPED_TRACE(dir);
    Dataset original;
    ASSERT_TRUE(ReadDataset(dir, &original).ok());
    ASSERT_FALSE(original.ground_truth.is_null());
    TempDir out;
    const Status written = WriteSceneJson(original, out.path());
    ASSERT_TRUE(written.ok()) << written.message();
    Dataset copy;
    const Status status = ReadDataset(out.path(), &copy);
    ASSERT_TRUE(status.ok()) << status.message();
    ExpectSameDataset(original, copy);
  }
}

json ReadJson(const std::string& file) {
  std::ifstream in(file);
  return json::parse(in);
}

// Reads DIR, writes it to a fresh directory and returns the written scene.json as JSON.
json RoundTripJson(const std::string& dir) {
  Dataset dataset;
  const Status read = ReadDataset(dir, &dataset);
  EXPECT_TRUE(read.ok()) << read.message();
  TempDir out;
  const Status written = WriteSceneJson(dataset, out.path());
  EXPECT_TRUE(written.ok()) << written.message();
  if (!read.ok() || !written.ok()) return json();
  return ReadJson(out.Join("scene.json"));
}

// The reference datasets hold unit quaternions and every documented key explicitly, so no
// normalization applies: the written scene.json equals the original as JSON.
TEST(DatasetWrite, CyclesScenesRoundTripExactlyAsJson) {
  bool saw_mapping = false;
  for (const std::string& dir : CyclesDatasets()) {
    SCOPED_TRACE(dir);
    const json original = ReadJson(dir + "/scene.json");
    const json written = RoundTripJson(dir);
    EXPECT_EQ(written, original) << "diff: " << json::diff(original, written).dump();
    for (const json& light : written["lights"])
      saw_mapping = saw_mapping || light.contains("mapping");
  }
  EXPECT_TRUE(saw_mapping);  // sphere_env_studio's environment light.
}

TEST(DatasetWrite, NestedExtrasRoundTripExactlyAsJson) {
  json scene = SceneWithNestedExtras();
  scene["rig"] = {{"turntable", true}};
  TempDir dir;
  WriteJson(dir.path(), scene);
  const json written = RoundTripJson(dir.path());
  EXPECT_EQ(written, scene) << "diff: " << json::diff(scene, written).dump();
}

TEST(DatasetWrite, OnlyDocumentedNormalizations) {
  json scene = MinimalScene();
  scene["lights"][0].erase("frame");
  scene["lights"][0]["intensity"] = 4.5;
  scene["lights"][1].erase("world_from_env");
  scene["lights"][1].erase("scale");
  scene["views"][0]["cam_from_world"]["rotation"] = {0, 0, 0, 3};
  scene["views"][0]["mask"] = nullptr;
  scene["views"][1].erase("lights");
  scene.erase("background");
  scene["cameras"][0]["width"] = 16.0;
  TempDir dir;
  WriteJson(dir.path(), scene);
  const json written = RoundTripJson(dir.path());

  json expected = scene;
  expected["lights"][0]["frame"] = "world";
  expected["lights"][0]["intensity"] = {4.5, 4.5, 4.5};
  expected["lights"][1]["world_from_env"] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  expected["lights"][1]["scale"] = 1.0;
  expected["views"][0]["cam_from_world"]["rotation"] = {0, 0, 0, 1};
  expected["views"][0].erase("mask");
  expected["views"][1]["lights"] = json::array();
  expected["background"] = "black";
  EXPECT_EQ(written, expected) << "diff: " << json::diff(expected, written).dump();
  EXPECT_TRUE(written["cameras"][0]["width"].is_number_integer());
}

TEST(DatasetWrite, DocumentedKeysWinOverExtras) {
  TempDir dir;
  WriteJson(dir.path(), MinimalScene());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  dataset.camera_extra[0] = {{"width", 999}, {"serial", "B7"}};
  dataset.camera_extra.push_back({{"orphan", 1}});  // beyond cameras.size(): ignored.
  dataset.lights[0].extra = {{"type", "spot"}, {"falloff", "none"}};
  dataset.views[1].extra = {{"camera", "c9"}, {"note", "x"}};
  dataset.views[1].cam_from_world_extra = {{"rotation", {0, 0, 0, 1}}, {"frame", "opencv"}};
  dataset.extra = {{"format", "other/2"}, {"rig", 1}};
  TempDir out;
  ASSERT_TRUE(WriteSceneJson(dataset, out.path()).ok());
  const json written = ReadJson(out.Join("scene.json"));
  EXPECT_EQ(written["format"], "sft-dataset/1");
  EXPECT_EQ(written["rig"], 1);
  EXPECT_EQ(written["cameras"][0]["width"], kWidth);
  EXPECT_EQ(written["cameras"][0]["serial"], "B7");
  EXPECT_EQ(written["cameras"].size(), 1u);
  EXPECT_EQ(written["lights"][0]["type"], "point");
  EXPECT_EQ(written["lights"][0]["falloff"], "none");
  EXPECT_EQ(written["views"][1]["camera"], "c0");
  EXPECT_EQ(written["views"][1]["note"], "x");
  EXPECT_EQ(written["views"][1]["cam_from_world"]["rotation"], json({0, 1, 0, 0}));
  EXPECT_EQ(written["views"][1]["cam_from_world"]["frame"], "opencv");
  Dataset copy;
  const Status status = ReadDataset(out.path(), &copy);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(copy.camera_extra[0], json({{"serial", "B7"}}));
}

TEST(DatasetWrite, RoundTripKeepsExtraKeysAndEnvironment) {
  json scene = MinimalScene();
  scene["background"] = "environment";
  scene["capture_rig"] = {{"name", "turntable"}, {"frames", {1, 2, 3}}};
  scene["views"][0]["cam_from_world"]["rotation"] = {0.1, 0.2, -0.3, 0.4};
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset original;
  ASSERT_TRUE(ReadDataset(dir.path(), &original).ok());
  TempDir out;
  ASSERT_TRUE(WriteSceneJson(original, out.Join("nested/ds")).ok());
  Dataset copy;
  const Status status = ReadDataset(out.Join("nested/ds"), &copy);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectSameDataset(original, copy);
  EXPECT_EQ(copy.extra["capture_rig"]["name"], "turntable");
  EXPECT_EQ(copy.background, Background::kEnvironment);
}

TEST(DatasetWrite, DatasetBuiltInCodeUsesIndices) {
  Dataset dataset;
  Camera camera;
  camera.id = "cam";
  camera.model = CameraModel::kSimpleRadial;
  camera.width = 32;
  camera.height = 24;
  camera.params = {30, 16, 12, 0.01};
  dataset.cameras.push_back(camera);
  LightSpec light;
  light.id = "sun";
  light.position = Eigen::Vector3d(1, 2, 3);
  light.intensity = Eigen::Vector3d(5, 5, 5);
  dataset.lights.push_back(light);
  ViewSpec view;
  view.image = "images/a.exr";
  view.camera = 0;  // only indices are set.
  view.lights = {0};
  view.cam_from_world.translation = Eigen::Vector3d(0, 0, 3);
  dataset.views.push_back(view);
  dataset.gt_mesh = "gt/mesh.ply";

  TempDir out;
  ASSERT_TRUE(WriteSceneJson(dataset, out.path()).ok());
  Dataset copy;
  const Status status = ReadDataset(out.path(), &copy);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(copy.views[0].camera_id, "cam");
  EXPECT_EQ(copy.views[0].light_ids, (std::vector<std::string>{"sun"}));
  EXPECT_EQ(copy.cameras[0].model, CameraModel::kSimpleRadial);
  EXPECT_EQ(copy.gt_mesh, "gt/mesh.ply");
  EXPECT_EQ(copy.ground_truth["mesh"], "gt/mesh.ply");

  // A reference that ReadDataset would reject is not written.
  dataset.views[0].camera = -1;
  dataset.views[0].camera_id = "other";
  TempDir bad;
  const Status rejected = WriteSceneJson(dataset, bad.path());
  ASSERT_FALSE(rejected.ok());
  EXPECT_THAT(rejected.message(), AllOf(HasSubstr("views[0].camera"), HasSubstr("other")));
  EXPECT_FALSE(std::filesystem::exists(bad.Join("scene.json")));
}

}  // namespace
}  // namespace sft
