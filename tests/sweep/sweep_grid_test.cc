// The grid of `sft sweep` (src/sweep/sweep_grid.h): parsing, one-line errors naming the field,
// cell enumeration, evenly spaced views, the ablations preset and command-line overrides.
#include "src/sweep/sweep_grid.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <set>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using json = nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

TEST(SweepGridTest, ParsesPathsConfigEvalAndAxesInOrder) {
  testing::TempDir tmp;
  std::filesystem::create_directories(tmp.Join("g"));
  testing::WriteTestFile(tmp.Join("g/cfg.json"), R"({"steps": 3, "bounces": 1})");
  testing::WriteTestFile(tmp.Join("g/grid.json"), R"({
    "dataset": "../ds", "init": "start.ply", "reference": "/abs/gt.ply",
    "material": "{\"albedo\": [0.5, 0.5, 0.5]}", "config": "cfg.json",
    "time_budget": 12.5, "eval": {"spp": 8, "bounces": 1, "mesh_samples": 1000},
    "axes": {"spp": [4, 16], "solver": ["lm", "adam"], "image_scale": [0.5, 1]}})");
  SweepGrid grid;
  const Status status = ReadSweepGrid(tmp.Join("g/grid.json"), &grid);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(grid.dataset, tmp.Join("ds"));  // relative to the grid's folder, normalised.
  EXPECT_EQ(grid.init, tmp.Join("g/start.ply"));
  EXPECT_EQ(grid.reference, "/abs/gt.ply");
  EXPECT_EQ(grid.material, "{\"albedo\": [0.5, 0.5, 0.5]}");             // inline JSON kept.
  EXPECT_EQ(grid.config, json::parse(R"({"steps": 3, "bounces": 1})"));  // the file, inlined.
  EXPECT_EQ(grid.time_budget, 12.5);
  EXPECT_EQ(grid.outer_iterations, 0);
  EXPECT_EQ(grid.eval.spp, 8);
  EXPECT_EQ(grid.eval.bounces, 1);
  EXPECT_EQ(grid.eval.mesh_samples, 1000);
  EXPECT_EQ(grid.eval.f1_tolerance, 0.005);
  // Axes in the fixed enumeration order, whatever the file's order.
  ASSERT_EQ(grid.axes.size(), 3u);
  EXPECT_EQ(grid.axes[0].name, "solver");
  EXPECT_EQ(grid.axes[1].name, "image_scale");
  EXPECT_EQ(grid.axes[2].name, "spp");
  EXPECT_EQ(grid.axes[1].values[0].label, "0.5");
  EXPECT_EQ(grid.axes[1].values[0].config, json::parse(R"({"image_scale": 0.5})"));
  // The JSON form (grid.json of the sweep's folder) parses back to itself.
  SweepGrid again;
  ASSERT_TRUE(ParseSweepGrid(SweepGridJson(grid), "grid.json", "/", &again).ok());
  EXPECT_EQ(SweepGridJson(again), SweepGridJson(grid));
}

TEST(SweepGridTest, BadGridsAreOneLineNamingTheField) {
  testing::TempDir tmp;
  const struct {
    const char* grid;
    const char* field;
  } cases[] = {
      {R"([1, 2])", "expected a JSON object"},
      {R"({"dataset": "ds", )", "not valid JSON"},
      {R"({"foo": 1})", "foo: unknown key"},
      {R"({"dataset": 3})", "dataset: expected a non-empty string"},
      {R"({"axes": {"sppp": [1]}})", "axes.sppp: unknown axis"},
      {R"({"axes": {"spp": []}})", "axes.spp: expected a non-empty array"},
      {R"({"axes": {"spp": 16}})", "axes.spp: expected a non-empty array"},
      {R"({"axes": {"spp": [16, 4, 16]}})", "axes.spp[2]: \"16\" repeats"},
      {R"({"axes": {"effects": ["a,b", "a b"]}})", "axes.effects[1]"},
      {R"({"axes": {"solver": [["lm"]]}})", "axes.solver[0]: expected a number or a non-empty"},
      {R"({"axes": {"bounces": [null]}})", "axes.bounces[0]"},
      {R"({"axes": {"views": [0]}})", "axes.views[0]: expected a number of views"},
      {R"({"axes": {"views": [2.5]}})", "axes.views[0]"},
      {R"({"axes": {"variant": [{"name": "a"}]}})", "axes.variant[0].config"},
      {R"({"axes": {"variant": [{"config": {}}]}})", "axes.variant[0].name: missing"},
      {R"({"axes": {"variant": [{"name": "a", "config": {}, "x": 1}]}})", "axes.variant[0].x"},
      {R"({"axes": {"variant": ["local"]}})", "axes.variant[0]: expected {"},
      {R"({"axes": {"phases": [{"name": "texture", "config": {}}]}})", "axes.phases[0].config"},
      {R"({"axes": {"phases": [{"init": "a.ply"}]}})", "axes.phases[0].name: missing"},
      {R"({"axes": {"phases": [{"name": "texture", "init": 3}]}})", "axes.phases[0].init"},
      {R"({"axes": {"variant": [{"name": "a", "config": {}, "material": ""}]}})",
       "axes.variant[0].material: expected a non-empty string"},
      {R"({"time_budget": -1})", "time_budget: expected seconds"},
      {R"({"time_budget": "60"})", "time_budget"},
      {R"({"outer_iterations": 0})", "outer_iterations: expected an integer"},
      {R"({"eval": {"spp": 0}})", "eval.spp: must be in"},
      {R"({"eval": {"f1_tolerance": 2}})", "eval.f1_tolerance"},
      {R"({"eval": {"mesh_samples": 10}})", "eval.mesh_samples"},
      {R"({"eval": {"seed": 1}})", "eval.seed: unknown key"},
      {R"({"config": {"spp": "many"}})", "config: spp: expected"},
      {R"({"config": {"spp": 16, "nonsense": 1}})", "nonsense"},
      {R"({"config": "missing.json"})", "missing.json"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.grid);
    testing::WriteTestFile(tmp.Join("grid.json"), c.grid);
    SweepGrid grid;
    const Status status = ReadSweepGrid(tmp.Join("grid.json"), &grid);
    ASSERT_FALSE(status.ok());
    EXPECT_THAT(status.message(), StartsWith(tmp.Join("grid.json")));
    EXPECT_THAT(status.message(), HasSubstr(c.field));
    EXPECT_EQ(status.message().find('\n'), std::string::npos);
  }
  // A grid without a dataset parses; Check names the missing field.
  SweepGrid grid;
  ASSERT_TRUE(ParseSweepGrid(json::object(), "g", ".", &grid).ok());
  std::string why;
  EXPECT_FALSE(grid.Check(&why));
  EXPECT_THAT(why, HasSubstr("dataset"));
}

// The last axis varies fastest; ids carry the index and each value; a variant's keys come first
// and a plain axis overrides them.
TEST(SweepGridTest, EnumeratesTheProductOfTheAxes) {
  SweepGrid grid;
  ASSERT_TRUE(ParseSweepGrid(json::parse(R"({"dataset": "ds", "axes": {
      "spp": [4, 16], "effects": ["direct,shadows"], "bounces": [1, "auto"],
      "variant": [{"name": "local", "config": {"bounces": 2, "phases": "geometry"}},
                  {"name": "all", "config": {}}]}})"),
                             "g", ".", &grid)
                  .ok());
  const std::vector<SweepCell> cells = EnumerateCells(grid);
  ASSERT_EQ(cells.size(), 8u);
  EXPECT_EQ(cells[0].id, "00_local_bounces1_effects-direct-shadows_spp4");
  EXPECT_EQ(cells[1].id, "01_local_bounces1_effects-direct-shadows_spp16");
  EXPECT_EQ(cells[2].id, "02_local_bouncesauto_effects-direct-shadows_spp4");
  EXPECT_EQ(cells[7].id, "07_all_bouncesauto_effects-direct-shadows_spp16");
  EXPECT_EQ(cells[0].config, json::parse(R"({"bounces": 1, "phases": "geometry",
                                           "effects": "direct,shadows", "spp": 4})"));
  EXPECT_EQ(cells[2].settings,
            json::parse(R"({"variant": "local", "bounces": "auto", "effects": "direct,shadows",
                            "spp": 4})"));
  std::set<std::string> ids;
  for (const SweepCell& cell : cells) {
    EXPECT_EQ(cell.index, static_cast<int>(ids.size()));
    ids.insert(cell.id);
    EXPECT_EQ(cell.views, 0);
  }
  EXPECT_EQ(ids.size(), cells.size());
  // No axes: one cell, the base configuration.
  SweepGrid single;
  ASSERT_TRUE(ParseSweepGrid(json::parse(R"({"dataset": "ds"})"), "g", ".", &single).ok());
  ASSERT_EQ(EnumerateCells(single).size(), 1u);
  EXPECT_EQ(EnumerateCells(single)[0].id, "00");
}

// Variant and phases values as objects give their cells a start of their own; files resolve
// against the grid's folder, the words "reference", "ground_truth" and "grey" and inline JSON
// stay; the grid's JSON form keeps them.
TEST(SweepGridTest, ObjectValuesGiveTheirCellsAStart) {
  SweepGrid grid;
  ASSERT_TRUE(ParseSweepGrid(json::parse(R"({"dataset": "ds", "axes": {
      "variant": [{"name": "a", "config": {"bounces": 1}, "init": "start.ply"},
                  {"name": "b", "config": {}, "material": "{\"albedo\": [0.2, 0.2, 0.2]}"}],
      "phases": [{"name": "geometry", "material": "ground_truth"},
                 {"name": "texture", "init": "reference", "material": "grey"}, "both"]}})"),
                             "g", "/grids", &grid)
                  .ok());
  const std::vector<SweepCell> cells = EnumerateCells(grid);
  ASSERT_EQ(cells.size(), 6u);
  EXPECT_EQ(cells[0].id, "00_a_geometry");
  EXPECT_EQ(cells[0].init, "/grids/start.ply");
  EXPECT_EQ(cells[0].material, "ground_truth");
  EXPECT_EQ(cells[0].config, json::parse(R"({"bounces": 1, "phases": "geometry"})"));
  EXPECT_EQ(cells[0].settings, json::parse(R"({"variant": "a", "phases": "geometry"})"));
  EXPECT_EQ(cells[1].init, "reference");  // the later axis wins.
  EXPECT_EQ(cells[1].material, "grey");
  EXPECT_EQ(cells[2].init, "/grids/start.ply");
  EXPECT_EQ(cells[2].material, "");
  EXPECT_EQ(cells[5].id, "05_b_both");
  EXPECT_EQ(cells[5].init, "");
  EXPECT_EQ(cells[5].material, "{\"albedo\": [0.2, 0.2, 0.2]}");
  SweepGrid again;
  ASSERT_TRUE(ParseSweepGrid(SweepGridJson(grid), "grid.json", "/", &again).ok());
  EXPECT_EQ(SweepGridJson(again), SweepGridJson(grid));
  EXPECT_EQ(EnumerateCells(again)[1].init, "reference");
}

TEST(SweepGridTest, EvenlySpacedViews) {
  std::vector<int> views;
  ASSERT_TRUE(EvenlySpacedViews(4, 10, &views).ok());
  EXPECT_EQ(views, (std::vector<int>{0, 2, 5, 7}));
  ASSERT_TRUE(EvenlySpacedViews(3, 3, &views).ok());
  EXPECT_EQ(views, (std::vector<int>{0, 1, 2}));
  ASSERT_TRUE(EvenlySpacedViews(1, 16, &views).ok());
  EXPECT_EQ(views, (std::vector<int>{0}));
  EXPECT_THAT(EvenlySpacedViews(64, 16, &views).message(),
              HasSubstr("views: 64 views asked, the dataset has 16"));
  EXPECT_FALSE(EvenlySpacedViews(0, 16, &views).ok());
}

// The report's ablations: views 8/16/32/64 × local, local + shadows, global illumination × geometry
// and texture, at 16 spp, with one time budget for every cell.
TEST(SweepGridTest, AblationsPreset) {
  SweepGrid grid;
  ASSERT_TRUE(PresetSweepGrid("ablations", &grid).ok());
  EXPECT_EQ(grid.config["spp"], 16);
  ASSERT_EQ(grid.config["stages"].size(), 1u);  // one Adam stage spends the budget.
  EXPECT_EQ(grid.config["stages"][0]["solver"], "adam");
  EXPECT_GT(grid.time_budget, 0.0);
  const std::vector<SweepCell> cells = EnumerateCells(grid);
  ASSERT_EQ(cells.size(), 24u);
  EXPECT_EQ(cells[0].id, "00_local_geometry_views8");
  EXPECT_EQ(cells[0].views, 8);
  EXPECT_EQ(cells[0].config, json::parse(R"({"bounces": 1, "effects": "direct,specular,environment",
                                           "phases": "geometry"})"));
  EXPECT_EQ(cells[0].init, "");  // geometry: the grid's start, holding the true material.
  EXPECT_EQ(cells[0].material, "ground_truth");
  EXPECT_EQ(cells[7].id, "07_local_texture_views64");
  EXPECT_EQ(cells[7].init, "reference");  // texture: the true shape, from grey.
  EXPECT_EQ(cells[7].material, "grey");
  EXPECT_EQ(cells[8].config["effects"], "direct,shadows,specular,environment");
  EXPECT_EQ(cells[23].id, "23_global_texture_views64");
  EXPECT_EQ(cells[23].config, json::parse(R"({"bounces": 2, "effects": "all",
                                            "phases": "texture"})"));
  EXPECT_THAT(PresetSweepGrid("nope", &grid).message(), HasSubstr("--preset"));
}

TEST(SweepGridTest, OverridesReplaceTheGridsValuesAndNameTheFlag) {
  testing::TempDir tmp;
  SweepGrid grid;
  ASSERT_TRUE(PresetSweepGrid("ablations", &grid).ok());
  testing::WriteTestFile(tmp.Join("cfg.json"), R"({"spp": 64, "steps": 2})");
  SweepOverrides o;
  o.dataset = tmp.Join("ds");
  o.config = tmp.Join("cfg.json");
  o.time_budget = 30;
  o.eval_spp = 16;
  ASSERT_TRUE(ApplySweepOverrides(o, &grid).ok());
  EXPECT_EQ(grid.dataset, tmp.Join("ds"));
  EXPECT_EQ(grid.config["spp"], 16);  // the preset's spp wins.
  EXPECT_EQ(grid.config["steps"], 2);
  EXPECT_EQ(grid.config["stages"].size(), 1u);
  EXPECT_EQ(grid.time_budget, 30.0);
  EXPECT_EQ(grid.eval.spp, 16);
  auto with = [](const std::function<void(SweepOverrides*)>& set) {
    SweepOverrides o;
    set(&o);
    return o;
  };
  const struct {
    SweepOverrides o;
    const char* flag;
  } bad[] = {{with([](SweepOverrides* o) { o->time_budget = -2; }), "--time-budget"},
             {with([](SweepOverrides* o) { o->outer_iterations = -1; }), "--outer"},
             {with([](SweepOverrides* o) { o->eval_spp = -5; }), "--eval-spp"},
             {with([](SweepOverrides* o) { o->eval_bounces = 99; }), "--eval-bounces"},
             {with([&](SweepOverrides* o) { o->config = tmp.Join("missing.json"); }), "--config"}};
  for (const auto& c : bad) {
    SweepGrid g;
    EXPECT_THAT(ApplySweepOverrides(c.o, &g).message(), StartsWith(c.flag));
  }
}

}  // namespace
}  // namespace sft
