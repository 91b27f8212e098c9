#include "src/sweep/sweep_grid.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <set>

#include "src/core/file_util.h"
#include "src/eval/mesh_metrics.h"
#include "src/optim/schedule_config.h"

namespace sft {

const char* const kSweepAxes[9] = {"variant", "phases",      "views", "solver", "bounces",
                                   "effects", "image_scale", "spp",   "steps"};

namespace {

using json = nlohmann::json;

// The id prefix of each axis' values ("spp16", "scale0.5", "lm").
const std::map<std::string, std::string>& IdPrefixes() {
  static const std::map<std::string, std::string> prefixes = {
      {"variant", ""},          {"phases", ""},         {"views", "views"},
      {"solver", ""},           {"bounces", "bounces"}, {"effects", "effects-"},
      {"image_scale", "scale"}, {"spp", "spp"},         {"steps", "steps"}};
  return prefixes;
}

// The ablations of the research report (docs/cli.md, "--preset ablations"). One Adam stage as
// the large_steps geometry stages run it (docs/reconstruct.md), so that a cell spends its budget
// on one fit. Geometry cells start from the grid's init and hold the dataset's true material;
// texture cells fit from the default grey start on the reference mesh: each phase is measured on
// what it fits.
const char kAblationsPreset[] = R"({
  "config": {"spp": 16, "stages": [{"name": "fit", "solver": "adam", "image_scale": 1,
    "pyramid_levels": 3, "steps": 25, "adam_lr_vertices": 0.001, "adam_large_steps": 25,
    "adam_uniform": true, "adam_resample": true, "adam_views_per_step": 8,
    "independent_gradient": true, "image_loss": "relative", "fit_specular": true}]},
  "time_budget": 300,
  "axes": {
    "variant": [
      {"name": "local", "config": {"bounces": 1, "effects": "direct,specular,environment"}},
      {"name": "local+shadows",
       "config": {"bounces": 1, "effects": "direct,shadows,specular,environment"}},
      {"name": "global", "config": {"bounces": 2, "effects": "all"}}],
    "phases": [{"name": "geometry", "material": "ground_truth"},
               {"name": "texture", "init": "reference", "material": "grey"}],
    "views": [8, 16, 32, 64]
  }
})";

std::string AbsolutePath(const std::string& base_dir, const std::string& path) {
  std::error_code error;
  const std::filesystem::path joined = JoinPath(base_dir, path);
  const std::filesystem::path absolute = std::filesystem::absolute(joined, error);
  return (error ? joined : absolute).lexically_normal().string();
}

// A label for a value: numbers as JSON writes them, strings as they are.
std::string Label(const json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}

// Characters a folder name keeps; others become '-'.
std::string IdSafe(const std::string& text) {
  std::string out = text;
  for (char& c : out) {
    const bool keep =
        std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '+' || c == '-';
    if (!keep) c = '-';
  }
  return out;
}

Status ParseJsonText(const std::string& path, json* out) {
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  StripUtf8Bom(&text);
  *out = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (out->is_discarded()) return Status::Error(path + ": not valid JSON");
  return Status::Ok();
}

Status ParseString(const json& v, const std::string& where, std::string* out) {
  if (!v.is_string() || v.get<std::string>().empty()) {
    return Status::Error(where + ": expected a non-empty string");
  }
  *out = v.get<std::string>();
  return Status::Ok();
}

Status ParseEval(const json& v, const std::string& where, SweepEvalOptions* eval) {
  if (!v.is_object()) return Status::Error(where + ": expected a JSON object");
  for (const auto& [key, value] : v.items()) {
    const std::string at = where + "." + key;
    if (key == "spp" || key == "bounces" || key == "mesh_samples") {
      if (!value.is_number_integer()) return Status::Error(at + ": expected an integer");
      const int64_t n = value.get<int64_t>();
      int& field = key == "spp" ? eval->spp : key == "bounces" ? eval->bounces : eval->mesh_samples;
      field = static_cast<int>(std::max<int64_t>(INT32_MIN, std::min<int64_t>(INT32_MAX, n)));
    } else if (key == "f1_tolerance") {
      if (!value.is_number()) return Status::Error(at + ": expected a number");
      eval->f1_tolerance = value.get<double>();
    } else {
      return Status::Error(at +
                           ": unknown key (expected spp, bounces, f1_tolerance or "
                           "mesh_samples)");
    }
  }
  std::string why;
  if (!eval->Check(&why)) return Status::Error(where + "." + why);
  return Status::Ok();
}

// The start keys of an object value: "init" (a mesh file or "reference") and "material" (a
// file, inline JSON, "ground_truth" or "grey"); files are resolved against base_dir.
Status ParseValueStart(const json& v, const std::string& where, const std::string& base_dir,
                       SweepAxisValue* out) {
  if (v.contains("init")) {
    SFT_RETURN_IF_ERROR(ParseString(v["init"], where + ".init", &out->init));
    if (out->init != "reference") out->init = AbsolutePath(base_dir, out->init);
  }
  if (v.contains("material")) {
    SFT_RETURN_IF_ERROR(ParseString(v["material"], where + ".material", &out->material));
    const std::string& m = out->material;
    if (m != "ground_truth" && m != "grey" && m[0] != '{') {
      out->material = AbsolutePath(base_dir, m);
    }
  }
  return Status::Ok();
}

// A variant ({"name", "config"}) or a phases value as an object ({"name"}), each with the
// optional start keys.
Status ParseObjectValue(const std::string& axis, const json& v, const std::string& where,
                        const std::string& base_dir, SweepAxisValue* out) {
  const bool variant = axis == "variant";
  const char* expected = variant ? "name, config, init and material" : "name, init and material";
  for (const auto& [key, value] : v.items()) {
    if (key != "name" && key != "init" && key != "material" && !(variant && key == "config")) {
      return Status::Error(where + "." + key + ": unknown key (expected " + expected + ")");
    }
  }
  if (!v.contains("name")) return Status::Error(where + ".name: missing");
  SFT_RETURN_IF_ERROR(ParseString(v["name"], where + ".name", &out->label));
  out->value = v["name"];
  if (variant) {
    if (!v.contains("config") || !v["config"].is_object()) {
      return Status::Error(where + ".config: expected a JSON object of reconstruct keys");
    }
    out->config = v["config"];
  } else {
    out->config = {{axis, v["name"]}};
  }
  return ParseValueStart(v, where, base_dir, out);
}

// One axis value: a number or string (views: a positive integer; variant: {"name", "config"};
// phases: a string or {"name", ...}).
Status ParseAxisValue(const std::string& axis, const json& v, const std::string& where,
                      const std::string& base_dir, SweepAxisValue* out) {
  out->value = v;
  if (axis == "variant" && !v.is_object()) {
    return Status::Error(where + ": expected {\"name\": ..., \"config\": {...}}");
  }
  if ((axis == "variant" || axis == "phases") && v.is_object()) {
    return ParseObjectValue(axis, v, where, base_dir, out);
  }
  if (axis == "views") {
    if (!v.is_number_integer() || v.get<int64_t>() < 1 || v.get<int64_t>() > 1000000) {
      return Status::Error(where + ": expected a number of views, an integer >= 1");
    }
    out->views = v.get<int>();
    out->label = Label(v);
    out->config = json::object();
    return Status::Ok();
  }
  if (!(v.is_number() || v.is_string()) || (v.is_string() && v.get<std::string>().empty())) {
    return Status::Error(where + ": expected a number or a non-empty string");
  }
  out->label = Label(v);
  out->config = {{axis, v}};
  return Status::Ok();
}

Status ParseAxes(const json& v, const std::string& where, const std::string& base_dir,
                 std::vector<SweepAxis>* axes) {
  if (!v.is_object()) return Status::Error(where + ": expected a JSON object of axes");
  std::string known;
  for (const char* name : kSweepAxes) known += (known.empty() ? "" : ", ") + std::string(name);
  for (const auto& [key, value] : v.items()) {
    if (IdPrefixes().count(key) == 0) {
      return Status::Error(where + "." + key + ": unknown axis (expected one of " + known + ")");
    }
  }
  axes->clear();
  for (const char* name : kSweepAxes) {
    if (!v.contains(name)) continue;
    const json& list = v[name];
    const std::string at = where + "." + name;
    if (!list.is_array() || list.empty()) return Status::Error(at + ": expected a non-empty array");
    SweepAxis axis;
    axis.name = name;
    std::set<std::string> labels;
    for (size_t k = 0; k < list.size(); ++k) {
      SweepAxisValue value;
      const std::string item = at + "[" + std::to_string(k) + "]";
      SFT_RETURN_IF_ERROR(ParseAxisValue(name, list[k], item, base_dir, &value));
      if (!labels.insert(IdSafe(value.label)).second) {
        return Status::Error(item + ": \"" + value.label + "\" repeats a value of the axis");
      }
      axis.values.push_back(std::move(value));
    }
    axes->push_back(std::move(axis));
  }
  return Status::Ok();
}

// The base configuration: an object or a file (read and inlined), checked as a config.
Status ParseConfig(const json& v, const std::string& where, const std::string& base_dir,
                   json* out) {
  if (v.is_string()) {
    const std::string path = AbsolutePath(base_dir, v.get<std::string>());
    SFT_RETURN_IF_ERROR(ParseJsonText(path, out).Prefixed(where));
    ScheduleConfig probe;
    return MergeScheduleConfig(*out, path, &probe).Prefixed(where);
  }
  if (!v.is_object()) return Status::Error(where + ": expected a JSON object or a file name");
  *out = v;
  ScheduleConfig probe;
  return MergeScheduleConfig(*out, where, &probe);
}

}  // namespace

bool SweepEvalOptions::Check(std::string* why) const {
  if (spp < 1 || spp > 65536) {
    *why = "spp: must be in [1, 65536]";
  } else if (bounces < 1 || bounces > 16) {
    *why = "bounces: must be in [1, 16]";
  } else if (!(f1_tolerance > 0.0 && f1_tolerance <= 1.0)) {
    *why = "f1_tolerance: must be in (0, 1]";
  } else if (mesh_samples < MeshMetricsOptions::kMinSamples ||
             mesh_samples > MeshMetricsOptions::kMaxSamples) {
    *why = "mesh_samples: must be in [" + std::to_string(MeshMetricsOptions::kMinSamples) + ", " +
           std::to_string(MeshMetricsOptions::kMaxSamples) + "]";
  } else {
    return true;
  }
  return false;
}

bool SweepGrid::Check(std::string* why) const {
  if (dataset.empty()) {
    *why = "dataset: missing (give it in the grid or with --dataset)";
    return false;
  }
  if (!(time_budget >= 0.0 && time_budget <= 1e6)) {
    *why = "time_budget: must be in (0, 1e6] seconds";
    return false;
  }
  if (outer_iterations < 0 || outer_iterations > 10000) {
    *why = "outer_iterations: must be in [1, 10000]";
    return false;
  }
  if (!eval.Check(why)) {
    *why = "eval." + *why;
    return false;
  }
  return true;
}

Status ParseSweepGrid(const json& grid, const std::string& source, const std::string& base_dir,
                      SweepGrid* out) {
  if (!grid.is_object()) return Status::Error(source + ": expected a JSON object");
  SweepGrid g;
  for (const auto& [key, value] : grid.items()) {
    const std::string where = source + ": " + key;
    if (key == "dataset" || key == "init" || key == "reference") {
      std::string path;
      SFT_RETURN_IF_ERROR(ParseString(value, where, &path));
      (key == "dataset" ? g.dataset
       : key == "init"  ? g.init
                        : g.reference) = AbsolutePath(base_dir, path);
    } else if (key == "material") {
      SFT_RETURN_IF_ERROR(ParseString(value, where, &g.material));
      if (g.material[0] != '{') g.material = AbsolutePath(base_dir, g.material);
    } else if (key == "config") {
      SFT_RETURN_IF_ERROR(ParseConfig(value, where, base_dir, &g.config));
    } else if (key == "time_budget") {
      if (!value.is_number() || !(value.get<double>() > 0.0 && value.get<double>() <= 1e6)) {
        return Status::Error(where + ": expected seconds in (0, 1e6]");
      }
      g.time_budget = value.get<double>();
    } else if (key == "outer_iterations") {
      if (!value.is_number_integer() || value.get<int64_t>() < 1 || value.get<int64_t>() > 10000) {
        return Status::Error(where + ": expected an integer in [1, 10000]");
      }
      g.outer_iterations = value.get<int>();
    } else if (key == "eval") {
      SFT_RETURN_IF_ERROR(ParseEval(value, where, &g.eval));
    } else if (key == "axes") {
      SFT_RETURN_IF_ERROR(ParseAxes(value, where, base_dir, &g.axes));
    } else {
      return Status::Error(source + ": " + key +
                           ": unknown key (expected dataset, init, material, reference, config, "
                           "time_budget, outer_iterations, eval or axes)");
    }
  }
  *out = std::move(g);
  return Status::Ok();
}

Status ReadSweepGrid(const std::string& path, SweepGrid* out) {
  json grid;
  SFT_RETURN_IF_ERROR(ParseJsonText(path, &grid));
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return ParseSweepGrid(grid, path, dir.empty() ? "." : dir, out);
}

Status ApplySweepOverrides(const SweepOverrides& o, SweepGrid* grid) {
  if (!o.dataset.empty()) grid->dataset = AbsolutePath(".", o.dataset);
  if (!o.init.empty()) grid->init = AbsolutePath(".", o.init);
  if (!o.reference.empty()) grid->reference = AbsolutePath(".", o.reference);
  if (!o.material.empty()) {
    grid->material = o.material[0] == '{' ? o.material : AbsolutePath(".", o.material);
  }
  if (!o.config.empty()) {
    json config;
    SFT_RETURN_IF_ERROR(ParseConfig(json(o.config), "--config", ".", &config));
    config.update(grid->config);
    grid->config = config;
  }
  if (o.time_budget != 0.0) {
    if (!(o.time_budget > 0.0 && o.time_budget <= 1e6)) {
      return Status::Error("--time-budget: expected seconds in (0, 1e6]");
    }
    grid->time_budget = o.time_budget;
  }
  if (o.outer_iterations != 0) {
    if (o.outer_iterations < 1 || o.outer_iterations > 10000) {
      return Status::Error("--outer: expected an integer in [1, 10000]");
    }
    grid->outer_iterations = o.outer_iterations;
  }
  if (o.eval_spp != 0) grid->eval.spp = o.eval_spp;
  if (o.eval_bounces != 0) grid->eval.bounces = o.eval_bounces;
  std::string why;
  if (!grid->eval.Check(&why)) {
    return Status::Error("--eval-" + why.substr(0, why.find(':')) + why.substr(why.find(':')));
  }
  return Status::Ok();
}

Status PresetSweepGrid(const std::string& name, SweepGrid* out) {
  if (name != "ablations") {
    return Status::Error("--preset: unknown preset \"" + name + "\" (expected ablations)");
  }
  return ParseSweepGrid(json::parse(kAblationsPreset), "preset ablations", ".", out);
}

json SweepGridJson(const SweepGrid& grid) {
  json axes = json::object();
  for (const SweepAxis& axis : grid.axes) {
    json values = json::array();
    for (const SweepAxisValue& v : axis.values) {
      json value = v.value;
      if (axis.name == "variant") value = {{"name", v.label}, {"config", v.config}};
      if (!v.init.empty() || !v.material.empty()) {
        if (!value.is_object()) value = {{"name", v.label}};
        if (!v.init.empty()) value["init"] = v.init;
        if (!v.material.empty()) value["material"] = v.material;
      }
      values.push_back(value);
    }
    axes[axis.name] = values;
  }
  json j = {{"dataset", grid.dataset},
            {"config", grid.config},
            {"eval",
             {{"spp", grid.eval.spp},
              {"bounces", grid.eval.bounces},
              {"f1_tolerance", grid.eval.f1_tolerance},
              {"mesh_samples", grid.eval.mesh_samples}}},
            {"axes", axes}};
  if (!grid.init.empty()) j["init"] = grid.init;
  if (!grid.material.empty()) j["material"] = grid.material;
  if (!grid.reference.empty()) j["reference"] = grid.reference;
  if (grid.time_budget > 0.0) j["time_budget"] = grid.time_budget;
  if (grid.outer_iterations > 0) j["outer_iterations"] = grid.outer_iterations;
  return j;
}

std::vector<SweepCell> EnumerateCells(const SweepGrid& grid) {
  size_t count = 1;
  for (const SweepAxis& axis : grid.axes) count *= axis.values.size();
  const int digits = std::max<int>(2, std::to_string(count - 1).size());
  std::vector<SweepCell> cells;
  for (size_t index = 0; index < count; ++index) {
    SweepCell cell;
    cell.index = static_cast<int>(index);
    std::string id = std::to_string(index);
    id.insert(0, digits - id.size(), '0');
    // The last axis varies fastest.
    size_t stride = count;
    for (const SweepAxis& axis : grid.axes) {
      stride /= axis.values.size();
      const SweepAxisValue& v = axis.values[(index / stride) % axis.values.size()];
      cell.settings[axis.name] = v.value;
      cell.config.update(v.config);
      if (axis.name == "views") cell.views = v.views;
      if (!v.init.empty()) cell.init = v.init;
      if (!v.material.empty()) cell.material = v.material;
      id += "_" + IdSafe(IdPrefixes().at(axis.name) + v.label);
    }
    cell.id = id;
    cells.push_back(std::move(cell));
  }
  return cells;
}

Status EvenlySpacedViews(int count, int total, std::vector<int>* views) {
  if (count < 1 || count > total) {
    return Status::Error("views: " + std::to_string(count) + " views asked, the dataset has " +
                         std::to_string(total));
  }
  views->clear();
  for (int i = 0; i < count; ++i) {
    views->push_back(static_cast<int>(static_cast<int64_t>(i) * total / count));
  }
  return Status::Ok();
}

}  // namespace sft
