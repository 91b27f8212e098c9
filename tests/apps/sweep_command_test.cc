// `sft sweep` end to end on a tiny synthesized dataset: cells run and scored, an error cell
// recorded, the default configuration marked, the report written; a sweep interrupted (SIGINT)
// and then killed (SIGKILL) continues without redoing a finished cell; bad grids and folders
// are one-line errors that write nothing (grid errors in detail: tests/sweep/sweep_grid_test.cc).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "src/geometry/mesh.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using json = nlohmann::json;
using testing::CountLines;
using ::testing::HasSubstr;
using testing::RunSft;
using ::testing::StartsWith;
namespace fs = std::filesystem;

std::vector<std::string> ReadLines(const std::string& path) {
  std::istringstream in(testing::ReadTestFile(path));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Starts the sweep in the background, waits (at most 120 s) until sweep.jsonl has `lines` lines,
// sends `signal` and prints the sweep's exit status last.
std::string StopAfter(const std::string& sweep, const std::string& jsonl, int lines,
                      const std::string& signal) {
  const std::string script = sweep + " & pid=$!; for i in $(seq 2400); do [ -f " + jsonl +
                             " ] && [ $(wc -l < " + jsonl + ") -ge " + std::to_string(lines) +
                             " ] && break; sleep 0.05; done; kill -" + signal +
                             " $pid; wait $pid; echo \"exit=$?\"";
  std::string out;
  testing::RunCommand("bash -c '" + script + "'", &out);
  return out;
}

class SweepCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(testing::SynthIcosphere(tmp_.Join("ds"),
                                      "--cameras 4 --zooms 1 --res 16 --spp 16 --bounces 1"),
              "");
    std::string out;
    ASSERT_EQ(RunSft("perturb --mesh " + tmp_.Join("ds/gt/mesh.ply") + " --out " +
                         tmp_.Join("init.ply") + " --amplitude 0.02 --seed 2",
                     &out),
              0)
        << out;
  }
  // Writes `grid` as <out>.json beside the dataset, runs `sft sweep --quiet` into <out> and
  // returns the lines of its sweep.jsonl (a failed sweep is a test failure).
  std::vector<std::string> RunGrid(const std::string& grid, const std::string& out) {
    const std::string path = tmp_.Join(out + ".json");
    testing::WriteTestFile(path, grid);
    std::string log;
    EXPECT_EQ(RunSft("sweep --quiet --grid " + path + " --out " + tmp_.Join(out), &log), 0) << log;
    return ReadLines(tmp_.Join(out + "/sweep.jsonl"));
  }
  testing::TempDir tmp_;
};

// Six cells: three real ones of 0.5 s each (a time budget) and three that the configuration
// rejects ("auto" bounces). Run 1 is interrupted after the first finished cell, run 2 killed
// after the second; run 3 finishes. Every finished cell's line stays as it was, and every cell
// is recorded once.
TEST_F(SweepCommandTest, InterruptedAndKilledSweepsContinue) {
  testing::WriteTestFile(tmp_.Join("grid.json"), R"({
    "dataset": "ds", "init": "init.ply", "reference": "ds/gt/mesh.ply",
    "time_budget": 0.5, "config": {"steps": 2, "phases": "geometry"},
    "eval": {"spp": 4, "bounces": 1, "mesh_samples": 2000},
    "axes": {"spp": [4, 8, 16], "bounces": [2, "auto"]}})");
  const std::string jsonl = tmp_.Join("out/sweep.jsonl");
  const std::string sweep = testing::SftBinary() + " sweep --quiet --grid " +
                            tmp_.Join("grid.json") + " --out " + tmp_.Join("out");
  std::string out = StopAfter(sweep, jsonl, 1, "INT");
  EXPECT_THAT(out, HasSubstr("exit=130")) << out;
  EXPECT_THAT(out, HasSubstr("run the same command again"));
  const std::vector<std::string> first = ReadLines(jsonl);
  ASSERT_GE(first.size(), 1u);
  ASSERT_LT(first.size(), 6u);

  out = StopAfter(sweep, jsonl, static_cast<int>(first.size()) + 1, "KILL");
  EXPECT_THAT(out, HasSubstr("exit=137")) << out;
  const std::vector<std::string> second = ReadLines(jsonl);
  ASSERT_GT(second.size(), first.size());
  ASSERT_LT(second.size(), 6u);
  EXPECT_TRUE(std::equal(first.begin(), first.end(), second.begin()));

  ASSERT_EQ(testing::RunCommand(sweep, &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("6 cells (" + std::to_string(6 - second.size()) + " run now, " +
                             std::to_string(second.size()) + " before; 3 errors)"));
  const std::vector<std::string> third = ReadLines(jsonl);
  ASSERT_EQ(third.size(), 6u);
  EXPECT_TRUE(std::equal(second.begin(), second.end(), third.begin()));
  std::map<std::string, json> cells;
  for (const std::string& text : third) {
    const json line = json::parse(text);
    EXPECT_TRUE(cells.emplace(line["id"].get<std::string>(), line).second) << text;
  }
  ASSERT_EQ(cells.size(), 6u);
  // Cells 0-2: bounces 2 and spp 4, 8, 16, each ended by the budget and scored.
  const json& ok = cells.at("00_bounces2_spp4");
  EXPECT_EQ(ok["status"], "ok");
  EXPECT_EQ(ok["ended_by"], "time_budget");
  EXPECT_GE(ok["seconds"].get<double>(), 0.5);
  EXPECT_GT(ok["f1"].get<double>(), 0.0);
  EXPECT_GT(ok["full"]["psnr_srgb"].get<double>(), 10.0);
  EXPECT_TRUE(ok["albedo"]["ssim_srgb"].is_number());
  EXPECT_EQ(ok["views"], 4);
  EXPECT_FALSE(ok["default"].get<bool>());
  // With a reference, every outer iteration is scored, and so is the one the budget stopped:
  // the trajectory and metrics.json agree.
  const json& trajectory = ok["trajectory"];
  ASSERT_EQ(trajectory.size(), ok["outer_iterations"].get<size_t>() + 1);
  const json metrics =
      json::parse(testing::ReadTestFile(tmp_.Join("out/cells/00_bounces2_spp4/metrics.json")));
  for (size_t k = 0; k < trajectory.size(); ++k) {
    EXPECT_GT(trajectory[k]["chamfer"].get<double>(), 0.0);
    EXPECT_GT(trajectory[k]["f1"].get<double>(), 0.0);
    EXPECT_EQ(trajectory[k]["chamfer"], metrics["outer"][k]["chamfer"]);
    if (k > 0) {
      EXPECT_GE(trajectory[k]["seconds"], trajectory[k - 1]["seconds"]);
    }
  }
  // spp 16 and bounces 2 are the configuration's own values: the default cell.
  EXPECT_TRUE(cells.at("02_bounces2_spp16")["default"].get<bool>());
  const json& error = cells.at("04_bouncesauto_spp8");
  EXPECT_EQ(error["status"], "error");
  EXPECT_THAT(error["error"].get<std::string>(), HasSubstr("bounces: expected an integer"));
  EXPECT_TRUE(fs::exists(tmp_.Join("out/cells/02_bounces2_spp16/eval.json")));
  EXPECT_TRUE(fs::exists(tmp_.Join("out/cells/02_bounces2_spp16/mesh.ply")));
  const std::string report = testing::ReadTestFile(tmp_.Join("out/report.html"));
  EXPECT_THAT(report, HasSubstr("Pareto front"));
  EXPECT_THAT(report, HasSubstr("default: 02_bounces2_spp16"));

  // A finished sweep run again does nothing; another grid in the same folder is refused.
  ASSERT_EQ(testing::RunCommand(sweep, &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("0 run now, 6 before"));
  EXPECT_EQ(ReadLines(jsonl), third);
  EXPECT_NE(testing::RunCommand(sweep + " --time-budget 2", &out), 0);
  EXPECT_THAT(out, HasSubstr("holds a sweep of another grid"));
  EXPECT_THAT(out, HasSubstr("\"time_budget\""));
}

// With a budget, a list's earlier stages keep their outer iterations and the last stage runs
// until the budget ends it.
TEST_F(SweepCommandTest, BudgetExtendsOnlyTheLastStage) {
  const std::vector<std::string> lines = RunGrid(R"({
    "dataset": "ds", "init": "init.ply", "reference": "ds/gt/mesh.ply", "time_budget": 2,
    "config": {"spp": 2, "steps": 1, "stages": [
      {"name": "first", "phases": "texture", "outer_iterations": 1},
      {"name": "last", "phases": "texture", "outer_iterations": 1}]},
    "eval": {"spp": 2, "bounces": 1, "mesh_samples": 2000}})",
                                                 "o");
  ASSERT_EQ(lines.size(), 1u);
  const json cell = json::parse(lines[0]);
  ASSERT_EQ(cell["status"], "ok") << lines[0];
  EXPECT_EQ(cell["ended_by"], "time_budget");
  const json state = json::parse(testing::ReadTestFile(tmp_.Join("o/cells/00/state.json")));
  EXPECT_EQ(state["stages"][0]["outer_iterations"], 1);
  EXPECT_EQ(state["stages"][1]["outer_iterations"], 10000);
  const json& trajectory = cell["trajectory"];
  ASSERT_GE(trajectory.size(), 3u);
  EXPECT_EQ(trajectory[0]["stage"], "first");
  for (size_t k = 1; k < trajectory.size(); ++k) EXPECT_EQ(trajectory[k]["stage"], "last");
}

// Views counts become evenly spaced view indices; more views than the dataset has is the cell's
// error. Outer iterations instead of a budget end the cells.
TEST_F(SweepCommandTest, ViewsAxisAndOuterIterations) {
  const std::vector<std::string> lines = RunGrid(R"({
    "dataset": "ds", "init": "init.ply", "outer_iterations": 1,
    "config": {"steps": 1, "spp": 2, "phases": "texture"},
    "eval": {"spp": 2, "bounces": 1},
    "axes": {"views": [2, 9]}})",
                                                 "o");
  ASSERT_EQ(lines.size(), 2u);
  const json two = json::parse(lines[0]), nine = json::parse(lines[1]);
  EXPECT_EQ(two["status"], "ok");
  EXPECT_EQ(two["ended_by"], "iterations");
  EXPECT_EQ(two["outer_iterations"], 1);
  EXPECT_EQ(two["views"], 2);
  EXPECT_TRUE(two["f1"].is_null());  // no reference mesh: no per-outer scores either.
  ASSERT_EQ(two["trajectory"].size(), 1u);
  EXPECT_FALSE(two["trajectory"][0].contains("chamfer"));
  // Views 0 and 2 of 4 were fitted and scored.
  EXPECT_EQ(two["id"], "00_views2");
  const json state = json::parse(testing::ReadTestFile(tmp_.Join("o/cells/00_views2/state.json")));
  EXPECT_EQ(state["stages"][0]["views"], json::parse("[0, 2]"));
  const json eval = json::parse(testing::ReadTestFile(tmp_.Join("o/cells/00_views2/eval.json")));
  EXPECT_EQ(eval["views"], json::parse("[0, 2]"));
  EXPECT_EQ(nine["status"], "error");
  EXPECT_THAT(nine["error"].get<std::string>(), HasSubstr("9 views asked, the dataset has 4"));
}

// Phases values with a start of their own (what the ablations preset uses): the geometry cell
// holds the dataset's true material, the texture cell fits on the reference mesh. A cell that
// asks for a reference the grid lacks is the cell's error.
TEST_F(SweepCommandTest, PhaseValuesStartWhereTheyAsk) {
  const std::string phases = R"("axes": {"phases": [
      {"name": "geometry", "material": "ground_truth"},
      {"name": "texture", "init": "reference", "material": "grey"}]}})";
  const std::string base = R"({"dataset": "ds", "init": "init.ply", "outer_iterations": 1,
    "config": {"steps": 1, "spp": 2}, "eval": {"spp": 2, "bounces": 1, "mesh_samples": 1000},
    )";
  const std::vector<std::string> lines =
      RunGrid(base + R"("reference": "ds/gt/mesh.ply", )" + phases, "o");
  ASSERT_EQ(lines.size(), 2u);
  for (const std::string& line : lines) EXPECT_EQ(json::parse(line)["status"], "ok") << line;
  // The geometry cell kept the true material (a geometry phase does not change it).
  const json gt = json::parse(testing::ReadTestFile(tmp_.Join("ds/gt/material.json")));
  const json held =
      json::parse(testing::ReadTestFile(tmp_.Join("o/cells/00_geometry/material.json")));
  EXPECT_EQ(testing::ReadTestFile(
                tmp_.Join("o/cells/00_geometry/" + held["mesh_colors"].get<std::string>())),
            testing::ReadTestFile(tmp_.Join("ds/gt/" + gt["mesh_colors"].get<std::string>())));
  // The texture cell started from the reference mesh (a texture phase does not move it).
  TriMesh reference, fitted, perturbed;
  ASSERT_TRUE(ReadMesh(tmp_.Join("ds/gt/mesh.ply"), &reference).ok());
  ASSERT_TRUE(ReadMesh(tmp_.Join("o/cells/01_texture/mesh.ply"), &fitted).ok());
  ASSERT_TRUE(ReadMesh(tmp_.Join("init.ply"), &perturbed).ok());
  auto max_distance = [&fitted](const TriMesh& other) {
    EXPECT_EQ(other.n_vertices(), fitted.n_vertices());
    double d = 0.0;
    for (const auto& v : fitted.vertices()) {
      d = std::max(d, (fitted.point(v) - other.point(v)).norm());
    }
    return d;
  };
  EXPECT_LT(max_distance(reference), 1e-6);
  EXPECT_GT(max_distance(perturbed), 1e-3);
  const json metrics =
      json::parse(testing::ReadTestFile(tmp_.Join("o/cells/01_texture/metrics.json")));
  EXPECT_EQ(metrics["init"], tmp_.Join("ds/gt/mesh.ply"));
  EXPECT_EQ(metrics["material"], "");
  // Without a reference the texture cell is an error line; the geometry cell still runs.
  const std::vector<std::string> noref = RunGrid(base + phases, "n");
  ASSERT_EQ(noref.size(), 2u);
  EXPECT_EQ(json::parse(noref[0])["status"], "ok");
  EXPECT_THAT(json::parse(noref[1])["error"].get<std::string>(),
              HasSubstr("init \"reference\": the grid gives no reference mesh"));
}

TEST_F(SweepCommandTest, BadInputsAreOneLineAndWriteNothing) {
  testing::WriteTestFile(tmp_.Join("bad.json"), R"({"dataset": "ds", "axes": {"spp": []}})");
  testing::WriteTestFile(tmp_.Join("good.json"), R"({"dataset": "ds", "init": "init.ply"})");
  fs::create_directories(tmp_.Join("full"));
  testing::WriteTestFile(tmp_.Join("full/x.txt"), "something else");
  const struct {
    std::string args;
    std::string expected;
  } cases[] = {
      {"sweep --grid " + tmp_.Join("bad.json") + " --out " + tmp_.Join("o"), "axes.spp"},
      {"sweep --out " + tmp_.Join("o"), "--grid"},
      {"sweep --preset ablations --out " + tmp_.Join("o"), "dataset: missing"},
      {"sweep --grid " + tmp_.Join("good.json"), "--out"},
      {"sweep --grid " + tmp_.Join("good.json") + " --time-budget -1 --out " + tmp_.Join("o"),
       "--time-budget"},
      {"sweep --grid " + tmp_.Join("good.json") + " --reference " + tmp_.Join("nope.ply") +
           " --out " + tmp_.Join("o"),
       "nope.ply"},
      {"sweep --grid " + tmp_.Join("good.json") + " --out " + tmp_.Join("ds/sub"), "--out"},
      {"sweep --grid " + tmp_.Join("good.json") + " --out " + tmp_.Join("full"), "holds no sweep"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    std::string out;
    EXPECT_EQ(RunSft(c.args, &out), 1);
    EXPECT_EQ(CountLines(out), 1) << out;
    EXPECT_THAT(out, StartsWith("sft sweep: error: "));
    EXPECT_THAT(out, HasSubstr(c.expected));
  }
  EXPECT_FALSE(fs::exists(tmp_.Join("o")));
  EXPECT_FALSE(fs::exists(tmp_.Join("ds/sub")));
  // --print-cells lists the preset's 24 cells and writes nothing.
  std::string out;
  ASSERT_EQ(
      RunSft("sweep --preset ablations --dataset " + tmp_.Join("ds") + " --print-cells", &out), 0)
      << out;
  EXPECT_EQ(CountLines(out), 24);
  EXPECT_THAT(out, HasSubstr("00_local_geometry_views8 "));
}

}  // namespace
}  // namespace sft
