// Reading scene.json (src/io/dataset.h): parsed values, defaults, extras kept, ParseSceneJson.
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

using ::testing::HasSubstr;
using json = nlohmann::json;
using testing::DataDir;
using testing::MinimalScene;
using testing::SceneWithNestedExtras;
using testing::TempDir;
using testing::WriteDataset;
using testing::WriteJson;

TEST(DatasetRead, MinimalSceneIsParsed) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  Dataset dataset;
  const Status status = ReadDataset(dir.path(), &dataset);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(dataset.root, dir.path());
  ASSERT_EQ(dataset.cameras.size(), 1u);
  EXPECT_EQ(dataset.cameras[0].model, CameraModel::kPinhole);
  EXPECT_EQ(dataset.cameras[0].params, (std::vector<double>{20, 20, 8, 6}));
  ASSERT_EQ(dataset.lights.size(), 2u);
  EXPECT_EQ(dataset.lights[0].type, LightType::kPoint);
  EXPECT_EQ(dataset.lights[0].frame, LightFrame::kCamera);
  EXPECT_EQ(dataset.lights[0].intensity, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(dataset.lights[1].type, LightType::kEnvironment);
  EXPECT_EQ(dataset.lights[1].image, "probes/env.exr");
  EXPECT_EQ(dataset.lights[1].world_from_env(0, 1), -1.0);
  EXPECT_EQ(dataset.lights[1].scale, 2.5);
  ASSERT_EQ(dataset.views.size(), 2u);
  EXPECT_EQ(dataset.views[0].mask, "masks/000.png");
  EXPECT_EQ(dataset.views[1].mask, "");
  EXPECT_EQ(dataset.views[1].camera, 0);
  EXPECT_EQ(dataset.views[1].lights, (std::vector<int>{0, 1}));
  EXPECT_EQ(dataset.views[1].light_ids, (std::vector<std::string>{"flash", "probe"}));
  EXPECT_EQ(dataset.views[1].cam_from_world.rotation.x(), 1.0);
  EXPECT_EQ(dataset.views[1].cam_from_world.translation, Eigen::Vector3d(0.5, 0, 2));
  EXPECT_EQ(dataset.background, Background::kBlack);
  EXPECT_EQ(dataset.gt_mesh, "gt/mesh.ply");
  EXPECT_EQ(dataset.ground_truth["material"]["albedo"][0], 0.5);
  EXPECT_TRUE(dataset.extra.is_null());
  ASSERT_EQ(dataset.camera_extra.size(), 1u);
  EXPECT_TRUE(dataset.camera_extra[0].is_null());
  EXPECT_TRUE(dataset.lights[0].extra.is_null());
  EXPECT_TRUE(dataset.lights[1].extra.is_null());
  EXPECT_TRUE(dataset.views[0].extra.is_null());
  EXPECT_TRUE(dataset.views[0].cam_from_world_extra.is_null());
  const Status files = CheckDatasetFiles(dataset);
  EXPECT_TRUE(files.ok()) << files.message();
}

TEST(DatasetRead, DefaultsAndAlternatives) {
  json scene = MinimalScene();
  scene["lights"][0].erase("frame");
  scene["lights"][0]["intensity"] = 4.5;  // a single number is grey.
  scene["lights"][1].erase("world_from_env");
  scene["lights"][1].erase("scale");
  scene["views"][0]["cam_from_world"]["rotation"] = {0, 0, 0, 3};  // normalized on read.
  scene["cameras"][0]["width"] = 16.0;                             // integral floats are fine.
  scene.erase("background");
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  const Status status = ReadDataset(dir.path(), &dataset);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(dataset.lights[0].frame, LightFrame::kWorld);
  EXPECT_EQ(dataset.lights[0].intensity, Eigen::Vector3d(4.5, 4.5, 4.5));
  EXPECT_TRUE(dataset.lights[1].world_from_env.isIdentity());
  EXPECT_EQ(dataset.lights[1].scale, 1.0);
  EXPECT_EQ(dataset.views[0].cam_from_world.rotation.coeffs(), Eigen::Vector4d(0, 0, 1, 0));
  EXPECT_EQ(dataset.cameras[0].width, 16);
  EXPECT_EQ(dataset.background, Background::kBlack);
}

TEST(DatasetRead, EnvironmentBackground) {
  json scene = MinimalScene();
  scene["background"] = "environment";
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  EXPECT_EQ(dataset.background, Background::kEnvironment);
}

TEST(DatasetRead, UnknownTopLevelKeysAreKept) {
  json scene = MinimalScene();
  scene["capture_rig"] = {{"name", "turntable"}, {"frames", {1, 2, 3}}};
  scene["note"] = "hello";
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  EXPECT_EQ(dataset.extra.size(), 2u);
  EXPECT_EQ(dataset.extra["capture_rig"], scene["capture_rig"]);
  EXPECT_EQ(dataset.extra["note"], "hello");
}

TEST(DatasetRead, ImportKeysAreParsedAndWrittenBack) {
  json scene = MinimalScene();
  scene["sparse_points"] = "sparse/points3D.ply";
  scene["initial_mesh"] = "init/mesh.ply";
  scene["dense_points"] = "init/fused.ply";
  scene["source_from_world"] = {
      {"scale", 3.5}, {"rotation", {0, 0, 0, 2}}, {"translation", {1, 2, 3}}, {"note", "kept"}};
  scene["image_encoding"] = "sRGB 8-bit JPEG converted to PNG";
  scene["lighting"] = "unknown";
  scene["support_plane"] = {{"normal", {0, 0, 2}}, {"point", {0.5, 0, -0.25}}};
  scene["views"][0]["lights"] = json::array();  // unknown lighting reads fine.
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  EXPECT_TRUE(dataset.extra.is_null());
  EXPECT_EQ(dataset.sparse_points, "sparse/points3D.ply");
  EXPECT_EQ(dataset.initial_mesh, "init/mesh.ply");
  EXPECT_EQ(dataset.dense_points, "init/fused.ply");
  EXPECT_EQ(dataset.image_encoding, "sRGB 8-bit JPEG converted to PNG");
  EXPECT_EQ(dataset.lighting, "unknown");
  ASSERT_TRUE(dataset.has_source_from_world);
  EXPECT_EQ(dataset.source_from_world.scale, 3.5);
  EXPECT_EQ(dataset.source_from_world.rotation.z(), 1.0);  // normalised.
  // 180° about z, scale 3.5, then the translation.
  EXPECT_LT(
      (dataset.source_from_world * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(-2.5, 2, 3)).norm(),
      1e-12);
  ASSERT_TRUE(dataset.has_support_plane);
  EXPECT_EQ(dataset.support_normal, Eigen::Vector3d(0, 0, 1));  // normalised.
  EXPECT_EQ(dataset.support_point, Eigen::Vector3d(0.5, 0, -0.25));
  EXPECT_TRUE(dataset.views[0].lights.empty());
  EXPECT_THAT(CheckViewsHaveLights(dataset).message(), HasSubstr("views[0].lights: empty"));
  TempDir copy;
  ASSERT_TRUE(WriteSceneJson(dataset, copy.path()).ok());
  Dataset again;
  ASSERT_TRUE(ReadDataset(copy.path(), &again).ok());
  EXPECT_EQ(again.sparse_points, dataset.sparse_points);
  EXPECT_EQ(again.lighting, dataset.lighting);
  EXPECT_EQ(again.source_from_world.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(again.source_from_world.extra["note"], "kept");
  EXPECT_TRUE(again.has_support_plane);
  EXPECT_EQ(again.support_point, dataset.support_point);
  // Without the keys nothing changes.
  Dataset plain;
  WriteJson(copy.path(), MinimalScene());
  ASSERT_TRUE(ReadDataset(copy.path(), &plain).ok());
  EXPECT_FALSE(plain.has_source_from_world);
  EXPECT_FALSE(plain.has_support_plane);
  EXPECT_TRUE(plain.sparse_points.empty());
  EXPECT_TRUE(CheckViewsHaveLights(plain).ok());
}

TEST(DatasetRead, UnknownNestedKeysAreKept) {
  const json scene = SceneWithNestedExtras();
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  const Status status = ReadDataset(dir.path(), &dataset);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(dataset.extra.is_null());
  ASSERT_EQ(dataset.camera_extra.size(), 1u);
  EXPECT_EQ(dataset.camera_extra[0],
            json({{"serial", "A123"}, {"exposure", scene["cameras"][0]["exposure"]}}));
  EXPECT_EQ(dataset.lights[0].extra,
            json({{"falloff", "inverse_square"}, {"image", "not/for/point/lights.exr"}}));
  EXPECT_EQ(dataset.lights[0].image, "");  // not interpreted for a point light.
  EXPECT_EQ(dataset.lights[1].extra, json({{"mapping", "equirectangular, +Z up"}}));
  EXPECT_TRUE(dataset.views[0].extra.is_null());
  EXPECT_EQ(dataset.views[0].cam_from_world_extra, json({{"covariance", {0.1, 0.2}}}));
  EXPECT_EQ(dataset.views[1].extra,
            json({{"timestamp", 12.5}, {"tags", scene["views"][1]["tags"]}}));
  EXPECT_TRUE(dataset.views[1].cam_from_world_extra.is_null());
}

// A UTF-8 byte-order mark before the JSON is skipped.
TEST(DatasetRead, ByteOrderMarkIsSkipped) {
  TempDir dir;
  std::ofstream(dir.Join("scene.json")) << "\xEF\xBB\xBF" << MinimalScene().dump(1);
  Dataset dataset;
  const Status status = ReadDataset(dir.path(), &dataset);
  EXPECT_TRUE(status.ok()) << status.message();
}

// ParseSceneJson (the fuzzed entry point) is ReadDataset without the file read.
TEST(DatasetRead, ParseSceneJsonMatchesReadDataset) {
  const std::string dir = testing::DataDir() + "/cycles/bunny_point_diffuse";
  std::ifstream in(dir + "/scene.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Dataset from_file, from_buffer;
  ASSERT_TRUE(ReadDataset(dir, &from_file).ok());
  const Status status = ParseSceneJson(text, dir, &from_buffer);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(from_buffer.root, dir);
  ASSERT_EQ(from_buffer.views.size(), from_file.views.size());
  EXPECT_EQ(from_buffer.views.back().image, from_file.views.back().image);
  const Status bad = ParseSceneJson("{\"format\": ", "somewhere", &from_buffer);
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.message(), ::testing::StartsWith("somewhere/scene.json: invalid JSON"));
}

}  // namespace
}  // namespace sft
