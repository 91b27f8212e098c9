// The reconstruction schedule: an ordered list of stages, each a run of outer iterations of one
// fit (phases, image scale, spp, pyramid, solver, effects: ReconstructOptions) on one topology.
// Before a stage starts, its topology change (remeshing, resampling) and its texel resolution
// are applied; the mesh-colour texels carry across by re-projection onto the new surface. Within
// a stage, an outer iteration that leaves too many folded or self-intersecting faces triggers a
// resampling. After every outer iteration the run folder receives a checkpoint (state.json,
// mesh, material, metrics, Adam's moments) that `Resume` continues from, also across topology
// changes.
//
// Modelled on a pipeline controller: the CLI configures the stages (schedule_config.h), calls
// Run with callbacks for progress, console lines and extra per-outer scores, and reports. The
// stage list, its keys and the built-in schedules are documented in docs/reconstruct.md.
#ifndef SFT_OPTIM_SCHEDULE_H_
#define SFT_OPTIM_SCHEDULE_H_

#include <algorithm>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/adam_checkpoint.h"
#include "src/optim/reconstruct.h"
#include "src/optim/topology.h"

namespace sft {

// One stage of the schedule.
struct StageOptions {
  std::string name = "refine";  // shown on the progress line, in metrics.json and the report.
  ReconstructOptions fit;       // phases, outer iterations, steps, spp, image scale, solver...
  // Mesh-colours resolution of albedo and roughness during the stage, [1, 64]; 0 = keep the
  // current one; kTexelResolutionAuto (-1, "auto" in the config) = texels about one pixel apart
  // at the stage's scale (ResolveTexelResolution). Texels are resampled (same mesh) or
  // re-projected (after a topology change).
  int texel_resolution = 0;
  // At the stage's start, every roughness texel is set to this value, (0, 1]; 0 = keep. For a
  // last texture stage whose earlier stages drove the roughness to its floor (docs/reconstruct.md,
  // "Glossy objects").
  double restart_roughness = 0.0;
  // At the stage's start, the specular weight is set to this value, (0, 1]; 0 = keep.
  double restart_specular = 0.0;
  TopologyOptions topology;  // remeshing / resampling before the stage, and on folds.
  // How albedo and roughness are represented while the stage fits them: "mesh_colors" (per-face
  // texel grids) or "uv" (bilinear UV textures: at the stage's start, and after a topology change
  // within it, the current mesh is charted into a UV atlas and the mesh colors are baked into it;
  // the texels are then the parameters; src/optim/uv_stage.h). A mesh-colors stage after a uv
  // stage samples the textures back into mesh colors (texel_resolution, or "auto" when 0).
  std::string material_model = "mesh_colors";
  // Side of a uv stage's textures in texels, [64, 16384]; 0 = from the images' pixel footprint
  // (as sft export chooses it: src/atlas/texture_size.h). Ignored by mesh_colors stages.
  int texture_size = 0;

  bool Check(std::string* why) const;
};

// Where a run stands; state.json records it (format sft-reconstruct-state/2).
struct ScheduleProgress {
  int stage = 0;                // index of the current stage (== stages.size() when finished).
  int stage_outer_done = 0;     // outer iterations completed within the current stage.
  bool stage_prepared = false;  // the current stage's topology/texel change has been applied.
  int outer_done = 0;           // outer iterations completed over all stages (seeds, records).
  int topology_changes = 0;     // remeshings and resamplings so far.
  std::vector<int> stage_outers_done;  // outer iterations completed per stage (index = stage).
  double seconds = 0.0;                // wall time of the run so far, all sessions.
};

// The state a schedule starts from (or a checkpoint holds).
struct ScheduleStart {
  TriMesh mesh;
  Material material;
  std::vector<double> light_scales;  // empty = all 1.
  // Fitted point-light positions per dataset light, in each light's frame (lights.json); empty =
  // the dataset's (none fitted yet).
  std::vector<Eigen::Vector3d> light_positions;
  // Fitted directional-light directions per dataset light, in each light's frame (lights.json);
  // empty = the dataset's (none fitted yet).
  std::vector<Eigen::Vector3d> light_directions;
  // Fitted probe rotations per dataset light (rotation vectors, radians, in each environment's
  // frame; lights.json); empty = the dataset's alignment (none fitted yet).
  std::vector<Eigen::Vector3d> environment_rotations;
  // Exposure gains per dataset view (src/optim/parameters.h); empty = all 1.
  std::vector<Eigen::Vector3d> view_gains;
  // Pose corrections per dataset view (src/optim/pose_corrections.h); empty = all zero.
  std::vector<PoseDelta> view_poses;
  // The fitted environment's texels (unknown lighting, src/optim/fitted_environment.h); empty =
  // the dataset's fitted light's own (or no fitted environment).
  Image environment;
};

struct ScheduleCallbacks {
  // After every solver iteration; false stops the run after writing a checkpoint.
  std::function<bool(const IterationRecord&)> on_iteration;
  // One console line per stage start, topology change and stop.
  std::function<void(const std::string&)> on_event;
  // Extra per-outer metrics for the current mesh (e.g. F1 and Chamfer against a reference);
  // merged into metrics.json's "outer" entries.
  std::function<Status(const TriMesh&, nlohmann::json*)> score;
};

class Schedule {
 public:
  // A fresh run in `out` (an existing, empty or new folder checked by the caller). `run_info` is
  // stored in state.json and merged into metrics.json (dataset path, start, flat config keys).
  static Status Start(const Dataset& dataset, const std::string& out,
                      const std::vector<StageOptions>& stages, const ScheduleStart& start,
                      const nlohmann::json& run_info, std::unique_ptr<Schedule>* schedule);
  // Continues the run in `out` from its checkpoint. `stages` are the run's stages (as state.json
  // records them, with any overrides applied; their count must match); `view_gains` the
  // checkpoint's exposure gains (RunState::view_gains; empty = all 1).
  static Status Resume(const Dataset& dataset, const std::string& out,
                       const std::vector<StageOptions>& stages, const nlohmann::json& run_info,
                       const ScheduleProgress& progress,
                       const std::vector<Eigen::Vector3d>& view_gains,
                       std::unique_ptr<Schedule>* schedule);

  // Runs the remaining stages; writes a checkpoint after every outer iteration and when stopped.
  Status Run(const ScheduleCallbacks& callbacks);

  // Called at every checkpoint; its object is merged into metrics.json's top level (e.g. the MPI
  // time split of `mpirun` runs).
  void SetExtraMetrics(std::function<nlohmann::json()> extra) { extra_metrics_ = std::move(extra); }
  // The run's --holdout K and the views it keeps out of the fit (src/optim/holdout.h; the stages'
  // views already exclude them): recorded in state.json and metrics.json at every checkpoint.
  void SetHeldOut(int holdout, std::vector<int> views) {
    holdout_ = holdout;
    held_out_views_ = std::move(views);
  }
  const std::vector<int>& held_out_views() const { return held_out_views_; }

  bool finished() const { return progress_.stage >= static_cast<int>(stages_.size()); }
  bool stopped() const { return stopped_; }
  const ScheduleProgress& progress() const { return progress_; }
  // The stage running (the last one once finished).
  const StageOptions& CurrentStage() const {
    return stages_[std::min<size_t>(progress_.stage, stages_.size() - 1)];
  }
  const std::vector<IterationRecord>& records() const { return records_; }
  const nlohmann::json& outer_records() const { return outer_records_; }
  const nlohmann::json& stage_records() const { return stage_records_; }
  // The reconstruction of the stage run last (the final state once finished); null before Run.
  Reconstruction* reconstruction() { return reconstruction_.get(); }

  // Total solver steps of the remaining work, each weighted by its relative cost (image pixels ×
  // spp, and the share of the views an Adam minibatch renders), for a progress line whose ETA
  // holds across stages of different scales.
  int64_t RemainingWork() const;
  // One step's work; `dataset_views` (0 = unknown: no minibatch share) counts the dataset's views.
  static int64_t StepWork(const StageOptions& stage, int dataset_views = 0);
  // StepWork of the current stage for this run's dataset.
  int64_t CurrentStepWork() const;
  // RemainingWork split by the kind of step (WorkKindOf), kNumWorkKinds entries: LM and Adam
  // steps, texture and geometry phases cost differently per unit of StepWork (a Progress prices
  // each kind at its own measured rate).
  static constexpr int kNumWorkKinds = 4;
  std::vector<int64_t> RemainingWorkByKind() const;
  // The kind of a step of `stage`'s phase `phase` ("texture" | "geometry"): Ceres' solvers (LM,
  // dogleg, L-BFGS: 0 texture, 1 geometry) or Adam (2, 3).
  static int WorkKindOf(const StageOptions& stage, const std::string& phase);
  // The work of a whole run of `stages` in the same units (RemainingWork of a fresh run), and
  // split by kind (RemainingWorkByKind of a fresh run).
  static int64_t TotalWork(const std::vector<StageOptions>& stages, int dataset_views = 0);
  static std::vector<int64_t> TotalWorkByKind(const std::vector<StageOptions>& stages,
                                              int dataset_views = 0);

 private:
  Schedule() = default;
  Status PrepareStage(const ScheduleCallbacks& callbacks);
  void RestartLobe(const StageOptions& stage, const ScheduleCallbacks& callbacks);
  Status CreateReconstruction();
  void RestoreAdamState(const ScheduleCallbacks& callbacks);
  Status RunStageOuter(const ScheduleCallbacks& callbacks, bool* stop);
  Status UntangleCurrent(const ScheduleCallbacks& callbacks, nlohmann::json* record);
  Status ChangeTopology(TopologyChange change, const ScheduleCallbacks& callbacks);
  Status SwitchMaterialModel(const ScheduleCallbacks& callbacks);
  Status PlanEffects(const ScheduleCallbacks& callbacks, nlohmann::json* record);
  Status OuterRecord(const ScheduleCallbacks& callbacks, int outer, nlohmann::json* out);
  Status FinishStage();
  Status Checkpoint();
  void SyncCurrent();
  double Elapsed() const;  // seconds of the run so far, all sessions.
  int WorkViews() const;   // the dataset's view count for StepWork (work_views_ without one).

  const Dataset* dataset_ = nullptr;
  int work_views_ = 0;  // TotalWork's view count (no dataset).
  std::string out_;
  std::vector<StageOptions> stages_;
  nlohmann::json run_info_;
  ScheduleProgress progress_;
  ScheduleStart current_;  // the state at the last sync (mesh, material, light scales, gains).
  TriMesh baseline_;       // folded faces are counted against it (reset at topology changes).
  std::unique_ptr<Reconstruction> reconstruction_;
  int reconstruction_stage_ = 0;  // the stage reconstruction_ was created for.
  // Adam's moments read by Resume (adam_state.bin), applied to the resumed stage's fit.
  std::unique_ptr<AdamCheckpoint> saved_adam_;
  std::vector<IterationRecord> records_;
  std::vector<PhaseRecord> phase_records_;
  nlohmann::json outer_records_ = nlohmann::json::array();
  nlohmann::json topology_records_ = nlohmann::json::array();
  // Switches between mesh colors and UV textures (metrics.json "material_switches").
  nlohmann::json material_records_ = nlohmann::json::array();
  nlohmann::json stage_records_ = nlohmann::json::array();
  // The effect planner's last report in this session (console lines name only changes).
  std::unique_ptr<EffectPlanReport> last_plan_;
  // The largest signals the planner measured in this stage since its last topology change.
  double image_signal_scale_ = 0.0;
  double step_signal_scale_ = 0.0;
  size_t phases_seen_ = 0;      // phase records of reconstruction_ already collected.
  double session_start_ = 0.0;  // steady-clock seconds when this session's Run began.
  double seconds_at_start_ = 0.0;
  bool stopped_ = false;
  std::function<nlohmann::json()> extra_metrics_;
  int holdout_ = 0;                  // --holdout K (0 = off).
  std::vector<int> held_out_views_;  // views no stage fits.
};

}  // namespace sft

#endif  // SFT_OPTIM_SCHEDULE_H_
