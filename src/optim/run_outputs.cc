#include "src/optim/run_outputs.h"

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

}  // namespace

Status WriteRunState(const std::string& out, const RunState& state) {
  json j = {{"format", "sft-reconstruct-state/1"},
            {"dataset", state.dataset},
            {"init", state.init},
            {"config", state.config},
            {"outer_done", state.outer_done},
            {"seconds", state.seconds},
            {"finished", state.finished}};
  return WriteTextFile(JoinPath(out, "state.json"), j.dump(1) + "\n");
}

Status ReadRunState(const std::string& out, RunState* state) {
  const std::string path = JoinPath(out, "state.json");
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object() || j.value("format", "") != "sft-reconstruct-state/1") {
    return Status::Error(path + ": not an sft reconstruction state (format " +
                         "sft-reconstruct-state/1)");
  }
  if (!j.contains("dataset") || !j["dataset"].is_string() || !j.contains("config") ||
      !j["config"].is_object() || !j.contains("outer_done") ||
      !j["outer_done"].is_number_integer()) {
    return Status::Error(path + ": missing dataset, config or outer_done");
  }
  state->dataset = j["dataset"].get<std::string>();
  state->init = j.value("init", "");
  state->config = j["config"];
  state->outer_done = j["outer_done"].get<int>();
  state->seconds = j.value("seconds", 0.0);
  state->finished = j.value("finished", false);
  return Status::Ok();
}

Status WriteReconstructionState(const std::string& out, const Dataset& dataset,
                                const Reconstruction& reconstruction) {
  const TriMesh mesh = reconstruction.Mesh();
  SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(out, "mesh.ply"), mesh));
  SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(out, "mesh.obj"), mesh));
  SFT_RETURN_IF_ERROR(
      SaveMaterial(JoinPath(out, "material.json"), reconstruction.CurrentMaterial()));
  return WriteLightScales(JoinPath(out, "lights.json"), dataset, reconstruction.LightScales());
}

Status WriteMetrics(const std::string& out, const std::vector<IterationRecord>& records,
                    const std::vector<PhaseRecord>& phases, const json& extra) {
  std::string csv = "outer,phase,iteration,cost,seconds,accepted,mean_psnr";
  const size_t num_views = records.empty() ? 0 : records.front().view_psnr.size();
  for (size_t v = 0; v < num_views; ++v) csv += ",psnr_view" + std::to_string(v);
  csv += "\n";
  json iterations = json::array();
  for (const IterationRecord& r : records) {
    double mean = 0.0;
    for (double p : r.view_psnr) mean += p / std::max<size_t>(1, r.view_psnr.size());
    char line[256];
    std::snprintf(line, sizeof(line), "%d,%s,%d,%.9g,%.3f,%d,%.4f", r.outer, r.phase.c_str(),
                  r.iteration, r.cost, r.seconds, r.accepted ? 1 : 0, mean);
    csv += line;
    for (double p : r.view_psnr) {
      std::snprintf(line, sizeof(line), ",%.4f", p);
      csv += line;
    }
    csv += "\n";
    iterations.push_back({{"outer", r.outer},
                          {"phase", r.phase},
                          {"iteration", r.iteration},
                          {"cost", r.cost},
                          {"seconds", r.seconds},
                          {"accepted", r.accepted},
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

Status ReadOuterRecords(const std::string& out, json* records) {
  const std::string path = JoinPath(out, "metrics.json");
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  *records = json::array();
  if (!j.is_discarded() && j.is_object() && j.contains("outer") && j["outer"].is_array()) {
    *records = j["outer"];
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
    r.phase = e.value("phase", "");
    r.iteration = e.value("iteration", 0);
    r.cost = e.value("cost", 0.0);
    r.seconds = e.value("seconds", 0.0);
    r.accepted = e.value("accepted", false);
    if (e.contains("view_psnr") && e["view_psnr"].is_array()) {
      for (const json& p : e["view_psnr"])
        r.view_psnr.push_back(p.is_number() ? p.get<double>() : 0.0);
    }
    records->push_back(std::move(r));
  }
  return Status::Ok();
}

}  // namespace sft
