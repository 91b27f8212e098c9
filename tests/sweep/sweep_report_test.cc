// OUT/report.html of `sft sweep` (src/sweep/sweep_report.h) from hand-made sweep lines: the five
// charts, the fronts in the table, the default configuration, errors and cells not run yet.
#include "src/sweep/sweep_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using json = nlohmann::json;
using ::testing::HasSubstr;
using ::testing::Not;

json Line(const std::string& id, double seconds, double chamfer, double f1, double psnr,
          bool is_default = false) {
  const json pass = {{"psnr_srgb", psnr},
                     {"ssim_srgb", 0.9},
                     {"psnr_linear", psnr - 1},
                     {"ssim_linear", 0.8},
                     {"rel_rmse", 0.1}};
  return {{"id", id},           {"status", "ok"},    {"seconds", seconds},
          {"chamfer", chamfer}, {"f1", f1},          {"full", pass},
          {"albedo", pass},     {"roughness", pass}, {"default", is_default}};
}

TEST(SweepReportTest, WritesFrontsTableAndDefault) {
  testing::TempDir tmp;
  SweepGrid grid;
  ASSERT_TRUE(ParseSweepGrid(json::parse(R"({"dataset": "ds", "reference": "gt.ply",
                                              "axes": {"solver": ["lm", "adam"],
                                                       "spp": [4, 16, 64]}})"),
                             "g", "/", &grid)
                  .ok());
  const std::vector<SweepCell> cells = EnumerateCells(grid);
  ASSERT_EQ(cells.size(), 6u);
  // Cell 1 is best in everything and slowest; cell 0 is fastest; cell 2 is slower than 0 and
  // worse: dominated. Cell 3 failed; cells 4 and 5 have not run.
  std::vector<json> lines = {Line(cells[0].id, 10, 0.01, 0.5, 20),
                             Line(cells[1].id, 30, 0.001, 0.9, 35, /*is_default=*/true),
                             Line(cells[2].id, 20, 0.02, 0.4, 18)};
  lines.push_back({{"id", cells[3].id}, {"status", "error"}, {"error", "bounces: <bad>"}});
  ASSERT_TRUE(WriteSweepReport(tmp.path(), grid, cells, lines).ok());
  const std::string html = testing::ReadTestFile(tmp.Join("report.html"));
  size_t charts = 0;
  for (size_t p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1)) ++charts;
  EXPECT_EQ(charts, 5u);  // no trajectories: no chart of them.
  EXPECT_THAT(html, Not(HasSubstr("Accuracy within each cell")));
  for (const char* text :
       {"Chamfer against wall time", "F1 against wall time", "full PSNR against wall time",
        "albedo PSNR against wall time", "roughness PSNR against wall time", "Pareto front",
        "default configuration", "not run yet", "the fronts use this PSNR",
        "error: bounces: &lt;bad&gt;"}) {
    EXPECT_THAT(html, HasSubstr(text)) << text;
  }
  // Table 1's column order after the settings.
  EXPECT_THAT(html, HasSubstr("<th>spp</th><th>wall s</th><th>Chamfer</th><th>F1</th><th>full "
                              "PSNR</th><th>full SSIM</th><th>albedo PSNR</th><th>albedo "
                              "SSIM</th><th>roughness PSNR</th><th>roughness SSIM</th>"));
  // Cells 0 and 1 are on all five fronts, cell 2 on none.
  EXPECT_THAT(html, HasSubstr("<td>CFPAR</td><td>default configuration</td>"));
  const size_t row2 = html.find("<td>" + cells[2].id + "</td>");
  ASSERT_NE(row2, std::string::npos);
  EXPECT_THAT(html.substr(row2, html.find("</tr>", row2) - row2), HasSubstr("<td></td><td></td>"));
  // The default cell is ringed in every chart.
  EXPECT_THAT(html, HasSubstr("default: " + cells[1].id));
  EXPECT_THAT(html, Not(HasSubstr("same wall-time budget")));
  // With a time budget the report says that the fronts compare equal times.
  grid.time_budget = 300;
  ASSERT_TRUE(WriteSweepReport(tmp.path(), grid, cells, lines).ok());
  EXPECT_THAT(testing::ReadTestFile(tmp.Join("report.html")),
              HasSubstr("Every cell had the same wall-time budget"));
}

TEST(SweepReportTest, WithoutReferenceOrResultsSaysSo) {
  testing::TempDir tmp;
  SweepGrid grid;
  ASSERT_TRUE(ParseSweepGrid(json::parse(R"({"dataset": "ds"})"), "g", "/", &grid).ok());
  ASSERT_TRUE(WriteSweepReport(tmp.path(), grid, EnumerateCells(grid), {}).ok());
  const std::string html = testing::ReadTestFile(tmp.Join("report.html"));
  EXPECT_THAT(html, HasSubstr("Chamfer: no finished cell has it (the grid gives no reference"));
  EXPECT_THAT(html, HasSubstr("not among the finished cells"));
  EXPECT_EQ(html.find("<svg"), std::string::npos);
}

// Cells with per-outer scores get one line each in a chart of Chamfer within the cell; a cell
// whose trajectory has no Chamfer (no reference) is left out of it.
TEST(SweepReportTest, TrajectoriesChart) {
  testing::TempDir tmp;
  SweepGrid grid;
  ASSERT_TRUE(ParseSweepGrid(json::parse(R"({"dataset": "ds", "reference": "gt.ply",
                                              "axes": {"spp": [4, 16]}})"),
                             "g", "/", &grid)
                  .ok());
  const std::vector<SweepCell> cells = EnumerateCells(grid);
  json a = Line(cells[0].id, 10, 0.01, 0.5, 20), b = Line(cells[1].id, 12, 0.02, 0.4, 19);
  a["trajectory"] = json::parse(R"([{"stage": "half", "seconds": 4, "chamfer": 0.03},
                                    {"stage": "full_stage", "seconds": 9, "chamfer": 0.012}])");
  b["trajectory"] = json::parse(R"([{"stage": "half", "seconds": 5}])");
  ASSERT_TRUE(WriteSweepReport(tmp.path(), grid, cells, {a, b}).ok());
  const std::string html = testing::ReadTestFile(tmp.Join("report.html"));
  size_t charts = 0;
  for (size_t p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1)) ++charts;
  EXPECT_EQ(charts, 6u);
  EXPECT_THAT(html, HasSubstr("Accuracy within each cell"));
  EXPECT_THAT(html, HasSubstr("full_stage: 0.012"));  // the tooltip of a's second point.
  const size_t chart = html.find("Chamfer within each cell");
  ASSERT_NE(chart, std::string::npos);
  const std::string svg = html.substr(chart, html.find("</svg>", chart) - chart);
  EXPECT_THAT(svg, HasSubstr(cells[0].id));
  EXPECT_THAT(svg, Not(HasSubstr(cells[1].id)));
}

TEST(SweepReportTest, LineValues) {
  const json line = Line("a", 1, 0.5, 0.25, 30);
  EXPECT_EQ(SweepLineValue(line, kSweepMeasures[0]), 0.5);
  EXPECT_EQ(SweepLineValue(line, kSweepMeasures[1]), 0.25);
  EXPECT_EQ(SweepLineValue(line, kSweepMeasures[3]), 30.0);
  EXPECT_TRUE(std::isnan(SweepLineValue({{"id", "b"}, {"albedo", nullptr}}, kSweepMeasures[3])));
}

}  // namespace
}  // namespace sft
