#include "src/optim/schedule_config.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <map>

#include "src/core/file_util.h"
#include "src/io/lights_file.h"
#include "src/optim/config.h"
#include "src/optim/holdout.h"

namespace sft {
namespace {

using json = nlohmann::json;

// The built-in stage lists (docs/reconstruct.md, "Built-in schedules").
// refine: from a given mesh, one stage of the fit's defaults.
const char kRefineSchedule[] = R"([{"name": "refine"}])";
// large_steps: from a given mesh, material and geometry stages alternating, half scale first.
// Material: one LM stage (albedo, roughness, specular weight), then Adam on independent gradient
// paths (16 views per step), whose first stage restarts the lobe (roughness 0.5, specular 0.2)
// that LM leaves near its floor. Geometry: Adam on the large-steps parameterisation (a new seed
// and 8 views per step, one pyramid level, 64 spp), the specular lobe in the rendered residual
// but out of the adjoint pass, silhouette edges on, at a step size that halves. Measured on the
// glossy dragon over 3 seeds (docs/design-notes.md, "Large steps for Adam", "The warp's floor is
// the material's", "The warp's material stages on Adam").
const char kLargeStepsSchedule[] = R"([
  {"name": "material", "phases": "texture", "image_scale": 0.5, "pyramid_levels": 3,
   "outer_iterations": 1, "steps": 5},
  {"name": "material_adam", "phases": "texture", "solver": "adam", "image_scale": 0.5,
   "pyramid_levels": 3, "outer_iterations": 1, "steps": 60, "independent_gradient": true,
   "adam_views_per_step": 16, "restart_roughness": 0.5, "restart_specular": 0.2},
  {"name": "shape_half", "phases": "geometry", "solver": "adam", "image_scale": 0.5,
   "pyramid_levels": 1, "outer_iterations": 2, "steps": 25, "adam_lr_vertices": 0.002},
  {"name": "material_half", "phases": "texture", "solver": "adam", "image_scale": 0.5,
   "pyramid_levels": 3, "outer_iterations": 1, "steps": 40, "independent_gradient": true,
   "adam_views_per_step": 16},
  {"name": "shape_full", "phases": "geometry", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 1, "outer_iterations": 2, "steps": 25, "adam_lr_vertices": 0.001},
  {"name": "material_full", "phases": "texture", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 3, "outer_iterations": 1, "steps": 40, "independent_gradient": true,
   "adam_views_per_step": 16},
  {"name": "shape_full2", "phases": "geometry", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 1, "outer_iterations": 2, "steps": 25, "adam_lr_vertices": 0.0005},
  {"name": "material_full2", "phases": "texture", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 3, "outer_iterations": 1, "steps": 40, "independent_gradient": true,
   "adam_views_per_step": 16},
  {"name": "shape_full3", "phases": "geometry", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 1, "outer_iterations": 2, "steps": 25, "adam_lr_vertices": 0.00025},
  {"name": "material_final", "phases": "texture", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 3, "outer_iterations": 1, "steps": 120, "independent_gradient": true,
   "adam_views_per_step": 16, "restart_roughness": 0.5, "restart_specular": 0.2}
])";
// Keys of every large_steps and hull stage.
const char kLargeStepsStageKeys[] = R"({"image_loss": "relative", "fit_specular": true,
  "adam_large_steps": 25, "adam_uniform": true, "adam_resample": true, "adam_views_per_step": 8})";
// Keys of the large_steps geometry stages: the lobe rendered (pinned on) but left out of the step.
const char kLargeStepsGeometryKeys[] = R"({"pin": {"specular": true, "primary_edges": true},
  "gradient_specular": false, "spp": 64})";
// Keys of the hull geometry stages: the lobe pinned off in both passes.
const char kHullGeometryKeys[] = R"({"pin": {"specular": false, "primary_edges": true}})";
// hull: from a carved hull, the report's shape: material (LM) and geometry (Adam, large steps,
// the lobe pinned off) alternating at a growing image scale (1/4, 1/2, 1), adaptive remeshing
// before the half and full scales, resampling before the full scale, and the closing material
// stage of large_steps. Measured on the glossy dragon (docs/design-notes.md, "The hull list on
// Adam").
const char kHullSchedule[] = R"([
  {"name": "material_quarter", "phases": "texture", "image_scale": 0.25, "pyramid_levels": 2,
   "outer_iterations": 1, "steps": 5},
  {"name": "shape_quarter", "phases": "geometry", "solver": "adam", "image_scale": 0.25,
   "pyramid_levels": 2, "outer_iterations": 2, "steps": 25, "adam_lr_vertices": 0.004},
  {"name": "material_half", "phases": "texture", "image_scale": 0.5, "pyramid_levels": 3,
   "outer_iterations": 1, "steps": 5, "remesh": "adaptive"},
  {"name": "shape_half", "phases": "geometry", "solver": "adam", "image_scale": 0.5,
   "pyramid_levels": 3, "outer_iterations": 3, "steps": 25, "adam_lr_vertices": 0.002},
  {"name": "material_full", "phases": "texture", "image_scale": 1, "pyramid_levels": 3,
   "outer_iterations": 1, "steps": 5, "remesh": "adaptive", "resample": true},
  {"name": "shape_full", "phases": "geometry", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 3, "outer_iterations": 3, "steps": 25, "adam_lr_vertices": 0.001},
  {"name": "material_full2", "phases": "texture", "image_scale": 1, "pyramid_levels": 3,
   "outer_iterations": 1, "steps": 5},
  {"name": "shape_full2", "phases": "geometry", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 3, "outer_iterations": 2, "steps": 25, "adam_lr_vertices": 0.0005},
  {"name": "material_final", "phases": "texture", "solver": "adam", "image_scale": 1,
   "pyramid_levels": 3, "outer_iterations": 1, "steps": 120, "independent_gradient": true,
   "adam_views_per_step": 16, "restart_roughness": 0.5, "restart_specular": 0.2}
])";

// environment: the automatic first stage under unknown lighting. The map alone, from a uniform
// albedo: with the albedo free, the map and the albedo trade shading between them; a light
// smoothness prior lets the map hold the probe's bright lights (docs/design-notes.md,
// "Separating the fitted environment from the albedo").
const char kEnvironmentStage[] = R"({"name": "environment", "solver": "lm",
  "outer_iterations": 2, "steps": 8, "environment_smoothness": 0.1})";
// What makes it the environment stage; flat keys (e.g. --phases) do not change these.
const char kEnvironmentStageRole[] = R"({"phases": "texture", "fit_albedo": false,
  "fit_roughness": false, "fit_specular": false, "fit_environment": true})";

// The flat keys that describe one stage's phases and solver loop: given any of them, `auto`
// with a given mesh picks the one-stage `refine` list rather than a list whose stages set them.
bool FlatKeysDescribeOneStage(const json& flat) {
  for (const char* key : {"phases", "solver", "outer_iterations", "steps"}) {
    if (flat.contains(key)) return true;
  }
  return false;
}

// Stage-only keys: how to apply a value ("" or what is wrong) and read it back.
struct StageKey {
  std::function<std::string(const json&, StageOptions*)> set;
  std::function<json(const StageOptions&)> get;
};

StageKey OneOf(std::function<std::string&(StageOptions*)> field, std::vector<std::string> allowed,
               std::string later) {
  return {[field, allowed, later](const json& v, StageOptions* s) -> std::string {
            std::string list;
            for (size_t k = 0; k < allowed.size(); ++k) {
              if (v.is_string() && v.get<std::string>() == allowed[k]) {
                field(s) = allowed[k];
                return "";
              }
              list += (k == 0 ? "" : k + 1 == allowed.size() ? " or " : ", ") + allowed[k];
            }
            return "expected " + list + later;
          },
          [field](const StageOptions& s) { return json(field(const_cast<StageOptions*>(&s))); }};
}

StageKey RealIn(std::function<double&(StageOptions*)> field, double lo, double hi, bool open_lo) {
  return {[=](const json& v, StageOptions* s) -> std::string {
            const bool ok = v.is_number() && std::isfinite(v.get<double>()) &&
                            (open_lo ? v.get<double>() > lo : v.get<double>() >= lo) &&
                            v.get<double>() <= hi;
            if (!ok) {
              return std::string("expected a number in ") + (open_lo ? "(" : "[") +
                     json(lo).dump() + ", " + json(hi).dump() + "]";
            }
            field(s) = v.get<double>();
            return "";
          },
          [field](const StageOptions& s) { return json(field(const_cast<StageOptions*>(&s))); }};
}

StageKey Flag(std::function<bool&(StageOptions*)> field) {
  return {[field](const json& v, StageOptions* s) -> std::string {
            if (!v.is_boolean()) return "expected true or false";
            field(s) = v.get<bool>();
            return "";
          },
          [field](const StageOptions& s) { return json(field(const_cast<StageOptions*>(&s))); }};
}

const std::map<std::string, StageKey>& StageKeys() {
  using S = StageOptions;
  static const std::map<std::string, StageKey> keys = {
      {"texel_resolution",
       {[](const json& v, S* s) -> std::string {
          if (v.is_string() && v.get<std::string>() == "auto") {
            s->texel_resolution = kTexelResolutionAuto;
            return "";
          }
          if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() > 64) {
            return "expected \"auto\" or an integer in [0, 64] (0 = keep)";
          }
          s->texel_resolution = v.get<int>();
          return "";
        },
        [](const S& s) {
          return s.texel_resolution == kTexelResolutionAuto ? json("auto")
                                                            : json(s.texel_resolution);
        }}},
      {"restart_roughness",
       RealIn([](S* s) -> double& { return s->restart_roughness; }, 0, 1, false)},
      {"restart_specular",
       RealIn([](S* s) -> double& { return s->restart_specular; }, 0, 1, false)},
      {"remesh", OneOf([](S* s) -> std::string& { return s->topology.remesh; },
                       {"none", "adaptive", "isotropic"}, "")},
      {"remesh_edge_pixels",
       RealIn([](S* s) -> double& { return s->topology.remesh_edge_pixels; }, 0, 64, true)},
      {"resample", Flag([](S* s) -> bool& { return s->topology.resample; })},
      {"untangle", Flag([](S* s) -> bool& { return s->topology.untangle; })},
      {"resample_fold_fraction",
       RealIn([](S* s) -> double& { return s->topology.resample_fold_fraction; }, 0, 1, false)},
      {"max_faces",
       {[](const json& v, S* s) -> std::string {
          if (!v.is_number_integer() || v.get<int64_t>() < 100 || v.get<int64_t>() > 5000000) {
            return "expected an integer in [100, 5000000]";
          }
          s->topology.max_faces = v.get<int>();
          return "";
        },
        [](const S& s) { return json(s.topology.max_faces); }}},
      {"material_model",
       OneOf([](S* s) -> std::string& { return s->material_model; }, {"mesh_colors", "uv"}, "")},
      {"texture_size",
       {[](const json& v, S* s) -> std::string {
          if (!v.is_number_integer() || v.get<int64_t>() < 0 || v.get<int64_t>() > 16384 ||
              (v.get<int64_t>() > 0 && v.get<int64_t>() < 64)) {
            return "expected 0 (from the pixel footprint) or an integer in [64, 16384]";
          }
          s->texture_size = v.get<int>();
          return "";
        },
        [](const S& s) { return json(s.texture_size); }}},
  };
  return keys;
}

Status ParseJsonFile(const std::string& path, json* out) {
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  *out = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (out->is_discarded()) return Status::Error(path + ": not valid JSON");
  return Status::Ok();
}

}  // namespace

Status ApplyStageConfig(const json& keys, const std::string& source, StageOptions* stage) {
  if (!keys.is_object()) return Status::Error(source + ": expected a JSON object");
  for (const auto& [name, value] : keys.items()) {
    if (name == "name") {
      if (!value.is_string() || value.get<std::string>().empty()) {
        return Status::Error(source + ": name: expected a non-empty string");
      }
      stage->name = value.get<std::string>();
      continue;
    }
    // state.json of runs before the effect planner: its "effects" list already says "fixed".
    if (name == "effect_plan" && value == "fixed") continue;
    const auto it = StageKeys().find(name);
    if (it != StageKeys().end()) {
      const std::string why = it->second.set(value, stage);
      if (!why.empty()) return Status::Error(source + ": " + name + ": " + why);
      continue;
    }
    SFT_RETURN_IF_ERROR(ApplyReconstructConfig({{name, value}}, source, &stage->fit));
  }
  return Status::Ok();
}

// The keys of "carve" (docs/reconstruct.md), for the error messages.
constexpr const char* kCarveKeys[] = {
    "resolution",       "faces",        "outlier_views",
    "support_contact",  "stereo",       "stereo_pairs",
    "stereo_max_angle", "stereo_scale", "stereo_consistency_pixels"};

// "carve": an object of `sft init`'s options (InitialMeshOptions), checked here.
Status MergeCarveKeys(const json& value, const std::string& source, ScheduleConfig* out) {
  const std::string where = source + ": carve";
  if (!value.is_object()) return Status::Error(where + ": expected an object");
  InitialMeshOptions carve = out->carve;
  for (const auto& [key, v] : value.items()) {
    const bool integer = v.is_number_integer() && std::abs(v.get<int64_t>()) < (int64_t{1} << 31);
    if (key == "resolution" && integer) {
      carve.hull.resolution = v.get<int>();
    } else if (key == "faces" && integer) {
      carve.faces = v.get<int>();
    } else if (key == "outlier_views" && integer) {
      carve.hull.outlier_views = v.get<int>();
    } else if (key == "support_contact" && v.is_number()) {
      carve.hull.support_contact = v.get<double>();
    } else if (key == "stereo" && v.is_boolean()) {
      carve.stereo = v.get<bool>();
    } else if (key == "stereo_max_angle" && v.is_number()) {
      carve.stereo_options.max_angle_deg = v.get<double>();
    } else if (key == "stereo_consistency_pixels" && v.is_number()) {
      carve.stereo_options.consistency_pixels = v.get<double>();
    } else if (key == "stereo_scale" && integer) {
      carve.stereo_options.image_scale_log2 = v.get<int>();
    } else if (key == "stereo_pairs" && integer) {
      carve.stereo_options.pairs_per_view = v.get<int>();
    } else if (key == "stereo") {
      return Status::Error(where + ".stereo: expected true or false");
    } else if (std::find(std::begin(kCarveKeys), std::end(kCarveKeys), key) !=
               std::end(kCarveKeys)) {
      return Status::Error(where + "." + key + ": expected a number");
    } else {
      std::string known;
      for (const char* name : kCarveKeys) known += (known.empty() ? "" : ", ") + std::string(name);
      return Status::Error(where + "." + key + ": unknown key (expected one of " + known + ")");
    }
  }
  std::string why;
  if (!carve.Check(&why)) return Status::Error(where + "." + why);
  out->carve = carve;
  out->carve_keys.update(value);
  return Status::Ok();
}

Status MergeScheduleConfig(const json& config, const std::string& source, ScheduleConfig* out) {
  if (!config.is_object()) return Status::Error(source + ": expected a JSON object");
  for (const auto& [name, value] : config.items()) {
    if (name == "schedule") {
      if (!value.is_string() ||
          (value != "auto" && value != "refine" && value != "hull" && value != "large_steps")) {
        return Status::Error(source + ": schedule: expected auto, refine, large_steps or hull");
      }
      out->schedule = value.get<std::string>();
    } else if (name == "stages") {
      if (!value.is_array() || value.empty()) {
        return Status::Error(source + ": stages: expected a non-empty array of stage objects");
      }
      for (size_t k = 0; k < value.size(); ++k) {
        StageOptions probe;  // checks keys and values now, so errors name the file.
        const std::string where = source + ": stages[" + std::to_string(k) + "]";
        SFT_RETURN_IF_ERROR(ApplyStageConfig(value[k], where, &probe));
      }
      out->stages = value;
    } else if (name == "holdout") {
      if (!value.is_number_integer() || value.get<int64_t>() < 0 ||
          value.get<int64_t>() > 1000000 || !ValidHoldout(static_cast<int>(value.get<int64_t>()))) {
        return Status::Error(source + ": holdout: expected 0 (off) or an integer in [2, 1000000]");
      }
      out->holdout = value.get<int>();
      out->holdout_given = true;
    } else if (name == "environment_frame") {
      if (!value.is_string() ||
          !LightFrameFromName(value.get<std::string>(), &out->environment.frame)) {
        return Status::Error(source + ": environment_frame: expected \"world\" or \"camera\"");
      }
      out->environment_frame_given = true;
    } else if (name == "environment_size") {
      EnvironmentEstimateOptions size = out->environment;
      if (value.is_array() && value.size() == 2 && value[0].is_number_integer() &&
          value[1].is_number_integer()) {
        size.width = static_cast<int>(std::clamp<int64_t>(value[0].get<int64_t>(), -1, 1 << 20));
        size.height = static_cast<int>(std::clamp<int64_t>(value[1].get<int64_t>(), -1, 1 << 20));
      } else {
        size.width = 0;  // fails the check below.
      }
      std::string why;
      if (!size.Check(&why)) {
        return Status::Error(source +
                             ": environment_size: expected [width, height], width in [2, 512] and "
                             "height in [1, 256]");
      }
      out->environment = size;
      out->environment_given = true;
    } else if (name == "estimate_lights") {
      if (!value.is_string() || value.get<std::string>().empty()) {
        return Status::Error(source + ": estimate_lights: expected the path of a lights file " +
                             "({\"lights\": [...]} in scene.json's light format)");
      }
      const std::string file = value.get<std::string>();
      EnvironmentEstimateOptions estimate = out->environment;
      if (estimate.find_lamp) {
        return Status::Error(source + ": estimate_lights: find_lamp is on (it looks for a lamp " +
                             "when none is given); give one or the other");
      }
      SFT_RETURN_IF_ERROR(
          ReadLightsFile(file, &estimate.lights).Prefixed(source + ": estimate_lights"));
      std::string why;
      if (!estimate.Check(&why)) {  // why: "estimate_lights: lights[k] ...: ...".
        return Status::Error(source + ": estimate_lights: " + file + ": " +
                             why.substr(why.find(": ") + 2));
      }
      out->environment = estimate;
      out->environment_given = true;
    } else if (name == "find_lamp" || name == "lamp_distance") {
      EnvironmentEstimateOptions estimate = out->environment;
      if (name == "find_lamp" && value.is_boolean()) {
        estimate.find_lamp = value.get<bool>();
      } else if (name == "lamp_distance" && value.is_number()) {
        estimate.lamp_distance = value.get<double>();
      } else {
        return Status::Error(source + ": " + name +
                             (name == "find_lamp" ? ": expected true or false"
                                                  : ": expected a number in [0.5, 1000]"));
      }
      std::string why;
      if (!estimate.Check(&why)) return Status::Error(source + ": " + why);
      out->environment = estimate;
      out->environment_given = true;
    } else if (name == "carve") {
      SFT_RETURN_IF_ERROR(MergeCarveKeys(value, source, out));
    } else if (name == "environment_stage") {
      if (value.is_boolean()) {
        out->environment_stage = value.get<bool>();
      } else if (value.is_object()) {
        StageOptions probe;
        SFT_RETURN_IF_ERROR(ApplyStageConfig(value, source + ": environment_stage", &probe));
        out->environment_stage = true;
        out->environment_stage_keys.update(value);
      } else {
        return Status::Error(source + ": environment_stage: expected true, false or an object " +
                             "of stage keys");
      }
      out->environment_given = true;
    } else if (name == "name") {
      return Status::Error(source + ": name: a stage key (put it inside \"stages\")");
    } else {
      StageOptions probe;
      SFT_RETURN_IF_ERROR(ApplyStageConfig({{name, value}}, source, &probe));
      out->flat[name] = value;
    }
  }
  return Status::Ok();
}

Status ReadScheduleConfig(const std::string& path, ScheduleConfig* out) {
  json config;
  SFT_RETURN_IF_ERROR(ParseJsonFile(path, &config));
  return MergeScheduleConfig(config, path, out);
}

Status EnvironmentStage(const ScheduleConfig& config, const StageOptions& first,
                        StageOptions* stage) {
  *stage = StageOptions();
  const std::string where = "environment stage";
  SFT_RETURN_IF_ERROR(ApplyStageConfig(json::parse(kEnvironmentStage), where, stage));
  // The scale and pyramid the list starts at: a map of 32×16 texels needs no finer images, and a
  // full-scale stage before a coarse-to-fine list would cost more than the list's first stages.
  stage->fit.cache.image_scale_log2 = first.fit.cache.image_scale_log2;
  stage->fit.cache.pyramid_levels = first.fit.cache.pyramid_levels;
  SFT_RETURN_IF_ERROR(ApplyStageConfig(config.flat, "flat keys", stage));
  SFT_RETURN_IF_ERROR(ApplyStageConfig(json::parse(kEnvironmentStageRole), where, stage));
  // Estimated lights are lighting too: the stage fits their intensity and place with the map;
  // so is the lamp find_lamp starts (a point light).
  if (config.environment.find_lamp) {
    stage->fit.fit_lights = true;
    stage->fit.fit_light_positions = true;
  }
  for (const LightSpec& light : config.environment.lights) {
    stage->fit.fit_lights = true;
    if (light.type == LightType::kPoint) stage->fit.fit_light_positions = true;
    if (light.type == LightType::kDirectional) stage->fit.fit_light_directions = true;
  }
  SFT_RETURN_IF_ERROR(ApplyStageConfig(config.environment_stage_keys, where, stage));
  std::string why;
  if (!stage->Check(&why)) return Status::Error(where + ": " + why);
  return Status::Ok();
}

Status ResolveStages(const ScheduleConfig& config, bool carved_start,
                     std::vector<StageOptions>* stages) {
  json list = config.stages;
  std::string source = "stages";
  if (list.is_null()) {
    std::string name = config.schedule;
    if (name == "auto") {
      name = carved_start                            ? "hull"
             : FlatKeysDescribeOneStage(config.flat) ? "refine"
                                                     : "large_steps";
    }
    if (name == "large_steps" || name == "hull") {
      list = json::parse(name == "hull" ? kHullSchedule : kLargeStepsSchedule);
      for (json& stage : list) {
        const json own = stage;  // a stage's own keys win over the list's.
        stage.update(json::parse(kLargeStepsStageKeys));
        if (stage["phases"] == "geometry") {
          stage.update(json::parse(name == "hull" ? kHullGeometryKeys : kLargeStepsGeometryKeys));
        }
        stage.update(own);
      }
    } else {
      list = json::parse(kRefineSchedule);
    }
    source = "built-in schedule " + name;
  }
  stages->clear();
  for (size_t k = 0; k < list.size(); ++k) {
    StageOptions stage;
    stage.name = "stage" + std::to_string(k);
    const std::string where = source + "[" + std::to_string(k) + "]";
    SFT_RETURN_IF_ERROR(ApplyStageConfig(list[k], where, &stage));
    SFT_RETURN_IF_ERROR(ApplyStageConfig(config.flat, "flat keys", &stage));
    std::string why;
    if (!stage.Check(&why)) return Status::Error(where + " (" + stage.name + "): " + why);
    stages->push_back(std::move(stage));
  }
  return Status::Ok();
}

json StageJson(const StageOptions& stage) {
  json j = ReconstructConfigJson(stage.fit);
  for (const auto& [name, key] : StageKeys()) j[name] = key.get(stage);
  j["name"] = stage.name;
  return j;
}

Status StagesFromJson(const json& list, const std::string& source,
                      std::vector<StageOptions>* stages) {
  if (!list.is_array() || list.empty()) {
    return Status::Error(source + ": stages: expected a non-empty array");
  }
  stages->clear();
  for (size_t k = 0; k < list.size(); ++k) {
    StageOptions stage;
    const std::string where = source + ": stages[" + std::to_string(k) + "]";
    SFT_RETURN_IF_ERROR(ApplyStageConfig(list[k], where, &stage));
    std::string why;
    if (!stage.Check(&why)) return Status::Error(where + ": " + why);
    stages->push_back(std::move(stage));
  }
  return Status::Ok();
}

namespace {

// At most this many view indices are listed in a stage's views column.
constexpr size_t kListedViews = 16;
// The width of the "before" column ("remesh isotropic, resample"), so that "views" aligns.
constexpr int kBeforeWidth = 26;

std::string JoinIndices(const std::vector<int>& views, size_t begin, size_t end) {
  std::string text;
  for (size_t i = begin; i < end; ++i) text += (i > begin ? "," : "") + std::to_string(views[i]);
  return text;
}

}  // namespace

std::string DescribeStageViews(const std::vector<int>& views, int dataset_views) {
  const std::string of = dataset_views > 0 ? " of " + std::to_string(dataset_views) : "";
  if (views.empty()) return dataset_views > 0 ? "all " + std::to_string(dataset_views) : "all";
  const std::string count = std::to_string(views.size()) + of + ": ";
  if (views.size() <= kListedViews) return count + JoinIndices(views, 0, views.size());
  // Many views: the ones left out when they are few (a holdout's), else the ends of the list.
  std::vector<int> others;
  for (int v = 0; v < dataset_views; ++v) {
    if (std::find(views.begin(), views.end(), v) == views.end()) others.push_back(v);
  }
  if (dataset_views > 0 && others.size() <= kListedViews) {
    return count + "all but " + (others.empty() ? "none" : JoinIndices(others, 0, others.size()));
  }
  return count + JoinIndices(views, 0, 3) + ",...," +
         JoinIndices(views, views.size() - 3, views.size());
}

std::string FormatSchedule(const std::vector<StageOptions>& stages, int dataset_views) {
  // The name column is as wide as the longest name (at least 10), so that columns stay aligned.
  size_t width = 10;
  for (const StageOptions& s : stages) width = std::max(width, s.name.size());
  std::string text = "stage  " + std::string("name") + std::string(width - 2, ' ') +
                     "phases     scale   spp  levels  outer  steps  texels  solver  before" +
                     std::string(kBeforeWidth - 4, ' ') + "views\n";
  for (size_t k = 0; k < stages.size(); ++k) {
    const StageOptions& s = stages[k];
    const ReconstructOptions& f = s.fit;
    std::string before;
    if (s.topology.remesh != "none") before += "remesh " + s.topology.remesh;
    if (s.topology.resample) before += std::string(before.empty() ? "" : ", ") + "resample";
    if (before.empty()) before = "-";
    const std::string views = DescribeStageViews(f.views, dataset_views);
    char line[512];
    std::snprintf(line, sizeof(line),
                  "%5zu  %-*s  %-9s  1/%-4d %4d  %6d  %5d  %5d  %6s  %-6s  %-*s  %s\n", k,
                  static_cast<int>(width), s.name.c_str(), PhaseScheduleName(f.phases),
                  1 << f.cache.image_scale_log2, f.cache.render.spp, f.cache.pyramid_levels,
                  f.outer_iterations, f.solver.steps,
                  s.material_model == "uv" ? "uv"
                  : s.texel_resolution > 0 ? std::to_string(s.texel_resolution).c_str()
                  : s.texel_resolution == kTexelResolutionAuto ? "auto"
                                                               : "keep",
                  SolverKindName(f.solver.kind), kBeforeWidth, before.c_str(), views.c_str());
    text += line;
  }
  return text;
}

}  // namespace sft
