// scene.json fixtures shared by the dataset tests (tests/io/dataset_*_test.cc).
#ifndef SFT_TESTS_TESTING_DATASET_SCENES_H_
#define SFT_TESTS_TESTING_DATASET_SCENES_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace testing {

// The camera size of MinimalScene.
constexpr int kMinimalSceneWidth = 16;
constexpr int kMinimalSceneHeight = 12;

// A small valid scene: one camera, a camera-attached point light, an environment light, two
// views (the first with a mask).
nlohmann::json MinimalScene();
// MinimalScene with unknown keys in a camera, both kinds of light, a view and a pose.
nlohmann::json SceneWithNestedExtras();
// Writes DIR/scene.json (creating DIR).
void WriteJson(const std::string& dir, const nlohmann::json& scene);
// Writes the scene and every image, mask and probe MinimalScene names, at the camera's size.
void WriteDataset(const TempDir& dir, const nlohmann::json& scene);
// Reads a scene that must fail (expecting the message to name scene.json) and returns the error
// message.
std::string ReadError(const nlohmann::json& scene);
// The reference datasets under data/cycles, sorted.
std::vector<std::string> CyclesDatasets();

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_DATASET_SCENES_H_
