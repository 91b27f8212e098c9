// One cell of `sft sweep`: its reconstruction, run in-process through the schedule
// (src/optim/schedule.h, configured as `sft reconstruct` configures it) in the cell's own folder,
// then scored with `sft eval`'s code (src/eval/reconstruction_eval.h for the images of the fitted
// views at the dataset's resolution, src/eval/mesh_metrics.h for Chamfer and F1) into one JSON
// line of sweep.jsonl.
#ifndef SFT_SWEEP_SWEEP_CELL_H_
#define SFT_SWEEP_SWEEP_CELL_H_

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/schedule.h"
#include "src/optim/start_mesh.h"
#include "src/sweep/sweep_grid.h"

namespace sft {

// What every cell of a sweep shares, loaded once.
struct SweepContext {
  const SweepGrid* grid = nullptr;
  Dataset dataset;
  StartChoice start;
  ScheduleStart start_state;      // the start mesh and initial material.
  TriMesh reference;              // when grid->reference is set.
  nlohmann::json default_stages;  // the base configuration's stages (IsDefault compares).
};

// Reads the dataset, the reference and the start (carving a hull when the grid gives no mesh
// and the dataset none), and the base stages.
Status LoadSweepContext(const SweepGrid& grid, SweepContext* context);

// What a cell starts from: the context's start, or the mesh and material its axis values name
// (SweepCell::init, material).
struct CellStart {
  StartChoice choice;
  std::string material;  // the initial material as loaded (file or inline JSON); "" = grey.
  ScheduleStart state;   // the start mesh and initial material.
};

// Loads the cell's start. Errors (the cell's): "reference" without a grid reference, a
// "ground_truth" material the dataset does not name, a mesh or material that does not load.
Status LoadCellStart(const SweepContext& context, const SweepCell& cell, CellStart* start);

// The cell's stages: the base config, the grid's outer_iterations (or 10000 with a time budget
// and none given), the cell's keys, its evenly spaced views. Errors are the cell's (recorded,
// the sweep goes on): a key the configuration rejects, more views than the dataset has.
Status CellStages(const SweepContext& context, const SweepCell& cell,
                  std::vector<StageOptions>* stages);

// True when `stages` are what the base configuration alone runs (the default configuration;
// fitting every view counts as the default views).
bool IsDefaultStages(const SweepContext& context, const std::vector<StageOptions>& stages);

// Hooks of a running cell.
struct CellCallbacks {
  // After every solver iteration with the run's seconds so far; false stops the sweep.
  std::function<bool(double seconds, const StageOptions& stage)> on_iteration;
};

// Runs the cell's reconstruction in `dir` (created; absent or empty before) and scores it.
// *line receives the cell's JSON line (settings, status, seconds, scores). *interrupted is set
// when the callback stopped it (then *line is not meaningful). A failure of the cell (its
// configuration, the run, writing its files, scoring) is a line with "status": "error" and the
// message, and the sweep goes on; the returned status is OK today (kept for failures that must
// stop the sweep).
Status RunCell(const SweepContext& context, const SweepCell& cell, const std::string& dir,
               const CellCallbacks& callbacks, nlohmann::json* line, bool* interrupted);

}  // namespace sft

#endif  // SFT_SWEEP_SWEEP_CELL_H_
