// sft reconstruct from a carved hull, end to end and CI-sized: no --init, so the run carves a hull
// from the masks and follows the built-in "hull" schedule (coarse to fine, remeshing, resampling,
// a final texture stage) on a small synthetic sphere.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;
using testing::RunSft;
namespace fs = std::filesystem;

nlohmann::json ReadJson(const std::string& path) {
  return nlohmann::json::parse(testing::ReadTestFile(path));
}

TEST(ReconstructHullTest, CarveRefineRemeshResampleTexture) {
  testing::TempDir tmp;
  ASSERT_EQ(
      testing::SynthIcosphere(tmp.Join("ds"),
                              "--cameras 8 --zooms 1 --res 48 --spp 32 --bounces 1 "
                              "--material '{\"albedo\": [0.7, 0.5, 0.3], \"roughness\": 0.5}'"),
      "");
  std::string out;
  ASSERT_EQ(RunSft("reconstruct --dataset " + tmp.Join("ds") + " --out " + tmp.Join("r") +
                       " --reference " + tmp.Join("ds/gt/mesh.ply") +
                       " --reference-tolerance 0.01 --outer 1 --steps 2 --spp 4 --bounces 1",
                   &out),
            0)
      << out;
  // One line per stage start and per topology change, the stage names on the progress line.
  EXPECT_THAT(out, HasSubstr("stage 1/9 material_quarter"));
  EXPECT_THAT(out, HasSubstr("remesh adaptive"));
  EXPECT_THAT(out, HasSubstr("resample"));
  EXPECT_THAT(out, HasSubstr("stage 9/9 material_final"));

  const nlohmann::json state = ReadJson(tmp.Join("r/state.json"));
  EXPECT_EQ(state["run"]["start"], "carved hull");
  EXPECT_TRUE(state["finished"].get<bool>());
  const nlohmann::json metrics = ReadJson(tmp.Join("r/metrics.json"));
  ASSERT_EQ(metrics["stages"].size(), 9u);
  for (const auto& stage : metrics["stages"]) {
    EXPECT_TRUE(fs::exists(tmp.Join("r/" + stage["normals"].get<std::string>())));
  }
  // Two remeshings (before half and full) and one resampling (before full).
  int remeshes = 0, resamples = 0;
  for (const auto& change : metrics["topology_changes"]) {
    remeshes += change["kind"] == "remesh";
    resamples += change["kind"] == "resample";
    EXPECT_GT(change["faces_after"].get<int>(), 100);
  }
  EXPECT_EQ(remeshes, 2);
  EXPECT_GE(resamples, 1);
  // The final mesh: no folds or self-intersections, close to the sphere (a carved hull of 8
  // views is already within ~1% of the diagonal; the fit must not lose that).
  const nlohmann::json& last = metrics["outer"].back();
  EXPECT_EQ(last["flipped_faces"], 0);
  EXPECT_EQ(last["self_intersecting_faces"], 0);
  EXPECT_GT(last["f1"].get<double>(), 0.8);
  const nlohmann::json material = ReadJson(tmp.Join("r/material.json"));
  EXPECT_TRUE(fs::exists(tmp.Join("r/report.html")));
  EXPECT_FALSE(material.is_null());
}

}  // namespace
}  // namespace sft
