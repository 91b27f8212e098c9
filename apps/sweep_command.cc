// sft sweep: runs a whole reconstruction per cell of a grid of settings, scores each with sft
// eval's code, and charts accuracy against wall time (src/sweep/sweep_runner.h; the grid format
// in src/sweep/sweep_grid.h and docs/cli.md). This file only reads the grid, applies the flags and
// reports. Ctrl-C stops after the current solver iteration and exits 130; running the same
// command again continues with the unfinished cells.
#include <atomic>
#include <csignal>
#include <cstdio>

#include "apps/commands.h"
#include "src/sweep/sweep_grid.h"
#include "src/sweep/sweep_runner.h"

namespace sft {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void OnSweepInterrupt(int) { g_interrupted = true; }

struct SweepCommandOptions {
  std::string grid;    // grid JSON file.
  std::string preset;  // or a built-in grid: "ablations".
  std::string out;     // the sweep's folder.
  SweepOverrides overrides;
  bool print_cells = false;
  bool quiet = false;
};

Status LoadGrid(const SweepCommandOptions& cli, SweepGrid* grid) {
  if (cli.grid.empty() == cli.preset.empty()) {
    return Status::Error("give one of --grid GRID.json and --preset ablations");
  }
  SFT_RETURN_IF_ERROR(cli.grid.empty() ? PresetSweepGrid(cli.preset, grid)
                                       : ReadSweepGrid(cli.grid, grid));
  SFT_RETURN_IF_ERROR(ApplySweepOverrides(cli.overrides, grid));
  std::string why;
  if (!grid->Check(&why)) {
    return Status::Error((cli.grid.empty() ? "--preset " + cli.preset : cli.grid) + ": " + why);
  }
  return Status::Ok();
}

Status RunSweepCommand(const SweepCommandOptions& cli) {
  SweepGrid grid;
  SFT_RETURN_IF_ERROR(LoadGrid(cli, &grid));
  if (cli.print_cells) {
    for (const SweepCell& cell : EnumerateCells(grid)) {
      std::printf("%s %s\n", cell.id.c_str(), cell.settings.dump().c_str());
    }
    return Status::Ok();
  }
  if (cli.out.empty()) return Status::Error("--out: required");
  SweepRunOptions options;
  options.out = cli.out;
  options.grid_file = cli.grid;
  options.progress = !cli.quiet;
  options.interrupted = [] { return g_interrupted.load(); };
  SweepSummary summary;
  SFT_RETURN_IF_ERROR(RunSweep(grid, options, &summary));
  const int done = summary.done_before + summary.run;
  if (summary.interrupted) {
    return Status::Error("interrupted with " + std::to_string(done) + " of " +
                         std::to_string(summary.cells) + " cells done (" + cli.out +
                         "/sweep.jsonl); run the same command again to continue");
  }
  std::printf("sft sweep: %d cells (%d run now, %d before; %d errors); %s/sweep.jsonl, report %s\n",
              summary.cells, summary.run, summary.done_before, summary.errors, cli.out.c_str(),
              summary.report.c_str());
  return Status::Ok();
}

}  // namespace

CommandRunner SetupSweepCommand(CLI::App* app) {
  auto opts = std::make_shared<SweepCommandOptions>();
  SweepOverrides& o = opts->overrides;
  app->add_option("--grid", opts->grid, "Grid JSON (docs/cli.md, \"sft sweep\")");
  app->add_option("--preset", opts->preset, "Built-in grid instead of --grid: ablations");
  app->add_option("--out", opts->out, "The sweep's folder (an existing one continues)");
  app->add_option("--dataset", o.dataset, "Dataset (replaces the grid's)");
  app->add_option("--init", o.init, "Start mesh of every cell (replaces the grid's)");
  app->add_option("--reference", o.reference, "Reference mesh for Chamfer and F1");
  app->add_option("--material", o.material, "Initial material (JSON file or inline)");
  app->add_option("--config", o.config,
                  "Reconstruct config under the grid's own config keys (docs/reconstruct.md)");
  app->add_option("--time-budget", o.time_budget, "Wall-time budget per cell, seconds");
  app->add_option("--outer", o.outer_iterations, "Outer iterations of every cell's stages");
  app->add_option("--eval-spp", o.eval_spp, "Samples per pixel of the scoring re-renders");
  app->add_option("--eval-bounces", o.eval_bounces, "Path segments of the scoring re-renders");
  app->add_flag("--print-cells", opts->print_cells,
                "Print each cell's id and settings and exit (nothing is written)");
  app->add_flag("--quiet", opts->quiet, "No progress line (one line per finished cell stays)");
  return [opts]() {
    g_interrupted = false;
    std::signal(SIGINT, OnSweepInterrupt);
    const Status status = RunSweepCommand(*opts);
    std::signal(SIGINT, SIG_DFL);
    if (status.ok()) return 0;
    PrintError("sweep", status);
    return g_interrupted ? 130 : 1;
  };
}

}  // namespace sft
