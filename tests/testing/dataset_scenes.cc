#include "tests/testing/dataset_scenes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "src/image/image_io.h"
#include "src/io/dataset.h"

namespace sft {
namespace testing {

using ::testing::HasSubstr;
using json = nlohmann::json;

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

void WriteDataset(const TempDir& dir, const json& scene) {
  WriteJson(dir.path(), scene);
  Image rgba(kMinimalSceneWidth, kMinimalSceneHeight, 4, 0.25f);
  ASSERT_TRUE(WriteImage(dir.Join("images/000.exr"), rgba).ok());
  ASSERT_TRUE(
      WritePng(dir.Join("images/001.png"), Image(kMinimalSceneWidth, kMinimalSceneHeight, 3, 0.5f))
          .ok());
  Image mask(kMinimalSceneWidth, kMinimalSceneHeight, 1, 0.0f);
  mask.at(3, 4) = 1.0f;
  ASSERT_TRUE(WritePng(dir.Join("masks/000.png"), mask, /*srgb=*/false).ok());
  Image probe(8, 4, 3, 1.0f);
  probe.at(1, 1, 0) = -2.0f;
  ASSERT_TRUE(WriteExr(dir.Join("probes/env.exr"), probe).ok());
}

std::string ReadError(const json& scene) {
  TempDir dir;
  WriteJson(dir.path(), scene);
  Dataset dataset;
  const Status status = ReadDataset(dir.path(), &dataset);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("scene.json")));
  return status.message();
}

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

std::vector<std::string> CyclesDatasets() {
  std::vector<std::string> dirs;
  for (const auto& entry : std::filesystem::directory_iterator(DataDir() + "/cycles")) {
    if (entry.is_directory()) dirs.push_back(entry.path().string());
  }
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

}  // namespace testing
}  // namespace sft
