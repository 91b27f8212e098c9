#include "src/io/dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "src/core/memory.h"
#include "src/io/image_io.h"
#include "src/io/scene_setup.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::AllOf;
using testing::DataDir;
using ::testing::HasSubstr;
using testing::TempDir;
using json = nlohmann::json;

constexpr int kWidth = 16;
constexpr int kHeight = 12;

// A small valid scene: one camera, a camera-attached point light, an environment light, two
// views (the first with a mask).
json MinimalScene() {
  return json::parse(R"({
    "format": "sft-dataset/1",
    "cameras": [{"id": "c0", "model": "PINHOLE", "width": 16, "height": 12,
                 "params": [20, 20, 8, 6]}],
    "lights": [
      {"id": "flash", "type": "point", "frame": "camera", "position": [0.1, 0, 0],
       "intensity": [1, 2, 3]},
      {"id": "probe", "type": "environment", "image": "probes/env.exr",
       "world_from_env": [[0, -1, 0], [1, 0, 0], [0, 0, 1]], "scale": 2.5}
    ],
    "views": [
      {"image": "images/000.exr", "mask": "masks/000.png", "camera": "c0", "lights": ["flash"],
       "cam_from_world": {"rotation": [1, 0, 0, 0], "translation": [0, 0, 2]}},
      {"image": "images/001.png", "camera": "c0", "lights": ["flash", "probe"],
       "cam_from_world": {"rotation": [0, 1, 0, 0], "translation": [0.5, 0, 2]}}
    ],
    "background": "black",
    "ground_truth": {"mesh": "gt/mesh.ply", "material": {"albedo": [0.5, 0.5, 0.5]}}
  })");
}

void WriteJson(const std::string& dir, const json& scene) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/scene.json") << scene.dump(1);
}

// Writes the scene and every image, mask and probe it names, at the camera's size.
void WriteDataset(const TempDir& dir, const json& scene) {
  WriteJson(dir.path(), scene);
  Image rgba(kWidth, kHeight, 4, 0.25f);
  ASSERT_TRUE(WriteImage(dir.Join("images/000.exr"), rgba).ok());
  ASSERT_TRUE(WritePng(dir.Join("images/001.png"), Image(kWidth, kHeight, 3, 0.5f)).ok());
  Image mask(kWidth, kHeight, 1, 0.0f);
  mask.at(3, 4) = 1.0f;
  ASSERT_TRUE(WritePng(dir.Join("masks/000.png"), mask, /*srgb=*/false).ok());
  Image probe(8, 4, 3, 1.0f);
  probe.at(1, 1, 0) = -2.0f;
  ASSERT_TRUE(WriteExr(dir.Join("probes/env.exr"), probe).ok());
}

// Reads a scene that must fail and returns the error message.
std::string ReadError(const json& scene) {
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  const Status status = ReadDataset(dir.path(), &dataset);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("scene.json")));
  return status.message();
}

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
  // Without the keys nothing changes.
  Dataset plain;
  WriteJson(copy.path(), MinimalScene());
  ASSERT_TRUE(ReadDataset(copy.path(), &plain).ok());
  EXPECT_FALSE(plain.has_source_from_world);
  EXPECT_TRUE(plain.sparse_points.empty());
  EXPECT_TRUE(CheckViewsHaveLights(plain).ok());
}

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
  scene["lighting"] = 3;
  EXPECT_THAT(ReadError(scene), HasSubstr("lighting"));
}

// A scene with unknown keys in a camera, both kinds of light, a view and a pose.
json SceneWithNestedExtras() {
  json scene = MinimalScene();
  scene["cameras"][0]["serial"] = "A123";
  scene["cameras"][0]["exposure"] = {{"iso", 100}, {"shutter", 0.01}};
  scene["lights"][0]["falloff"] = "inverse_square";
  scene["lights"][0]["image"] = "not/for/point/lights.exr";  // the other type's key: unknown.
  scene["lights"][1]["mapping"] = "equirectangular, +Z up";
  scene["views"][1]["timestamp"] = 12.5;
  scene["views"][1]["tags"] = {"turntable", nullptr, 3};
  scene["views"][0]["cam_from_world"]["covariance"] = json::array({0.1, 0.2});
  return scene;
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

// A UTF-8 byte-order mark before the JSON is skipped.
TEST(DatasetRead, ByteOrderMarkIsSkipped) {
  TempDir dir;
  std::ofstream(dir.Join("scene.json")) << "\xEF\xBB\xBF" << MinimalScene().dump(1);
  Dataset dataset;
  const Status status = ReadDataset(dir.path(), &dataset);
  EXPECT_TRUE(status.ok()) << status.message();
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

// Paths in scene.json are relative to the dataset and never leave it (DESIGN.md §2.5): absolute
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

TEST(DatasetOutputPaths, MirrorUnderImagesAndNeverCollide) {
  Dataset dataset;
  for (const char* image : {"images/000.exr", "images/cam1/000.png", "images/cam2/000.png",
                            "photos/a.jpg", "images/000.png", "images/000.exr", "b.png"}) {
    ViewSpec view;
    view.image = image;
    dataset.views.push_back(view);
  }
  EXPECT_THAT(ViewOutputPaths(dataset, ".exr"),
              ::testing::ElementsAre("images/000.exr", "images/cam1/000.exr", "images/cam2/000.exr",
                                     "images/photos/a.exr", "images/000_view004.exr",
                                     "images/000_view005.exr", "images/b.exr"));
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
}

TEST(DatasetFiles, ImageSizeDiffersFromCamera) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  ASSERT_TRUE(WritePng(dir.Join("images/001.png"), Image(20, 10, 3)).ok());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  Status status = CheckDatasetFiles(dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr(dir.Join("images/001.png")), HasSubstr("20x10"), HasSubstr("16x12")));
  Image image;
  status = LoadViewImage(dataset, 1, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr("images/001.png"), HasSubstr("20x10")));
}

TEST(DatasetFiles, MaskSizeDiffersFromCamera) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  ASSERT_TRUE(WritePng(dir.Join("masks/000.png"), Image(8, 6, 1), false).ok());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  const Status status = CheckDatasetFiles(dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr(dir.Join("masks/000.png")), HasSubstr("8x6")));
}

TEST(DatasetFiles, MissingImageFile) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  std::filesystem::remove(dir.Join("images/000.exr"));
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());  // ReadDataset does not open images.
  Status status = CheckDatasetFiles(dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr(dir.Join("images/000.exr")), HasSubstr("not found")));
  Image image;
  status = LoadViewImage(dataset, 0, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("images/000.exr")));
}

TEST(DatasetFiles, UnreadableProbe) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  std::ofstream(dir.Join("probes/env.exr"), std::ios::trunc) << "not an exr";
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  Status status = CheckDatasetFiles(dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("probes/env.exr")));
  Image probe;
  status = LoadProbe(dataset, 1, &probe);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("probes/env.exr")));

  std::filesystem::remove(dir.Join("probes/env.exr"));
  status = LoadProbe(dataset, 1, &probe);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr(dir.Join("probes/env.exr")), HasSubstr("not found")));
}

TEST(DatasetFiles, LoadProbeClampsNegativeTexelsAndReturnsRgb) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  Image probe;
  Status status = LoadProbe(dataset, 1, &probe);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(probe.width, 8);
  EXPECT_EQ(probe.height, 4);
  EXPECT_EQ(probe.channels, 3);
  EXPECT_EQ(probe.at(1, 1, 0), 0.0f);  // was -2.
  EXPECT_EQ(probe.at(1, 1, 1), 1.0f);

  // A 4-channel probe loses its alpha; a 1-channel one is replicated to grey.
  Image grey(6, 3, 1, 0.75f);
  ASSERT_TRUE(WriteExr(dir.Join("probes/env.exr"), grey).ok());
  status = LoadProbe(dataset, 1, &probe);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(probe.channels, 3);
  EXPECT_EQ(probe.at(5, 2, 2), 0.75f);
}

TEST(DatasetFiles, LoadViewImageAndMask) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  Image image;
  ASSERT_TRUE(LoadViewImage(dataset, 0, &image).ok());  // RGBA EXR -> RGB
  EXPECT_EQ(image.channels, 3);
  EXPECT_EQ(image.width, kWidth);
  EXPECT_EQ(image.at(2, 3, 2), 0.25f);
  ASSERT_TRUE(LoadViewImage(dataset, 1, &image).ok());  // sRGB PNG -> linear
  EXPECT_NEAR(image.at(0, 0, 0), 0.5f, 0.005f);         // written as linear 0.5, 8-bit quantized.

  Image mask;
  ASSERT_TRUE(LoadViewMask(dataset, 0, &mask).ok());
  EXPECT_EQ(mask.channels, 1);
  EXPECT_EQ(mask.at(3, 4), 1.0f);
  EXPECT_EQ(mask.at(4, 3), 0.0f);
  const Status status = LoadViewMask(dataset, 1, &mask);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr("scene.json"), HasSubstr("views[1].mask")));
}

std::vector<std::string> CyclesDatasets() {
  std::vector<std::string> dirs;
  for (const auto& entry : std::filesystem::directory_iterator(DataDir() + "/cycles")) {
    if (entry.is_directory()) dirs.push_back(entry.path().string());
  }
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

TEST(DatasetCycles, EveryReferenceDatasetReadsAndChecks) {
  const std::vector<std::string> dirs = CyclesDatasets();
  ASSERT_GE(dirs.size(), 4u);
  int environment_lights = 0;
  for (const std::string& dir : dirs) {
    SCOPED_TRACE(dir);
    Dataset dataset;
    Status status = ReadDataset(dir, &dataset);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(dataset.views.size(), 8u);
    EXPECT_EQ(dataset.gt_mesh, "gt/mesh.ply");
    status = CheckDatasetFiles(dataset);
    EXPECT_TRUE(status.ok()) << status.message();
    for (const ViewSpec& view : dataset.views) {
      EXPECT_NEAR(view.cam_from_world.rotation.norm(), 1.0, 1e-12);
      EXPECT_FALSE(view.lights.empty());
    }
    for (int l = 0; l < static_cast<int>(dataset.lights.size()); ++l) {
      if (dataset.lights[l].type != LightType::kEnvironment) continue;
      ++environment_lights;
      Image probe;
      status = LoadProbe(dataset, l, &probe);
      ASSERT_TRUE(status.ok()) << status.message();
      EXPECT_EQ(probe.width, 2 * probe.height);  // equirectangular
      EXPECT_GE(*std::min_element(probe.data.begin(), probe.data.end()), 0.0f);
    }
  }
  EXPECT_GE(environment_lights, 1);  // sphere_env_studio
}

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
