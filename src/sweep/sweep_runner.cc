#include "src/sweep/sweep_runner.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/eval/report.h"
#include "src/sweep/sweep_cell.h"
#include "src/sweep/sweep_report.h"

namespace sft {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

constexpr char kGridFile[] = "grid.json";
constexpr char kLinesFile[] = "sweep.jsonl";
// Progress units of a cell's whole fit under a time budget.
constexpr int64_t kBudgetCellWork = 1000;

// Refuses an OUT among the inputs.
Status CheckFolder(const SweepGrid& grid, const SweepRunOptions& options) {
  const RunInputs inputs{{grid.dataset},
                         {grid.init, grid.material.rfind('{', 0) == 0 ? "" : grid.material,
                          grid.reference, options.grid_file}};
  return CheckOutputDirectory(options.out, inputs, "--out");
}

// Whether OUT already holds a sweep of this grid (*resume); refuses one of another grid and a
// non-empty folder that holds no sweep. Writes nothing.
Status MatchFolder(const SweepGrid& grid, const SweepRunOptions& options, bool* resume) {
  const std::string grid_path = JoinPath(options.out, kGridFile);
  const json wanted = SweepGridJson(grid);
  *resume = FileExists(grid_path);
  if (*resume) {
    std::string text;
    SFT_RETURN_IF_ERROR(ReadTextFile(grid_path, &text));
    const json stored = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (stored == wanted) return Status::Ok();
    std::string key = "the whole grid";
    if (stored.is_object()) {
      for (const auto& [name, value] : wanted.items()) {
        if (!stored.contains(name) || stored[name] != value) {
          key = "\"" + name + "\"";
          break;
        }
      }
    }
    return Status::Error("--out " + options.out + ": holds a sweep of another grid (" + grid_path +
                         " differs in " + key + "); choose another folder");
  }
  std::error_code error;
  if (fs::exists(options.out, error) && !fs::is_empty(options.out, error)) {
    return Status::Error("--out " + options.out + ": not empty and holds no sweep (no " +
                         std::string(kGridFile) + "); choose a new or empty folder");
  }
  return Status::Ok();
}

// The lines of earlier runs; each must name a cell of the grid once.
Status ReadLines(const std::string& path, const std::vector<SweepCell>& cells,
                 std::vector<json>* lines) {
  lines->clear();
  if (!FileExists(path)) return Status::Ok();
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  std::map<std::string, int> seen;
  for (const SweepCell& cell : cells) seen[cell.id] = 0;
  std::istringstream in(text);
  std::string row;
  for (int number = 1; std::getline(in, row); ++number) {
    if (row.empty()) continue;
    const json line = json::parse(row, nullptr, /*allow_exceptions=*/false);
    const std::string where = path + ":" + std::to_string(number);
    if (!line.is_object() || !line.contains("id") || !line["id"].is_string()) {
      return Status::Error(where + ": not a sweep line (a JSON object with an \"id\")");
    }
    const auto it = seen.find(line["id"].get<std::string>());
    if (it == seen.end()) return Status::Error(where + ": not a cell of this grid");
    if (it->second++ > 0) return Status::Error(where + ": the cell is already recorded");
    lines->push_back(line);
  }
  return Status::Ok();
}

Status WriteLines(const std::string& path, const std::vector<json>& lines) {
  std::string text;
  for (const json& line : lines) text += line.dump() + "\n";
  return WriteTextFile(path, text);
}

// Progress units of a cell: its fit (solver steps weighted by pixels × spp, times the fitted
// fraction of the views; or kBudgetCellWork under a time budget) and its scoring (about a
// quarter of a solver step at the scoring spp: forward renders only).
struct CellWork {
  int64_t fit = 1;
  int64_t eval = 0;
  double view_fraction = 1.0;
};

CellWork EstimateWork(const SweepContext& context, const SweepCell& cell) {
  CellWork work;
  std::vector<StageOptions> stages;
  if (!CellStages(context, cell, &stages).ok()) return work;
  const size_t views = context.dataset.views.size();
  const size_t fitted = stages.back().fit.views.empty() ? views : stages.back().fit.views.size();
  work.view_fraction = views > 0 ? static_cast<double>(fitted) / views : 1.0;
  work.fit = context.grid->time_budget > 0.0
                 ? kBudgetCellWork
                 : std::max<int64_t>(1, Schedule::TotalWork(stages, static_cast<int>(views)) *
                                            work.view_fraction);
  work.eval =
      context.grid->time_budget > 0.0
          ? 0
          : static_cast<int64_t>(250.0 * context.grid->eval.spp / 16.0 * work.view_fraction);
  return work;
}

std::string NoteLine(const json& line, int position, int count) {
  std::string note = "cell " + std::to_string(position) + "/" + std::to_string(count) + " " +
                     line["id"].get<std::string>() + ": ";
  if (line.value("status", "") != "ok") return note + "error: " + line.value("error", "?");
  auto number = [&](const json& v) { return v.is_number() ? FormatNumber(v.get<double>()) : "-"; };
  note += number(line["seconds"]) + " s";
  if (line["f1"].is_number()) {
    note += ", Chamfer " + number(line["chamfer"]) + ", F1 " + number(line["f1"]);
  }
  if (line["full"].is_object()) note += ", full PSNR " + number(line["full"]["psnr_srgb"]) + " dB";
  return note;
}

}  // namespace

Status RunSweep(const SweepGrid& grid, const SweepRunOptions& options, SweepSummary* summary) {
  *summary = SweepSummary();
  std::string why;
  if (!grid.Check(&why)) return Status::Error(why);
  SFT_RETURN_IF_ERROR(CheckFolder(grid, options));
  bool resume = false;
  SFT_RETURN_IF_ERROR(MatchFolder(grid, options, &resume));
  // Every input is read before anything is written: a bad one leaves no folder behind.
  auto context = std::make_unique<SweepContext>();
  SFT_RETURN_IF_ERROR(LoadSweepContext(grid, context.get()));
  if (!resume) {
    SFT_RETURN_IF_ERROR(MakeDirectories(options.out));
    SFT_RETURN_IF_ERROR(
        WriteTextFile(JoinPath(options.out, kGridFile), SweepGridJson(grid).dump(1) + "\n"));
  }
  const std::vector<SweepCell> cells = EnumerateCells(grid);
  const std::string lines_path = JoinPath(options.out, kLinesFile);
  std::vector<json> lines;
  SFT_RETURN_IF_ERROR(ReadLines(lines_path, cells, &lines));
  std::map<std::string, bool> done;
  for (const json& line : lines) done[line["id"].get<std::string>()] = true;
  summary->cells = static_cast<int>(cells.size());
  summary->done_before = static_cast<int>(lines.size());
  summary->report = JoinPath(options.out, "report.html");

  std::map<int, CellWork> work;
  int64_t total = 0;
  for (const SweepCell& cell : cells) {
    if (done.count(cell.id)) continue;
    work[cell.index] = EstimateWork(*context, cell);
    total += work[cell.index].fit + work[cell.index].eval;
  }
  Progress progress("sweep", std::max<int64_t>(1, total), options.progress);
  for (const SweepCell& cell : cells) {
    if (done.count(cell.id)) continue;
    if (options.interrupted && options.interrupted()) {  // e.g. during the last cell's scoring.
      summary->interrupted = true;
      break;
    }
    progress.SetDetail(cell.id);
    const std::string dir = JoinPath(JoinPath(options.out, "cells"), cell.id);
    std::error_code error;
    fs::remove_all(dir, error);  // an unfinished cell of an earlier run starts over.
    if (error)
      return Status::Error(dir + ": cannot remove the unfinished cell: " + error.message());
    const CellWork& w = work[cell.index];
    int64_t advanced = 0, steps = 0;
    CellCallbacks callbacks;
    callbacks.on_iteration = [&](double seconds, const StageOptions& stage) {
      // Progress within the fit: time against the budget, or solver steps done.
      steps += Schedule::StepWork(stage, static_cast<int>(context->dataset.views.size()));
      const double fraction =
          grid.time_budget > 0.0 ? seconds / grid.time_budget : steps * w.view_fraction / w.fit;
      const int64_t target = std::min<int64_t>(w.fit, static_cast<int64_t>(fraction * w.fit));
      if (target > advanced) progress.Advance(target - advanced);
      advanced = std::max(advanced, target);
      return !(options.interrupted && options.interrupted());
    };
    json line;
    bool interrupted = false;
    SFT_RETURN_IF_ERROR(RunCell(*context, cell, dir, callbacks, &line, &interrupted));
    if (interrupted) {
      summary->interrupted = true;
      break;
    }
    progress.Advance(std::max<int64_t>(0, w.fit - advanced) + w.eval);
    lines.push_back(line);
    SFT_RETURN_IF_ERROR(WriteLines(lines_path, lines));
    ++summary->run;
    progress.Note(NoteLine(line, static_cast<int>(lines.size()), summary->cells));
    SFT_RETURN_IF_ERROR(WriteSweepReport(options.out, grid, cells, lines));
  }
  if (!summary->interrupted) progress.Finish();
  for (const json& line : lines) summary->errors += line.value("status", "") != "ok";
  return WriteSweepReport(options.out, grid, cells, lines);
}

}  // namespace sft
