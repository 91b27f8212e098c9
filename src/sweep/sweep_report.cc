#include "src/sweep/sweep_report.h"

#include <cmath>
#include <limits>
#include <map>

#include "src/eval/line_chart.h"
#include "src/eval/report.h"
#include "src/sweep/pareto.h"

namespace sft {

const SweepMeasure kSweepMeasures[5] = {
    {"Chamfer", "", "chamfer", false},
    {"F1", "", "f1", true},
    {"full PSNR", "full", "psnr_srgb", true},
    {"albedo PSNR", "albedo", "psnr_srgb", true},
    {"roughness PSNR", "roughness", "psnr_srgb", true},
};

namespace {

using json = nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Number(const json& v) { return v.is_number() ? v.get<double>() : kNaN; }

bool IsOk(const json& line) { return line.value("status", "") == "ok"; }

std::string Cell(double v, int digits = 4) {
  return std::isfinite(v) ? FormatNumber(v, digits) : "–";
}

std::string AxisLabel(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

// The y-axis title of a measure.
std::string Units(const SweepMeasure& m, const SweepGrid& grid) {
  if (std::string(m.key) == "chamfer") return "Chamfer (fraction of the diagonal)";
  if (std::string(m.key) == "f1") return "F1 at " + FormatNumber(grid.eval.f1_tolerance);
  return std::string(m.name) + " (dB, sRGB)";
}

// One chart: the cells, the front and the default; the front's cells get `letter` in *fronts.
void AddFrontChart(const SweepMeasure& m, const SweepGrid& grid, const std::vector<json>& lines,
                   const std::string& letter, std::map<std::string, std::string>* fronts,
                   HtmlReport* html) {
  std::vector<double> seconds, values;
  for (const json& line : lines) {
    const bool ok = IsOk(line);
    seconds.push_back(ok ? Number(line["seconds"]) : kNaN);
    values.push_back(ok ? SweepLineValue(line, m) : kNaN);
  }
  LineSeries all{"cells", {}, {}};
  all.line = false;
  all.marker_radius = 3.5;
  all.color = "#999999";
  LineSeries front{"Pareto front", {}, {}};
  front.marker_radius = 3.5;
  front.color = "#1f77b4";
  LineSeries chosen{"default configuration", {}, {}};
  chosen.line = false;
  chosen.marker_radius = 7.0;
  chosen.hollow_markers = true;
  chosen.color = "#d62728";
  for (size_t i = 0; i < lines.size(); ++i) {
    if (!std::isfinite(values[i]) || !std::isfinite(seconds[i])) continue;
    const std::string tip = lines[i]["id"].get<std::string>() + ": " + FormatNumber(values[i]) +
                            ", " + FormatNumber(seconds[i]) + " s";
    all.x.push_back(seconds[i]);
    all.y.push_back(values[i]);
    all.tips.push_back(tip);
    if (lines[i].value("default", false)) {
      chosen.x.push_back(seconds[i]);
      chosen.y.push_back(values[i]);
      chosen.tips.push_back("default: " + tip);
    }
  }
  if (all.x.empty()) {
    html->AddParagraph(std::string(m.name) + ": no finished cell has it" +
                       (m.pass[0] == '\0' ? " (the grid gives no reference mesh)." : "."));
    return;
  }
  for (int i : ParetoFront(seconds, values, m.higher_is_better)) {
    front.x.push_back(seconds[i]);
    front.y.push_back(values[i]);
    front.tips.push_back(lines[i]["id"].get<std::string>());
    (*fronts)[lines[i]["id"].get<std::string>()] += letter;
  }
  LineChart chart;
  chart.title = std::string(m.name) + " against wall time (" +
                (m.higher_is_better ? "higher" : "lower") + " is better)";
  chart.x_label = "wall time of the reconstruction (s)";
  chart.y_label = Units(m, grid);
  chart.log_y = !m.higher_is_better;
  chart.width = 760;
  chart.height = 300;
  chart.margin = 0.05;
  chart.series = {all, front};
  if (!chosen.x.empty()) chart.series.push_back(chosen);
  html->AddSvg(LineChartSvg(chart));
}

// Chamfer after every outer iteration against the time within each cell (the lines' trajectories
// of cells with a reference); nothing when no cell has one.
void AddTrajectoryChart(const std::vector<json>& lines, HtmlReport* html) {
  LineChart chart{"Chamfer within each cell, after every outer iteration",
                  "seconds since the cell's start",
                  "Chamfer (fraction of the diagonal)",
                  true,
                  640,
                  320,
                  {}};
  for (const json& line : lines) {
    if (!IsOk(line) || !line.contains("trajectory")) continue;
    LineSeries series;
    series.name = line["id"].get<std::string>();
    series.marker_radius = 2.0;
    for (const json& point : line["trajectory"]) {
      if (!point.contains("chamfer")) continue;
      series.x.push_back(Number(point.value("seconds", json())));
      series.y.push_back(Number(point["chamfer"]));
      series.tips.push_back(point.value("stage", "") + ": " + Cell(series.y.back()));
    }
    if (!series.x.empty()) chart.series.push_back(series);
  }
  if (chart.series.empty()) return;
  html->AddHeading("Accuracy within each cell");
  html->AddParagraph(
      "Each line is one cell's Chamfer after each of its outer iterations, scored with at most "
      "50,000 samples per surface (it reads higher than the table's Chamfer, which uses the "
      "scoring's samples). At equal time, a line that is still falling at its end was stopped "
      "by the budget, not converged.");
  html->AddSvg(LineChartSvg(chart));
}

std::vector<std::pair<std::string, std::string>> Summary(const SweepGrid& grid,
                                                         const std::vector<SweepCell>& cells,
                                                         const std::vector<json>& lines) {
  int ok = 0;
  std::string default_id = "not among the finished cells";
  for (const json& line : lines) {
    ok += IsOk(line);
    if (line.value("default", false)) default_id = line["id"].get<std::string>();
  }
  const std::string budget =
      grid.time_budget > 0.0      ? FormatNumber(grid.time_budget) + " s of wall time per cell"
      : grid.outer_iterations > 0 ? std::to_string(grid.outer_iterations) + " outer iterations"
                                  : "the configuration's outer iterations";
  return {
      {"dataset", grid.dataset},
      {"start mesh", grid.init.empty() ? "the dataset's initial mesh or a carved hull" : grid.init},
      {"reference mesh", grid.reference.empty() ? "none (no Chamfer, F1)" : grid.reference},
      {"cells", std::to_string(cells.size()) + " in the grid; " + std::to_string(lines.size()) +
                    " finished, " + std::to_string(lines.size() - ok) + " of them errors"},
      {"each cell runs", budget},
      {"scoring", "re-renders of the fitted views at the dataset's resolution, " +
                      std::to_string(grid.eval.spp) + " spp, " + std::to_string(grid.eval.bounces) +
                      " bounces; F1 and Chamfer with " + std::to_string(grid.eval.mesh_samples) +
                      " samples per surface"},
      {"PSNR and SSIM",
       "of the display images (linear values clipped to [0, 1], sRGB-encoded; peak 1): the "
       "fronts use this PSNR"},
      {"default configuration", default_id}};
}

}  // namespace

double SweepLineValue(const json& line, const SweepMeasure& m) {
  if (m.pass[0] == '\0') return line.contains(m.key) ? Number(line[m.key]) : kNaN;
  if (!line.contains(m.pass) || !line[m.pass].is_object()) return kNaN;
  return line[m.pass].contains(m.key) ? Number(line[m.pass][m.key]) : kNaN;
}

Status WriteSweepReport(const std::string& out, const SweepGrid& grid,
                        const std::vector<SweepCell>& cells, const std::vector<json>& lines) {
  HtmlReport html(out, "sft sweep: " + out);
  html.AddSummaryTable(Summary(grid, cells, lines));
  html.AddHeading("Accuracy against wall time");
  html.AddParagraph(
      "Each dot is a finished cell: its accuracy against the wall time of its reconstruction "
      "(scoring not included). The line joins the Pareto front: the cells that no other cell "
      "beats in both time and accuracy. For a time you can afford, the front's cell at or left "
      "of it is the setting to choose. The ring marks the default configuration.");
  if (grid.time_budget > 0.0) {
    html.AddParagraph(
        "Every cell had the same wall-time budget, so the times differ only by where a cell's "
        "last solver iteration ended: the charts compare the cells' accuracy at equal time, and "
        "their fronts say little. Read the table below.");
  }
  std::map<std::string, std::string> fronts;
  const char* const letters[] = {"C", "F", "P", "A", "R"};
  for (int k = 0; k < 5; ++k) {
    AddFrontChart(kSweepMeasures[k], grid, lines, letters[k], &fronts, &html);
  }
  AddTrajectoryChart(lines, &html);
  html.AddHeading("Every cell");
  html.AddParagraph(
      "Columns after the settings follow the research report's Table 1: F1, then PSNR (dB) and "
      "SSIM of the full, diffuse (albedo) and roughness images (display images). 'fronts' lists "
      "the Pareto fronts the cell is on: C Chamfer, F F1, P full, A albedo, R roughness PSNR.");
  std::vector<std::string> header = {"cell"};
  for (const SweepAxis& axis : grid.axes) header.push_back(axis.name);
  for (const char* h : {"wall s", "Chamfer", "F1", "full PSNR", "full SSIM", "albedo PSNR",
                        "albedo SSIM", "roughness PSNR", "roughness SSIM", "fronts", "note"}) {
    header.push_back(h);
  }
  std::map<std::string, const json*> by_id;
  for (const json& line : lines) by_id[line["id"].get<std::string>()] = &line;
  std::vector<std::vector<std::string>> rows;
  for (const SweepCell& cell : cells) {
    std::vector<std::string> row = {cell.id};
    for (const SweepAxis& axis : grid.axes) row.push_back(AxisLabel(cell.settings[axis.name]));
    const auto it = by_id.find(cell.id);
    if (it == by_id.end()) {
      row.push_back("not run yet");
      rows.push_back(row);
      continue;
    }
    const json& line = *it->second;
    row.push_back(Cell(Number(line.value("seconds", json()))));
    row.push_back(Cell(Number(line.value("chamfer", json()))));
    row.push_back(Cell(Number(line.value("f1", json()))));
    for (const char* pass : {"full", "albedo", "roughness"}) {
      const json& p = line.contains(pass) ? line[pass] : json();
      row.push_back(Cell(p.is_object() ? Number(p.value("psnr_srgb", json())) : kNaN));
      row.push_back(Cell(p.is_object() ? Number(p.value("ssim_srgb", json())) : kNaN, 3));
    }
    row.push_back(fronts.count(cell.id) ? fronts[cell.id] : "");
    std::string note = line.value("default", false) ? "default configuration" : "";
    if (!IsOk(line)) note = "error: " + line.value("error", "?");
    if (line.value("ended_by", "") == "time_budget") {
      note += std::string(note.empty() ? "" : "; ") + "ended by the time budget";
    }
    row.push_back(note);
    rows.push_back(row);
  }
  html.AddTable(header, rows);
  return html.Write();
}

}  // namespace sft
