// The schedule's configuration (docs/reconstruct.md): one JSON object of
//   - flat keys (every key of config.h's list and every stage key below except "name"): they
//     override the same key in every stage, as the command-line flags do;
//   - "schedule": a built-in stage list, "auto" (default: "hull" when the run starts from a
//     carved hull, "refine" otherwise), "refine" or "hull";
//   - "stages": an explicit stage list (an array of objects) instead of a built-in one;
//   - "holdout": K, every K-th selected view is kept out of the fit (src/optim/holdout.h);
//   - "environment_frame": "world" or "camera", where unknown lighting's fitted map is fixed.
//   - "environment_size": [W, H] and "environment_stage": unknown lighting's fitted map and the
//     automatic first stage that fits it alone (src/optim/fitted_environment.h);
//   - "estimate_lights": the path of a lights file whose point and directional lights unknown
//     lighting estimates beside the map (read when the config is merged; errors name that file);
//   - "find_lamp": true, with no lights given: the map is fitted alone first and a point lamp
//     starts in its brightest lobe's direction, "lamp_distance" half diagonals from the object
//     (src/optim/lamp_finder.h).
//   - "carve": {"resolution", "faces", "outlier_views", "support_contact", "stereo",
//     "stereo_pairs", "stereo_max_angle", "stereo_consistency_pixels", "stereo_scale"}: `sft
//     init`'s options for the hull carved when the run has no start mesh (src/init/initial_mesh.h).
// A stage object holds any flat key plus "name", and the stage-only keys "texel_resolution",
// "remesh", "remesh_edge_pixels", "resample", "resample_fold_fraction", "material_model" and
// "texture_size" (the effect planner's keys, "effects": "auto" and "pin", are flat keys: config.h).
// A stage's options are: defaults < the stage's keys < the flat keys. Errors name the file, the
// stage and the key ("cfg.json: stages[1].remesh: expected none, adaptive or isotropic").
#ifndef SFT_OPTIM_SCHEDULE_CONFIG_H_
#define SFT_OPTIM_SCHEDULE_CONFIG_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/init/initial_mesh.h"
#include "src/optim/fitted_environment.h"
#include "src/optim/schedule.h"

namespace sft {

struct ScheduleConfig {
  std::string schedule = "auto";                   // auto | refine | large_steps | hull.
  nlohmann::json stages;                           // explicit list; null = the built-in one.
  nlohmann::json flat = nlohmann::json::object();  // keys that override every stage.
  int holdout = 0;             // "holdout": every K-th selected view held out; 0 = off, K >= 2.
  bool holdout_given = false;  // "holdout" was given (a resumed run must not change it).
  // Unknown lighting: the fitted map's size ("environment_size": [W, H]), the frame it is fixed
  // in ("environment_frame": "world" or "camera") and the lights estimated beside it
  // ("estimate_lights": the path of a lights file; or "find_lamp" and "lamp_distance";
  // src/optim/fitted_environment.h).
  EnvironmentEstimateOptions environment;
  bool environment_frame_given = false;  // "environment_frame" given (a resume must not change it).
  // "environment_stage": false = no automatic environment stage; an object = stage keys over
  // the built-in stage's (EnvironmentStage).
  bool environment_stage = true;
  nlohmann::json environment_stage_keys = nlohmann::json::object();
  // environment_size, environment_stage, estimate_lights, find_lamp or lamp_distance was given
  // (a resumed run keeps its map, its lights and its stages).
  bool environment_given = false;
  // "carve": the options of the hull carved when there is no start mesh (the dataset's
  // support_plane is added where it is carved).
  InitialMeshOptions carve;
  nlohmann::json carve_keys = nlohmann::json::object();  // as given, for the run's records.
};

// Adds `config`'s keys to *out (later calls override earlier ones key by key; "stages" and
// "schedule" replace). Checks every key and value; `source` names the file in errors.
Status MergeScheduleConfig(const nlohmann::json& config, const std::string& source,
                           ScheduleConfig* out);
Status ReadScheduleConfig(const std::string& path, ScheduleConfig* out);

// The stage list: the explicit or built-in stages, each with the flat keys applied, checked.
// "auto" picks `hull` for a carved start; from a given mesh, `large_steps`, or the one-stage
// `refine` when a flat key describes one stage's loop (phases, solver, outer_iterations, steps).
Status ResolveStages(const ScheduleConfig& config, bool carved_start,
                     std::vector<StageOptions>* stages);

// The automatic first stage of a run whose lighting is unknown (docs/reconstruct.md, "Unknown
// lighting"): "environment", a texture stage that fits the environment map alone with the
// material held as it starts (LM), at the image scale and pyramid levels of `first`, the list's
// first stage. Its keys: the built-in ones and first's scale < the flat keys < its role
// (phases texture, fit_albedo/fit_roughness/fit_specular false, fit_environment true; with
// estimated lights also fit_lights and fit_light_positions or fit_light_directions) <
// config.environment_stage_keys; find_lamp sets fit_lights and fit_light_positions too.
Status EnvironmentStage(const ScheduleConfig& config, const StageOptions& first,
                        StageOptions* stage);

// Applies stage keys (a stage object or flat keys) to one stage.
Status ApplyStageConfig(const nlohmann::json& keys, const std::string& source, StageOptions* stage);

// Every key of a stage with its value (ApplyStageConfig of it reproduces the stage).
nlohmann::json StageJson(const StageOptions& stage);
// Stages from StageJson objects (state.json's "stages").
Status StagesFromJson(const nlohmann::json& list, const std::string& source,
                      std::vector<StageOptions>* stages);

// The effective stage list as a table (`sft reconstruct --print-schedule`), with the views each
// stage fits; `dataset_views` (0 = unknown) is the dataset's view count.
std::string FormatSchedule(const std::vector<StageOptions>& stages, int dataset_views = 0);

// A stage's views for that table: "all N" (empty list), the count and the indices when there are
// at most 16, else the count and the views left out when those are at most 16 ("all but 0,8"),
// else the list's first and last three.
std::string DescribeStageViews(const std::vector<int>& views, int dataset_views);

}  // namespace sft

#endif  // SFT_OPTIM_SCHEDULE_CONFIG_H_
