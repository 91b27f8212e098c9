// Where the time of a reconstruction goes (`sft bench reconstruct`, issue 11 item 8): one outer
// iteration of `sft reconstruct` on a dataset (its own cameras, lights and material), with the
// wall time of each phase split into superset renders, problem assembly, Ceres' start-up, renders
// (forward + Jacobian rows, or adjoint), pyramid, the rest of the evaluations (rows copied into
// Ceres in double, regularizers), the linear solve and the remainder (SolverTimeSplit), against
// a baseline measured in the same run: one forward render of every fitted view at the fit's spp,
// bounces and threads. Also the problem's size, the rows' memory and the process's peak resident
// set.
#ifndef SFT_EVAL_RECONSTRUCT_COST_H_
#define SFT_EVAL_RECONSTRUCT_COST_H_

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/reconstruct.h"

namespace sft {

struct ReconstructCostOptions {
  // The run's options (solver, phases, steps, spp, bounces, threads, views); outer_iterations is
  // ignored: the benchmark runs outer iteration 0 only.
  ReconstructOptions reconstruct;
  bool progress = false;  // print a line per solver iteration on stderr.

  bool Check(std::string* why) const;
};

struct ReconstructCostReport {
  int views = 0;                // fitted views.
  int64_t pixels = 0;           // level-0 pixels over the fitted views.
  int vertices = 0, faces = 0;  // of the starting mesh.
  int spp = 0, bounces = 0, threads = 0;
  std::string solver, phases;
  double create_seconds = 0.0;   // Reconstruction::Create: targets, masks, pyramids, the scene.
  double forward_seconds = 0.0;  // the baseline: one forward render of every fitted view.
  std::vector<PhaseRecord> phases_run;         // one per phase of the outer iteration.
  double cost_before = 0.0, cost_after = 0.0;  // objective at the first and last iteration.
  int accepted_steps = 0;
  int64_t rows_bytes = 0;      // the render cache's rows after the run.
  int64_t peak_rss_bytes = 0;  // process peak resident set (VmHWM); 0 when unknown.
};

// Runs outer iteration 0 from `mesh` and `material` on `dataset` and fills *report.
Status MeasureReconstructCost(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                              const ReconstructCostOptions& options, ReconstructCostReport* report);

// A plain-text table: per phase, seconds and share of each part, seconds per iteration and per
// iteration over the forward baseline.
std::string ReconstructCostTable(const ReconstructCostReport& report);
nlohmann::json ReconstructCostToJson(const ReconstructCostReport& report);

}  // namespace sft

#endif  // SFT_EVAL_RECONSTRUCT_COST_H_
