// What `sft reconstruct` writes into its output folder, each file atomically:
//   mesh.ply, mesh.obj          the current mesh (faces and their order as the initial mesh);
//   material.json, albedo.mc, roughness.mc   the material (mesh colors; `sft render` reads it);
//   lights.json                 the fitted light scales (src/io/light_scales.h);
//   metrics.csv, metrics.json   per iteration: outer, phase, iteration, cost, seconds, accepted,
//                               per-view PSNR; metrics.json adds per-phase solver statistics;
//   state.json                  what --resume needs: dataset, effective config, outer iterations
//                               done, elapsed seconds, the --init path as given;
//   initial_mesh.ply            the starting mesh, the baseline of the folded-face count (kept so
//                               a resumed run compares with the run's start, not its checkpoint).
// A checkpoint is written after every outer iteration and when the run is interrupted.
#ifndef SFT_OPTIM_RUN_OUTPUTS_H_
#define SFT_OPTIM_RUN_OUTPUTS_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/optim/reconstruct.h"

namespace sft {

// The resumable state of a run (state.json).
struct RunState {
  std::string dataset;    // the dataset folder, as given.
  std::string init;       // the --init mesh, as given (for the record; initial_mesh.ply is used).
  nlohmann::json config;  // ReconstructConfigJson of the effective options.
  int outer_done = 0;     // outer iterations completed.
  double seconds = 0.0;   // wall time of the run so far (all sessions).
  bool finished = false;  // every outer iteration done.
};

Status WriteRunState(const std::string& out, const RunState& state);
Status ReadRunState(const std::string& out, RunState* state);

// mesh.ply, mesh.obj, material.json (+ .mc files), lights.json.
Status WriteReconstructionState(const std::string& out, const Dataset& dataset,
                                const Reconstruction& reconstruction);

// metrics.csv and metrics.json. `records` are all iterations so far (resumed runs included),
// `extra` is merged into metrics.json's top level.
Status WriteMetrics(const std::string& out, const std::vector<IterationRecord>& records,
                    const std::vector<PhaseRecord>& phases, const nlohmann::json& extra);
// Reads the per-outer-iteration entries ("outer", an array; empty when absent) of metrics.json.
Status ReadOuterRecords(const std::string& out, nlohmann::json* records);
// Reads the iteration records of an earlier session back from metrics.json (for --resume).
Status ReadIterationRecords(const std::string& out, std::vector<IterationRecord>* records);

}  // namespace sft

#endif  // SFT_OPTIM_RUN_OUTPUTS_H_
