// sft reconstruct from a carved hull, end to end and CI-sized: no --init, so the run carves a hull
// from the masks and follows the built-in "hull" schedule (coarse to fine, remeshing, resampling,
// a final texture stage) on a small synthetic sphere.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "src/geometry/mesh.h"
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
  EXPECT_THAT(out, HasSubstr("start: the hull carved from 8 views' masks, "));
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

// The config's "carve" key reaches the carved start (`sft init`'s options), is recorded with the
// run, and a bad value is one error line naming the key. The dataset's support_plane (through the
// sphere's centre) cuts the carved start: its lowest vertex lies on the plane.
TEST(ReconstructHullTest, CarveKeysAndTheSupportPlaneShapeTheCarvedStart) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 6 --zooms 1 --res 24 --spp 4"), "");
  nlohmann::json scene = ReadJson(tmp.Join("ds/scene.json"));
  scene["support_plane"] = {{"normal", {0, 0, 1}}, {"point", {0, 0, 0}}};
  testing::WriteTestFile(tmp.Join("ds/scene.json"), scene.dump(1));
  testing::WriteTestFile(tmp.Join("cfg.json"), R"({"carve": {"resolution": 32, "faces": 300},
      "stages": [{"name": "m", "phases": "texture", "outer_iterations": 1, "steps": 1, "spp": 1,
      "bounces": 1}]})");
  std::string out;
  ASSERT_EQ(RunSft("reconstruct --quiet --no-report --dataset " + tmp.Join("ds") + " --out " +
                       tmp.Join("r") + " --config " + tmp.Join("cfg.json"),
                   &out),
            0)
      << out;
  const nlohmann::json state = ReadJson(tmp.Join("r/state.json"));
  EXPECT_EQ(state["run"]["start"], "carved hull");
  EXPECT_EQ(state["run"]["carve"]["faces"], 300);
  TriMesh start;
  ASSERT_TRUE(ReadMesh(tmp.Join("r/initial_mesh.ply"), &start).ok());
  EXPECT_GT(start.n_faces(), 100u);
  EXPECT_LE(start.n_faces(), 300u);
  // Cut by the plane: no vertex below it by more than a voxel (the carving box's side, about
  // 0.7, over 32), and the sphere's top (radius 0.2887) kept.
  double lo = 1, hi = -1;
  for (auto vh : start.vertices()) {
    lo = std::min<double>(lo, start.point(vh)[2]);
    hi = std::max<double>(hi, start.point(vh)[2]);
  }
  EXPECT_GT(lo, -0.7 / 32);
  EXPECT_GT(hi, 0.25);
  // A bad carve value is one line that writes nothing.
  const std::vector<std::pair<std::string, std::string>> bad_configs = {
      {R"({"carve": {"faces": 5}})", "carve.faces: must be in [100, 50000000], got 5"},
      {R"({"carve": {"stereo": true, "stereo_consistency_pixels": 20}})",
       "carve.stereo.consistency_pixels: must be in (0, 16], got 20"},
      {R"({"carve": {"stereo": true, "stereo_pairs": 1}})",
       "carve.stereo.pairs_per_view: must be in [2, 8], got 1"},
      {R"({"carve": {"stereo": 1}})", "carve.stereo: expected true or false"},
  };
  for (const auto& [config, message] : bad_configs) {
    SCOPED_TRACE(config);
    testing::WriteTestFile(tmp.Join("bad.json"), config);
    EXPECT_NE(RunSft("reconstruct --quiet --dataset " + tmp.Join("ds") + " --out " + tmp.Join("b") +
                         " --config " + tmp.Join("bad.json"),
                     &out),
              0);
    EXPECT_THAT(out, HasSubstr(message)) << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
    EXPECT_FALSE(fs::exists(tmp.Join("b")));
  }
  // A resumed run has its start: the key is refused.
  testing::WriteTestFile(tmp.Join("again.json"), R"({"carve": {"outlier_views": 1}})");
  EXPECT_NE(RunSft("reconstruct --quiet --resume " + tmp.Join("r") + " --config " +
                       tmp.Join("again.json"),
                   &out),
            0);
  EXPECT_THAT(out, HasSubstr("carve: a resumed run has its start already")) << out;
}

}  // namespace
}  // namespace sft
