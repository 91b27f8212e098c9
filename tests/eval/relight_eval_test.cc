// The lighting conditions of `sft eval --relight` (src/eval/relight_eval.h): "capture" first, one
// condition per light of a lights file (probe paths resolved against the file's folder), and
// "side": each view's flash turned by 90° about the centre at the same distance.
#include "src/eval/relight_eval.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// Two views on the x and y axes looking at the origin, lit by a camera-frame flash 0.1 to the
// camera's right (horizontal); a third view straight above, lit by the flash and by a world light
// on the z axis.
Dataset ThreeViews() {
  const char* kScene = R"({"format": "sft-dataset/1",
    "cameras": [{"id": "c", "model": "PINHOLE", "width": 8, "height": 8, "params": [8, 8, 4, 4]}],
    "lights": [{"id": "flash", "type": "point", "frame": "camera", "position": [0.1, 0, 0],
                "intensity": 2},
               {"id": "top", "type": "point", "position": [0, 0, 3], "intensity": 1}],
    "views": [
      {"image": "a.exr", "camera": "c", "lights": ["flash"],
       "cam_from_world": {"rotation": [0.5, 0.5, 0.5, -0.5], "translation": [0, 0, 2]}},
      {"image": "b.exr", "camera": "c", "lights": ["flash"],
       "cam_from_world": {"rotation": [0, 0, 0.70710678, -0.70710678], "translation": [0, 0, 2]}},
      {"image": "c.exr", "camera": "c", "lights": ["flash", "top"],
       "cam_from_world": {"rotation": [0, 1, 0, 0], "translation": [0, 0, 2]}}]})";
  Dataset dataset;
  const Status status = ParseSceneJson(kScene, "ds", &dataset);
  EXPECT_TRUE(status.ok()) << status.message();
  return dataset;
}

TEST(RelightEval, SideTurnsEachViewsFlashByNinetyDegrees) {
  const Dataset dataset = ThreeViews();
  const Eigen::Vector3d centre(0.0, 0.0, 0.0);
  std::vector<RelightCondition> conditions;
  ASSERT_TRUE(MakeRelightConditions({"side"}, dataset, centre, &conditions).ok());
  ASSERT_EQ(conditions.size(), 2u);
  EXPECT_EQ(conditions[0].name, "capture");
  const RelightCondition& side = conditions[1];
  EXPECT_EQ(side.name, "side");
  ASSERT_EQ(side.view_lights.size(), 3u);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  for (int v = 0; v < 3; ++v) {
    SCOPED_TRACE(v);
    const ViewSpec& view = dataset.views[v];
    ASSERT_EQ(side.view_lights[v].size(), view.lights.size());
    for (size_t k = 0; k < view.lights.size(); ++k) {
      const LightSpec& original = dataset.lights[view.lights[k]];
      const LightSpec& turned = side.lights[side.view_lights[v][k]];
      EXPECT_EQ(turned.frame, LightFrame::kWorld);
      EXPECT_EQ(turned.intensity, original.intensity);
      const Eigen::Vector3d p = original.frame == LightFrame::kCamera
                                    ? view.cam_from_world.Inverse() * original.position
                                    : original.position;
      const Eigen::Vector3d a = p - centre, b = turned.position - centre;
      EXPECT_NEAR(b.norm(), a.norm(), 1e-9);
      EXPECT_NEAR(a.dot(b), 0.0, 1e-9);  // 90° apart.
      if (a.cross(z).norm() > 1e-6) {
        EXPECT_NEAR(b.dot(a.cross(z)), 0.0, 1e-9);  // in the plane of a and +z...
        EXPECT_GT(b.z(), 0.0);                      // ...turned up.
      } else {
        EXPECT_NEAR(b.x(), b.norm(), 1e-9);  // on the z axis: towards +x.
      }
    }
  }
  // The horizontal flashes of views 0 and 1 end straight above the centre.
  EXPECT_NEAR(side.lights[side.view_lights[0][0]].position.z(), 2.0, 0.01);
  EXPECT_NEAR(side.lights[side.view_lights[1][0]].position.z(), 2.0, 0.01);
}

TEST(RelightEval, LightsFileGivesOneConditionPerLight) {
  testing::TempDir tmp;
  std::filesystem::create_directories(tmp.Join("l"));
  testing::WriteTestFile(tmp.Join("l/lights.json"), R"({"lights": [
      {"id": "key", "type": "point", "position": [1, 2, 3], "intensity": [1, 2, 3]},
      {"id": "env", "type": "environment", "image": "../probes/p.exr", "scale": 2}]})");
  std::vector<RelightCondition> conditions;
  const Status status =
      MakeRelightConditions({tmp.Join("l/lights.json")}, ThreeViews(), {0, 0, 0}, &conditions);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(conditions.size(), 3u);
  EXPECT_EQ(conditions[1].name, "key");
  EXPECT_TRUE(conditions[1].view_lights.empty());  // every view.
  ASSERT_EQ(conditions[1].lights.size(), 1u);
  EXPECT_EQ(conditions[1].lights[0].position, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(conditions[2].name, "env");
  EXPECT_EQ(conditions[2].lights[0].type, LightType::kEnvironment);
  EXPECT_EQ(conditions[2].lights[0].scale, 2.0);
  EXPECT_EQ(std::filesystem::path(conditions[2].lights[0].image).lexically_normal(),
            std::filesystem::absolute(tmp.Join("probes/p.exr")).lexically_normal());
}

}  // namespace
}  // namespace sft
