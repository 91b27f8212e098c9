// `sft sweep`: runs every cell of a grid (src/sweep/sweep_grid.h) as a full reconstruction in
// OUT/cells/<id>/ (src/sweep/sweep_cell.h), appends one JSON line per finished cell to
// OUT/sweep.jsonl and rewrites OUT/report.html (src/sweep/sweep_report.h) after each.
//
// Resumable: OUT/grid.json records the grid; running again with the same grid skips the cells
// that sweep.jsonl holds and restarts any other cell from scratch (its folder is removed first),
// whether the last session was interrupted (SIGINT) or killed. A different grid in an existing
// OUT is refused. sweep.jsonl is rewritten whole and atomically per cell, so it never holds a
// partial line.
#ifndef SFT_SWEEP_SWEEP_RUNNER_H_
#define SFT_SWEEP_SWEEP_RUNNER_H_

#include <functional>
#include <string>

#include "src/core/status.h"
#include "src/sweep/sweep_grid.h"

namespace sft {

struct SweepRunOptions {
  std::string out;        // the sweep's folder.
  std::string grid_file;  // the grid's file, an input the folder must not hold ("" for a preset).
  bool progress = true;   // the progress line over the whole grid (stderr).
  // Polled after every solver iteration; true stops the sweep after that iteration (the
  // unfinished cell is redone by the next run).
  std::function<bool()> interrupted;
};

struct SweepSummary {
  int cells = 0;             // in the grid.
  int done_before = 0;       // finished by earlier runs (skipped).
  int run = 0;               // finished by this run.
  int errors = 0;            // cells recorded with "status": "error" (all runs).
  bool interrupted = false;  // stopped before the last cell.
  std::string report;        // OUT/report.html.
};

Status RunSweep(const SweepGrid& grid, const SweepRunOptions& options, SweepSummary* summary);

}  // namespace sft

#endif  // SFT_SWEEP_SWEEP_RUNNER_H_
