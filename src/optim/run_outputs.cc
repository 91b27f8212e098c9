#include "src/optim/run_outputs.h"

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "src/core/file_util.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/light_scales.h"

namespace sft {

using json = nlohmann::json;

namespace {

json TimeSplitJson(const SolverTimeSplit& t) {
  json split = json::object();
  for (const auto& [name, seconds] : TimeSplitParts(t)) split[name] = seconds;
  return split;
}

// "holdout" and "held_out_views" (absent in runs before --holdout: none held out).
Status ReadHeldOut(const json& j, const std::string& path, RunState* state) {
  state->holdout = 0;
  state->held_out_views.clear();
  if (!j.contains("held_out_views") && !j.contains("holdout")) return Status::Ok();
  const json& k = j.value("holdout", json(0));
  const json& views = j.value("held_out_views", json::array());
  bool ok = k.is_number_integer() && k.get<int64_t>() >= 0 && k.get<int64_t>() <= INT32_MAX &&
            views.is_array();
  for (size_t i = 0; ok && i < views.size(); ++i) {
    ok = views[i].is_number_integer() && views[i].get<int64_t>() >= 0 &&
         views[i].get<int64_t>() <= INT32_MAX;
    if (ok) state->held_out_views.push_back(views[i].get<int>());
  }
  if (!ok) {
    return Status::Error(path + ": holdout/held_out_views: expected an integer >= 0 and an " +
                         "array of view indices");
  }
  state->holdout = k.get<int>();
  return Status::Ok();
}

}  // namespace

Status WriteRunState(const std::string& out, const RunState& state) {
  const ScheduleProgress& p = state.progress;
  json j = {{"format", kRunStateFormat},
            {"run", state.run_info},
            {"stages", state.stages},
            {"stage", p.stage},
            {"stage_outer_done", p.stage_outer_done},
            {"stage_prepared", p.stage_prepared},
            {"outer_done", p.outer_done},
            {"topology_changes", p.topology_changes},
            {"stage_outers_done", p.stage_outers_done},
            {"seconds", p.seconds},
            {"finished", state.finished},
            {"holdout", state.holdout},
            {"held_out_views", state.held_out_views}};
  if (!state.view_gains.empty()) {
    json gains = json::array();
    for (const Eigen::Vector3d& g : state.view_gains) gains.push_back({g[0], g[1], g[2]});
    j["exposure_gains"] = gains;
  }
  return WriteTextFile(JoinPath(out, "state.json"), j.dump(1) + "\n");
}

Status ReadRunState(const std::string& out, RunState* state) {
  const std::string path = JoinPath(out, "state.json");
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    return Status::Error(path + ": not an sft reconstruction state (not a JSON object)");
  }
  const std::string format = j.value("format", "");
  if (format != kRunStateFormat) {
    return Status::Error(path + ": format \"" + format + "\" is not " + kRunStateFormat +
                         " (a run of an older sft cannot be resumed: start a new run from its " +
                         "mesh.ply with --init)");
  }
  const auto integer = [&](const char* key) {
    return j.contains(key) && j[key].is_number_integer() && j[key].get<int64_t>() >= 0;
  };
  if (!j.contains("run") || !j["run"].is_object() || !j["run"].contains("dataset") ||
      !j["run"]["dataset"].is_string() || !j.contains("stages") || !j["stages"].is_array() ||
      !integer("stage") || !integer("stage_outer_done") || !integer("outer_done")) {
    return Status::Error(path + ": missing or invalid run, stages, stage, stage_outer_done or " +
                         "outer_done");
  }
  state->run_info = j["run"];
  state->stages = j["stages"];
  ScheduleProgress& p = state->progress;
  p.stage = j["stage"].get<int>();
  p.stage_outer_done = j["stage_outer_done"].get<int>();
  p.stage_prepared = j.value("stage_prepared", false);
  p.outer_done = j["outer_done"].get<int>();
  p.topology_changes = j.value("topology_changes", 0);
  if (j.contains("stage_outers_done") && j["stage_outers_done"].is_array()) {
    for (const json& n : j["stage_outers_done"]) {
      p.stage_outers_done.push_back(n.is_number_integer() ? n.get<int>() : 0);
    }
  }
  p.seconds = j.value("seconds", 0.0);
  state->finished = j.value("finished", false);
  state->view_gains.clear();
  if (j.contains("exposure_gains")) {
    const json& gains = j["exposure_gains"];
    bool ok = gains.is_array();
    for (size_t v = 0; ok && v < gains.size(); ++v) {
      const json& g = gains[v];
      ok = g.is_array() && g.size() == 3;
      Eigen::Vector3d gain;
      for (int c = 0; ok && c < 3; ++c) {
        ok = g[c].is_number() && std::isfinite(g[c].get<double>()) && g[c].get<double>() > 0.0;
        if (ok) gain[c] = g[c].get<double>();
      }
      if (ok) state->view_gains.push_back(gain);
    }
    if (!ok) {
      return Status::Error(path + ": exposure_gains: expected one [R, G, B] of positive numbers " +
                           "per dataset view");
    }
  }
  SFT_RETURN_IF_ERROR(ReadHeldOut(j, path, state));
  if (p.stage > static_cast<int>(state->stages.size())) {
    return Status::Error(path + ": stage " + std::to_string(p.stage) + " of " +
                         std::to_string(state->stages.size()));
  }
  return Status::Ok();
}

Status WriteRunSnapshot(const std::string& out, const Dataset& dataset, const TriMesh& mesh,
                        const Material& material, const std::vector<double>& light_scales,
                        const std::vector<Eigen::Vector3d>& light_positions,
                        const std::vector<Eigen::Vector3d>& light_directions,
                        const std::vector<Eigen::Vector3d>& environment_rotations) {
  SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(out, "mesh.ply"), mesh));
  if (material.has_uv_textures()) {
    // UV textures: mesh.obj carries the corner UVs that material.json's "uv_mesh" names.
    TriMesh with_uvs = mesh;
    SetFaceCornerUvs(material.uv.corner_uvs, &with_uvs);
    SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(out, "mesh.obj"), with_uvs));
    SFT_RETURN_IF_ERROR(SaveUvMaterial(JoinPath(out, "material.json"), material, "mesh.obj"));
  } else {
    SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(out, "mesh.obj"), mesh));
    SFT_RETURN_IF_ERROR(SaveMaterial(JoinPath(out, "material.json"), material));
  }
  std::vector<double> scales = light_scales;
  if (scales.empty()) scales.assign(dataset.lights.size(), 1.0);
  return WriteLightScales(JoinPath(out, "lights.json"), dataset, scales, light_positions,
                          light_directions, environment_rotations);
}

Status ReadRunSnapshot(const std::string& out, const Dataset& dataset, TriMesh* mesh,
                       Material* material, std::vector<double>* light_scales,
                       std::vector<Eigen::Vector3d>* light_positions,
                       std::vector<Eigen::Vector3d>* light_directions,
                       std::vector<Eigen::Vector3d>* environment_rotations) {
  SFT_RETURN_IF_ERROR(ReadMesh(JoinPath(out, "mesh.ply"), mesh));
  SFT_RETURN_IF_ERROR(
      LoadMaterial(JoinPath(out, "material.json"), *mesh, material, MaterialUse::kCheckpoint));
  return ReadLightScales(JoinPath(out, "lights.json"), dataset, light_scales, light_positions,
                         light_directions, environment_rotations);
}

Status WriteExposure(const std::string& out, const Dataset& dataset,
                     const std::vector<Eigen::Vector3d>& view_gains, int gauge_view) {
  json views = json::array();
  for (size_t v = 0; v < view_gains.size(); ++v) {
    const Eigen::Vector3d& g = view_gains[v];
    views.push_back({{"view", v},
                     {"image", v < dataset.views.size() ? dataset.views[v].image : ""},
                     {"gains", {g[0], g[1], g[2]}}});
  }
  const json j = {{"format", "sft-exposure/1"}, {"gauge_view", gauge_view}, {"views", views}};
  return WriteTextFile(JoinPath(out, "exposure.json"), j.dump(1) + "\n");
}

Status WritePoses(const std::string& out, const Dataset& dataset,
                  const std::vector<PoseDelta>& view_poses, int gauge_view) {
  std::vector<Rigid3d> poses;
  std::vector<std::string> images;
  for (const ViewSpec& view : dataset.views) {
    poses.push_back(view.cam_from_world);
    images.push_back(view.image);
  }
  return WriteTextFile(JoinPath(out, kPosesFile), PosesJson(view_poses, poses, images, gauge_view));
}

Status ReadPoses(const std::string& path, const Dataset& dataset,
                 std::vector<PoseDelta>* view_poses, bool* found) {
  view_poses->clear();
  *found = FileExists(path);
  if (!*found) return Status::Ok();
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  return ParsePosesJson(text, static_cast<int>(dataset.views.size()), view_poses).Prefixed(path);
}

Status WriteMetrics(const std::string& out, const std::vector<IterationRecord>& records,
                    const std::vector<PhaseRecord>& phases, const json& extra) {
  std::string csv = "outer,stage,phase,iteration,cost,seconds,accepted,mean_psnr";
  const size_t num_views = records.empty() ? 0 : records.front().view_psnr.size();
  for (size_t v = 0; v < num_views; ++v) csv += ",psnr_view" + std::to_string(v);
  csv += "\n";
  json iterations = json::array();
  for (const IterationRecord& r : records) {
    double mean = 0.0;
    for (double p : r.view_psnr) mean += p / std::max<size_t>(1, r.view_psnr.size());
    char line[256];
    std::snprintf(line, sizeof(line), "%d,%s,%s,%d,%.9g,%.3f,%d,%.4f", r.outer, r.stage.c_str(),
                  r.phase.c_str(), r.iteration, r.cost, r.seconds, r.accepted ? 1 : 0, mean);
    csv += line;
    for (double p : r.view_psnr) {
      std::snprintf(line, sizeof(line), ",%.4f", p);
      csv += line;
    }
    csv += "\n";
    iterations.push_back({{"outer", r.outer},
                          {"stage", r.stage},
                          {"phase", r.phase},
                          {"iteration", r.iteration},
                          {"cost", r.cost},
                          {"seconds", r.seconds},
                          {"accepted", r.accepted},
                          {"full", r.full},
                          {"view_psnr", r.view_psnr}});
  }
  json phase_list = json::array();
  for (const PhaseRecord& p : phases) {
    phase_list.push_back({{"outer", p.outer},
                          {"phase", p.phase},
                          {"iterations", p.stats.iterations},
                          {"seconds", p.stats.seconds},
                          {"setup_seconds", p.stats.setup_seconds},
                          {"residual_blocks", p.stats.problem.residual_blocks},
                          {"parameter_blocks", p.stats.problem.parameter_blocks},
                          {"superset_entries", p.stats.problem.superset_entries},
                          {"pixels_without_parameters", p.stats.problem.pixels_without_parameters},
                          {"dropped_jacobian_fraction", p.stats.dropped_jacobian_fraction},
                          {"non_finite_values", p.non_finite_values},
                          {"evaluations", p.stats.evaluations},
                          {"time_split", TimeSplitJson(p.stats.time)},
                          {"termination", p.stats.termination}});
  }
  json metrics = extra.is_object() ? extra : json::object();
  metrics["iterations"] = iterations;
  metrics["phases"] = phase_list;
  SFT_RETURN_IF_ERROR(WriteTextFile(JoinPath(out, "metrics.csv"), csv));
  return WriteTextFile(JoinPath(out, "metrics.json"), metrics.dump(1) + "\n");
}

Status ReadMetricsJson(const std::string& out, json* metrics) {
  const std::string path = JoinPath(out, "metrics.json");
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  *metrics = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (metrics->is_discarded() || !metrics->is_object()) {
    return Status::Error(path + ": not a JSON object");
  }
  return Status::Ok();
}

Status ReadIterationRecords(const std::string& out, std::vector<IterationRecord>* records) {
  const std::string path = JoinPath(out, "metrics.json");
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object() || !j.contains("iterations") ||
      !j["iterations"].is_array()) {
    return Status::Error(path + ": iterations: expected an array");
  }
  records->clear();
  for (const json& e : j["iterations"]) {
    IterationRecord r;
    r.outer = e.value("outer", 0);
    r.stage = e.value("stage", "");
    r.phase = e.value("phase", "");
    r.iteration = e.value("iteration", 0);
    r.cost = e.value("cost", 0.0);
    r.seconds = e.value("seconds", 0.0);
    r.accepted = e.value("accepted", false);
    r.full = e.value("full", false);
    if (e.contains("view_psnr") && e["view_psnr"].is_array()) {
      for (const json& p : e["view_psnr"])
        r.view_psnr.push_back(p.is_number() ? p.get<double>() : 0.0);
    }
    records->push_back(std::move(r));
  }
  return Status::Ok();
}

}  // namespace sft
