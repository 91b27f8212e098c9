// sft reconstruct from a given mesh with the built-in "large_steps" list, end to end and CI-sized:
// every stage runs, the Adam material stages restart the lobe, and the geometry stages render the
// specular lobe (pinned on) while keeping it out of their step (docs/reconstruct.md, "Built-in
// schedules"). The list's accuracy is measured on the glossy dragon, not here
// (docs/design-notes.md, "The warp's material stages on Adam").
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;
using testing::RunSft;

nlohmann::json ReadJson(const std::string& path) {
  return nlohmann::json::parse(testing::ReadTestFile(path));
}

TEST(ReconstructLargeStepsTest, EveryStageRunsWithTheLobeInTheGeometryResidual) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(
                tmp.Join("ds"),
                "--cameras 4 --zooms 1 --res 24 --spp 16 --bounces 1 --material "
                "'{\"albedo\": [0.6, 0.5, 0.4], \"roughness\": 0.3, \"specular\": 0.4}'"),
            "");
  testing::WriteTestFile(tmp.Join("c.json"), R"({"schedule": "large_steps"})");
  std::string out;
  // "schedule": "large_steps" keeps the list although --outer and --steps describe one stage's
  // loop (with "auto" they would pick the one-stage refine list); the flags shrink every stage.
  ASSERT_EQ(
      RunSft("reconstruct --dataset " + tmp.Join("ds") + " --init " + tmp.Join("ds/gt/mesh.ply") +
                 " --out " + tmp.Join("r") + " --config " + tmp.Join("c.json") +
                 " --outer 1 --steps 2 "
                 "--bounces 1 --no-report",
             &out),
      0)
      << out;
  EXPECT_THAT(out, HasSubstr("stage 1/10 material:"));
  EXPECT_THAT(out, HasSubstr("stage 2/10 material_adam:"));
  EXPECT_THAT(out, HasSubstr("stage 10/10 material_final:"));
  EXPECT_EQ(testing::CountOccurrences(out, "restart: roughness 0.5, specular 0.2"), 2) << out;

  const nlohmann::json state = ReadJson(tmp.Join("r/state.json"));
  EXPECT_TRUE(state["finished"].get<bool>());
  ASSERT_EQ(state["stages"].size(), 10u);
  int geometry_stages = 0;
  for (const auto& stage : state["stages"]) {
    SCOPED_TRACE(stage["name"].get<std::string>());
    if (stage["phases"] != "geometry") {
      EXPECT_EQ(stage["spp"].get<int>(), 16);
      continue;
    }
    ++geometry_stages;
    EXPECT_EQ(stage["spp"].get<int>(), 64);
    EXPECT_FALSE(stage["gradient_specular"].get<bool>());
    EXPECT_TRUE(stage["pin"]["specular"].get<bool>());
  }
  EXPECT_EQ(geometry_stages, 4);

  // The planner's record: the geometry stages rendered the lobe because it is pinned on.
  const nlohmann::json metrics = ReadJson(tmp.Join("r/metrics.json"));
  int geometry_outers = 0;
  for (const auto& outer : metrics["outer"]) {
    if (outer["stage"].get<std::string>().rfind("shape_", 0) != 0) continue;
    ++geometry_outers;
    bool specular_pinned_on = false;
    for (const auto& decision : outer["effects"]["decisions"]) {
      specular_pinned_on |= decision["name"] == "specular" && decision["on"].get<bool>() &&
                            decision["reason"] == "pinned";
    }
    EXPECT_TRUE(specular_pinned_on) << outer["stage"];
  }
  EXPECT_EQ(geometry_outers, 4);
  // The material stages fitted the lobe: its weight is neither the start's 0 nor the restart's.
  const double specular = ReadJson(tmp.Join("r/material.json"))["specular"].get<double>();
  EXPECT_GT(specular, 0.0);
  EXPECT_NE(specular, 0.2);
}

}  // namespace
}  // namespace sft
