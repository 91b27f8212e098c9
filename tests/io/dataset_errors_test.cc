// Bad scene.json files: each is one error naming the file and the JSON path.
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
using testing::MinimalScene;
using testing::ReadError;
using testing::TempDir;
using testing::WriteJson;

TEST(DatasetErrors, BadImportKeys) {
  json scene = MinimalScene();
  scene["initial_mesh"] = "../outside.ply";
  EXPECT_THAT(ReadError(scene), HasSubstr("initial_mesh"));
  scene = MinimalScene();
  scene["sparse_points"] = "/abs/points.ply";
  EXPECT_THAT(ReadError(scene), HasSubstr("sparse_points"));
  scene = MinimalScene();
  scene["source_from_world"] = {
      {"scale", 0}, {"rotation", {1, 0, 0, 0}}, {"translation", {0, 0, 0}}};
  EXPECT_THAT(ReadError(scene), HasSubstr("source_from_world.scale"));
  scene["source_from_world"] = {{"scale", 1}, {"rotation", {1, 0, 0}}, {"translation", {0, 0, 0}}};
  EXPECT_THAT(ReadError(scene), HasSubstr("source_from_world.rotation"));
  scene["source_from_world"] = {{"scale", 1}, {"rotation", {1, 0, 0, 0}}};
  EXPECT_THAT(ReadError(scene), HasSubstr("source_from_world.translation: missing"));
  scene = MinimalScene();
  scene["support_plane"] = {{"normal", {0, 0, 0}}, {"point", {0, 0, 0}}};
  EXPECT_THAT(ReadError(scene), HasSubstr("support_plane.normal: must not be zero"));
  scene["support_plane"] = {{"normal", {0, 0, 1}}};
  EXPECT_THAT(ReadError(scene), HasSubstr("support_plane.point: missing"));
  scene["support_plane"] = {{"normal", {0, 1}}, {"point", {0, 0, 0}}};
  EXPECT_THAT(ReadError(scene), HasSubstr("support_plane.normal"));
  scene["support_plane"] = "floor";
  EXPECT_THAT(ReadError(scene), HasSubstr("support_plane: expected an object"));
  scene = MinimalScene();
  scene["lighting"] = 3;
  EXPECT_THAT(ReadError(scene), HasSubstr("lighting"));
}

TEST(DatasetErrors, MissingSceneJson) {
  TempDir dir;
  Dataset dataset;
  Status status = ReadDataset(dir.path(), &dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr(dir.Join("scene.json")), HasSubstr("not found")));

  status = ReadDataset(dir.Join("no_such_dir"), &dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("no_such_dir"));
}

TEST(DatasetErrors, InvalidJson) {
  TempDir dir;
  std::ofstream(dir.Join("scene.json"))
      << "{\n  \"format\": \"sft-dataset/1\",\n  \"cameras\": [\n}";
  Dataset dataset;
  const Status status = ReadDataset(dir.path(), &dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr(dir.Join("scene.json")), HasSubstr("invalid JSON"),
                                      HasSubstr("line 4")));
  EXPECT_EQ(status.message().find('\n'), std::string::npos);  // one line.

  std::ofstream(dir.Join("scene.json"), std::ios::trunc) << "{\"format\": 1e999}";
  const Status overflow = ReadDataset(dir.path(), &dataset);
  ASSERT_FALSE(overflow.ok());
  EXPECT_THAT(overflow.message(), AllOf(HasSubstr("scene.json"), HasSubstr("invalid JSON")));
}

TEST(DatasetErrors, TopLevelNotAnObject) {
  EXPECT_THAT(ReadError(json::array({1, 2})), HasSubstr("top level"));
}

TEST(DatasetErrors, WrongFormatTag) {
  json scene = MinimalScene();
  scene["format"] = "sft-dataset/2";
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("format: "), HasSubstr("sft-dataset/2")));
  scene.erase("format");
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("format: missing")));
}

TEST(DatasetErrors, UnknownCameraModel) {
  json scene = MinimalScene();
  scene["cameras"][0]["model"] = "FISHEYE";
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("cameras[0].model: "), HasSubstr("FISHEYE")));
}

TEST(DatasetErrors, WrongCameraParamCount) {
  json scene = MinimalScene();
  scene["cameras"][0]["params"] = {20, 20, 8};
  EXPECT_THAT(ReadError(scene), HasSubstr("cameras[0].params: PINHOLE needs 4 values, got 3"));
}

TEST(DatasetErrors, BadCameraSize) {
  json scene = MinimalScene();
  scene["cameras"][0]["height"] = -12;
  EXPECT_THAT(ReadError(scene), HasSubstr("cameras[0].height: expected a positive integer"));
  scene["cameras"][0]["height"] = 12.5;
  EXPECT_THAT(ReadError(scene), HasSubstr("cameras[0].height"));
  scene["cameras"][0].erase("height");
  EXPECT_THAT(ReadError(scene), HasSubstr("cameras[0].height: missing"));
}

// Sizes beyond kMaxCameraSide per side or kMaxCameraPixels in all are refused on read (a
// 100000² camera used to end in std::bad_alloc when rendered).
TEST(DatasetErrors, CameraTooLarge) {
  json scene = MinimalScene();
  scene["cameras"][0]["width"] = 100000;
  EXPECT_THAT(ReadError(scene),
              HasSubstr("cameras[0].width: 100000 is larger than the maximum 65536 pixels"));
  scene["cameras"][0]["width"] = 65536;
  scene["cameras"][0]["height"] = 65536;
  EXPECT_THAT(ReadError(scene), HasSubstr("cameras[0]: 65536x65536 has 4294967296 pixels, more "
                                          "than the maximum 1073741824"));
  scene["cameras"][0]["height"] = 16384;  // Exactly 2^30 pixels: accepted.
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  EXPECT_TRUE(ReadDataset(dir.path(), &dataset).ok());
}

// A camera that passes the read limits but whose views cannot be rendered in the memory this
// machine has is refused before anything is allocated, naming the camera and both sizes.
TEST(DatasetErrors, ViewsThatDoNotFitInMemory) {
  json scene = MinimalScene();
  scene["cameras"][0]["width"] = 32768;
  scene["cameras"][0]["height"] = 32768;
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  const uint64_t needed = EstimateViewRenderBytes(dataset.cameras[0]);
  EXPECT_EQ(needed, 3 * 16 * (uint64_t{1} << 30));  // 48 GiB.
  if (AvailableMemoryBytes() >= needed) GTEST_SKIP() << "this machine has 48 GiB available";
  DatasetViews views;
  const Status status = MakeDatasetViews(dataset, &views);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("cameras[0] (\"c0\"): rendering one view of "
                                          "32768x32768 pixels needs an estimated 48 GB, more "
                                          "than the "));
  EXPECT_TRUE(views.views.empty());
}

TEST(DatasetErrors, DuplicateCameraId) {
  json scene = MinimalScene();
  scene["cameras"].push_back(scene["cameras"][0]);
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("cameras[1].id"), HasSubstr("duplicate")));
}

TEST(DatasetErrors, WrongQuaternionLength) {
  json scene = MinimalScene();
  scene["views"][1]["cam_from_world"]["rotation"] = {1, 0, 0};
  EXPECT_THAT(ReadError(scene),
              HasSubstr("scene.json: views[1].cam_from_world.rotation: expected 4 numbers, got 3"));
}

TEST(DatasetErrors, BadQuaternionValues) {
  json scene = MinimalScene();
  scene["views"][0]["cam_from_world"]["rotation"] = {0, 0, 0, 0};
  EXPECT_THAT(ReadError(scene), HasSubstr("views[0].cam_from_world.rotation: "));
  scene["views"][0]["cam_from_world"]["rotation"] = {1, 0, "0", 0};
  EXPECT_THAT(ReadError(scene),
              HasSubstr("views[0].cam_from_world.rotation[2]: expected a number"));
  scene["views"][0]["cam_from_world"]["rotation"] = "identity";
  EXPECT_THAT(ReadError(scene), HasSubstr("views[0].cam_from_world.rotation: expected 4 numbers"));
}

TEST(DatasetErrors, WrongTranslationLength) {
  json scene = MinimalScene();
  scene["views"][0]["cam_from_world"]["translation"] = {0, 0, 2, 1};
  EXPECT_THAT(ReadError(scene),
              HasSubstr("views[0].cam_from_world.translation: expected 3 numbers, got 4"));
  scene["views"][0].erase("cam_from_world");
  EXPECT_THAT(ReadError(scene), HasSubstr("views[0].cam_from_world: missing"));
}

TEST(DatasetErrors, ViewNamesMissingLight) {
  json scene = MinimalScene();
  scene["views"][1]["lights"] = {"flash", "lamp"};
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("views[1].lights[1]: "), HasSubstr("lamp")));
  scene["views"][1]["lights"] = {"flash", "flash"};
  EXPECT_THAT(ReadError(scene), HasSubstr("views[1].lights[1]: "));
}

TEST(DatasetErrors, ViewNamesMissingCamera) {
  json scene = MinimalScene();
  scene["views"][0]["camera"] = "c7";
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("views[0].camera: "), HasSubstr("c7")));
}

TEST(DatasetErrors, ViewWithoutImage) {
  json scene = MinimalScene();
  scene["views"][1].erase("image");
  EXPECT_THAT(ReadError(scene), HasSubstr("views[1].image: missing"));
  scene["views"][1]["image"] = 3;
  EXPECT_THAT(ReadError(scene), HasSubstr("views[1].image: expected a string"));
}

// Paths in scene.json are relative to the dataset and never leave it (docs/dataset.md): absolute
// paths and ".." components are refused with one error naming the field, before any file is read.
TEST(DatasetErrors, PathsMustStayInsideTheDataset) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/views/0/image", "/etc/passwd"},
      {"/views/1/image", "../outside.exr"},
      {"/views/1/image", "images/../../outside.exr"},
      {"/views/0/mask", "/tmp/m.png"},
      {"/views/0/mask", "masks/../../m.png"},
      {"/lights/1/image", "../probe.exr"},
      {"/ground_truth/mesh", "/home/user/mesh.ply"},
  };
  const std::vector<std::string> fields = {"views[0].image",   "views[1].image", "views[1].image",
                                           "views[0].mask",    "views[0].mask",  "lights[1].image",
                                           "ground_truth.mesh"};
  for (size_t i = 0; i < cases.size(); ++i) {
    json scene = MinimalScene();
    scene[json::json_pointer(cases[i].first)] = cases[i].second;
    const std::string error = ReadError(scene);
    EXPECT_THAT(error, HasSubstr(fields[i])) << cases[i].second;
    EXPECT_THAT(error, HasSubstr(cases[i].second)) << error;
  }
}

TEST(DatasetErrors, NoViews) {
  json scene = MinimalScene();
  scene["views"] = json::array();
  EXPECT_THAT(ReadError(scene), HasSubstr("views: "));
  scene.erase("views");
  EXPECT_THAT(ReadError(scene), HasSubstr("views: missing"));
}

TEST(DatasetErrors, BadPointLight) {
  json scene = MinimalScene();
  scene["lights"][0]["intensity"] = {1, -2, 3};
  EXPECT_THAT(ReadError(scene), HasSubstr("lights[0].intensity: must be non-negative"));
  scene = MinimalScene();
  scene["lights"][0]["frame"] = "object";
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("lights[0].frame: "), HasSubstr("object")));
  scene = MinimalScene();
  scene["lights"][0]["position"] = {1, 2};
  EXPECT_THAT(ReadError(scene), HasSubstr("lights[0].position: expected 3 numbers, got 2"));
  scene = MinimalScene();
  scene["lights"][0]["type"] = "spot";
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("lights[0].type: "), HasSubstr("spot")));
  scene = MinimalScene();
  scene["lights"][1]["id"] = "flash";
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("lights[1].id: "), HasSubstr("duplicate")));
}

TEST(DatasetErrors, BadEnvironmentLight) {
  json scene = MinimalScene();
  scene["lights"][1]["world_from_env"] = {{1, 0, 0}, {0, 2, 0}, {0, 0, 1}};
  EXPECT_THAT(ReadError(scene), HasSubstr("lights[1].world_from_env: must be a rotation"));
  scene["lights"][1]["world_from_env"] = {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}};  // a reflection.
  EXPECT_THAT(ReadError(scene), HasSubstr("lights[1].world_from_env: must be a rotation"));
  scene["lights"][1]["world_from_env"] = {{1, 0, 0}, {0, 1, 0}};
  EXPECT_THAT(ReadError(scene), HasSubstr("lights[1].world_from_env: expected a 3x3 matrix"));
  scene["lights"][1]["world_from_env"] = {{1, 0, 0}, {0, 1, 0}, {0, 1}};
  EXPECT_THAT(ReadError(scene), HasSubstr("lights[1].world_from_env[2]: expected 3 numbers"));
  scene = MinimalScene();
  scene["lights"][1]["scale"] = -1;
  EXPECT_THAT(ReadError(scene), HasSubstr("lights[1].scale: must be non-negative"));
  scene = MinimalScene();
  scene["lights"][1].erase("image");
  EXPECT_THAT(ReadError(scene), HasSubstr("lights[1].image: missing"));
}

TEST(DatasetErrors, EnvironmentBackgroundNeedsEnvironmentLight) {
  json scene = MinimalScene();
  scene["background"] = "environment";
  scene["lights"].erase(1);
  scene["views"][1]["lights"] = {"flash"};
  EXPECT_THAT(ReadError(scene), HasSubstr("background: "));
  scene["background"] = "white";
  EXPECT_THAT(ReadError(scene), AllOf(HasSubstr("background: "), HasSubstr("white")));
}

TEST(DatasetErrors, BadGroundTruth) {
  json scene = MinimalScene();
  scene["ground_truth"] = "gt/mesh.ply";
  EXPECT_THAT(ReadError(scene), HasSubstr("ground_truth: expected an object"));
  scene["ground_truth"] = {{"mesh", 5}};
  EXPECT_THAT(ReadError(scene), HasSubstr("ground_truth.mesh: expected a string"));
  scene["ground_truth"] = {{"shading", "phong"}};
  EXPECT_THAT(ReadError(scene),
              AllOf(HasSubstr("ground_truth.shading: expected \"flat\" or \"smooth\""),
                    HasSubstr("phong")));
  scene["ground_truth"] = {{"shading", 1}};
  EXPECT_THAT(ReadError(scene), HasSubstr("ground_truth.shading: expected a string"));
}

// ground_truth.shading picks the shading of "auto"; without it a dataset is shaded smooth.
TEST(DatasetErrors, ShadingFollowsGroundTruth) {
  json scene = MinimalScene();
  Dataset dataset;
  ASSERT_TRUE(ParseSceneJson(scene.dump(), "d", &dataset).ok());
  EXPECT_EQ(DatasetShading(dataset), Shading::kSmooth);
  scene["ground_truth"] = {{"shading", "flat"}};
  ASSERT_TRUE(ParseSceneJson(scene.dump(), "d", &dataset).ok());
  EXPECT_EQ(DatasetShading(dataset), Shading::kFlat);
  Shading shading = Shading::kFlat;
  EXPECT_TRUE(ResolveShading("smooth", dataset, &shading));
  EXPECT_EQ(shading, Shading::kSmooth);
  EXPECT_TRUE(ResolveShading("auto", dataset, &shading));
  EXPECT_EQ(shading, Shading::kFlat);
  EXPECT_FALSE(ResolveShading("gouraud", dataset, &shading));
}

}  // namespace
}  // namespace sft
