// What `sft reconstruct` writes into its output folder, each file atomically:
//   mesh.ply, mesh.obj          the current mesh (mesh.obj with the corner UVs after a uv stage);
//   material.json, material_albedo.meshcolors, material_roughness.meshcolors   the material (mesh
//   colors; `sft render` reads it) — after a uv stage instead material_albedo.png (sRGB) and
//   material_roughness.png with "uv_mesh": "mesh.obj" (SaveUvMaterial); lights.json the fitted
//   light scales (src/io/light_scales.h); metrics.csv, metrics.json   per iteration: outer, stage,
//   phase, iteration, cost, seconds,
//                               accepted, per-view PSNR; metrics.json adds per-phase solver
//                               statistics, per-outer records, topology changes and stages;
//   state.json                  what --resume needs (format sft-reconstruct-state/2): the run's
//                               info (dataset, start, config), the stages, where the run stands,
//                               the held-out views;
//   adam_state.bin              Adam's moments and step count in an Adam stage
//                               (src/optim/adam_checkpoint.h);
//   initial_mesh.ply            the run's starting mesh;
//   baseline_mesh.ply           the mesh after the last topology change: folded faces are
//                               counted against it;
//   stages/NN_NAME_normals.png  the normals of the first fitted view after each stage;
//   exposure.json               when a stage fits exposure: the gains per dataset view (format
//                               sft-exposure/1, WriteExposure);
//   poses.json                  when a stage fits poses: the corrected views' pose corrections
//                               and poses (format sft-poses/1, WritePoses).
// A checkpoint is written after every outer iteration and when the run is interrupted.
#ifndef SFT_OPTIM_RUN_OUTPUTS_H_
#define SFT_OPTIM_RUN_OUTPUTS_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/optim/reconstruct.h"
#include "src/optim/schedule.h"

namespace sft {

// The resumable state of a run (state.json).
constexpr char kRunStateFormat[] = "sft-reconstruct-state/2";
struct RunState {
  nlohmann::json run_info;  // dataset (as given), start, config (flat keys as given).
  nlohmann::json stages = nlohmann::json::array();  // StageJson of every stage.
  ScheduleProgress progress;
  bool finished = false;  // every stage done.
  // Exposure gains per dataset view ("exposure_gains"); empty when no stage fits them (all 1).
  std::vector<Eigen::Vector3d> view_gains;
  // --holdout K ("holdout"; 0 = off) and the views it kept out of the fit ("held_out_views",
  // ascending; src/optim/holdout.h). A resumed run keeps them.
  int holdout = 0;
  std::vector<int> held_out_views;

  std::string dataset() const { return run_info.value("dataset", ""); }
};

Status WriteRunState(const std::string& out, const RunState& state);
// Refuses other formats (older versions) with one line naming the file and the formats.
Status ReadRunState(const std::string& out, RunState* state);

// mesh.ply, mesh.obj, material.json (+ .mc files), lights.json.
// `light_positions`: the fitted point-light positions (empty: none fitted; lights.json then has
// no positions and ReadRunSnapshot returns them empty); `light_directions` the same for the
// fitted directional-light directions and `environment_rotations` the fitted probe rotations.
Status WriteRunSnapshot(const std::string& out, const Dataset& dataset, const TriMesh& mesh,
                        const Material& material, const std::vector<double>& light_scales,
                        const std::vector<Eigen::Vector3d>& light_positions = {},
                        const std::vector<Eigen::Vector3d>& light_directions = {},
                        const std::vector<Eigen::Vector3d>& environment_rotations = {});
Status ReadRunSnapshot(const std::string& out, const Dataset& dataset, TriMesh* mesh,
                       Material* material, std::vector<double>* light_scales,
                       std::vector<Eigen::Vector3d>* light_positions = nullptr,
                       std::vector<Eigen::Vector3d>* light_directions = nullptr,
                       std::vector<Eigen::Vector3d>* environment_rotations = nullptr);

// exposure.json: {"format": "sft-exposure/1", "gauge_view": G, "views": [{"view": i, "image":
// its image path in the dataset, "gains": [R, G, B]}, ...]} for every dataset view; gains
// multiply the rendered image to match the photograph, relative to the gauge view G (fixed; -1
// when unknown). Views that were not fitted keep 1.
Status WriteExposure(const std::string& out, const Dataset& dataset,
                     const std::vector<Eigen::Vector3d>& view_gains, int gauge_view);

// poses.json (src/optim/pose_corrections.h, PosesJson): the pose corrections per dataset view
// (zero: not corrected, not listed) relative to the dataset's cam_from_world, and the corrected
// poses; G the gauge view (-1 when unknown).
constexpr char kPosesFile[] = "poses.json";
Status WritePoses(const std::string& out, const Dataset& dataset,
                  const std::vector<PoseDelta>& view_poses, int gauge_view);
// Reads `path` (a poses.json) into one correction per dataset view; *found = false (and no
// corrections) when the file does not exist. Errors name the file and the field.
Status ReadPoses(const std::string& path, const Dataset& dataset,
                 std::vector<PoseDelta>* view_poses, bool* found);

// metrics.csv and metrics.json. `records` are all iterations so far (resumed runs included),
// `extra` is merged into metrics.json's top level.
Status WriteMetrics(const std::string& out, const std::vector<IterationRecord>& records,
                    const std::vector<PhaseRecord>& phases, const nlohmann::json& extra);
// metrics.json as a whole (an object).
Status ReadMetricsJson(const std::string& out, nlohmann::json* metrics);
// Reads the iteration records of an earlier session back from metrics.json (for --resume).
Status ReadIterationRecords(const std::string& out, std::vector<IterationRecord>* records);

}  // namespace sft

#endif  // SFT_OPTIM_RUN_OUTPUTS_H_
