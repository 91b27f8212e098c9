#include "src/sweep/sweep_cell.h"

#include <algorithm>
#include <chrono>
#include <set>

#include "src/core/file_util.h"
#include "src/eval/mesh_metrics.h"
#include "src/eval/reconstruction_eval.h"
#include "src/eval/reference_score.h"
#include "src/geometry/material.h"
#include "src/io/scene_setup.h"
#include "src/optim/schedule_config.h"

namespace sft {
namespace {

using json = nlohmann::json;

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Outer iterations of a budgeted cell's last stage: more than any budget allows, so that the
// budget is what ends the cell.
constexpr int kBudgetOuterIterations = 10000;

// The base configuration with the grid's outer iterations.
Status BaseConfig(const SweepGrid& grid, ScheduleConfig* config) {
  SFT_RETURN_IF_ERROR(MergeScheduleConfig(grid.config, "config", config));
  if (grid.outer_iterations > 0) {
    return MergeScheduleConfig({{"outer_iterations", grid.outer_iterations}}, "grid", config);
  }
  return Status::Ok();
}

// The stages of `config`. With a budget and no flat outer_iterations, the last stage runs until
// the budget ends it; the earlier stages keep their own counts (a list's coarse stages stay as
// long as the list says, and the budget's remainder goes to its last stage).
Status ResolveBudgetedStages(const SweepGrid& grid, const ScheduleConfig& config, bool carved,
                             std::vector<StageOptions>* stages) {
  SFT_RETURN_IF_ERROR(ResolveStages(config, carved, stages));
  if (grid.time_budget > 0.0 && !config.flat.contains("outer_iterations")) {
    stages->back().fit.outer_iterations = kBudgetOuterIterations;
  }
  return Status::Ok();
}

// The stages as JSON with "fit every view" written one way (an empty list).
json NormalizedStages(const std::vector<StageOptions>& stages, int num_views) {
  json list = json::array();
  for (const StageOptions& stage : stages) {
    json j = StageJson(stage);
    const std::set<int> views(stage.fit.views.begin(), stage.fit.views.end());
    if (static_cast<int>(views.size()) == num_views && *views.begin() == 0 &&
        *views.rbegin() == num_views - 1) {
      j["views"] = json::array();
    }
    list.push_back(j);
  }
  return list;
}

json MeasureLine(const json& pass) {
  if (!pass.is_object()) return nullptr;
  json out = json::object();
  for (const char* key : {"psnr_srgb", "ssim_srgb", "psnr_linear", "ssim_linear", "rel_rmse"}) {
    out[key] = pass.value(key, json());
  }
  return out;
}

// Scores the reconstruction in `dir`: images of the fitted views (dir/eval.json) and, with a
// reference, Chamfer and F1 of dir/mesh.ply.
Status ScoreCell(const SweepContext& context, const std::string& dir, const std::vector<int>& views,
                 json* line) {
  const SweepGrid& grid = *context.grid;
  ReconstructionEvalOptions options;
  options.spp = grid.eval.spp;
  options.bounces = grid.eval.bounces;
  options.views = views;
  json images;
  SFT_RETURN_IF_ERROR(EvaluateReconstruction(grid.dataset, dir, options, &images));
  SFT_RETURN_IF_ERROR(WriteTextFile(JoinPath(dir, "eval.json"), images.dump(1) + "\n"));
  for (const char* pass : {"full", "albedo", "roughness"}) {
    (*line)[pass] = MeasureLine(images[pass]);
  }
  (*line)["chamfer"] = nullptr;
  (*line)["f1"] = nullptr;
  if (grid.reference.empty()) return Status::Ok();
  TriMesh mesh;
  const std::string mesh_path = JoinPath(dir, "mesh.ply");
  SFT_RETURN_IF_ERROR(ReadMesh(mesh_path, &mesh));
  MeshMetricsOptions mesh_options;
  mesh_options.tolerance = grid.eval.f1_tolerance;
  mesh_options.samples = grid.eval.mesh_samples;
  MeshMetrics m;
  SFT_RETURN_IF_ERROR(
      ComputeMeshMetrics(context.reference, mesh, mesh_options, &m, grid.reference, mesh_path));
  (*line)["chamfer"] = m.chamfer;
  (*line)["f1"] = m.f1;
  (*line)["f1_tolerance"] = m.tolerance;
  return Status::Ok();
}

// Runs the schedule of `stages` in `dir`; *seconds is its wall time, *ended_by why it stopped.
Status Reconstruct(const SweepContext& context, const CellStart& start,
                   const std::vector<StageOptions>& stages, const std::string& dir,
                   const CellCallbacks& callbacks, json* line, bool* interrupted) {
  const json run_info = {{"dataset", context.grid->dataset},
                         {"start", start.choice.Describe()},
                         {"init", start.choice.path},
                         {"material", start.material},
                         {"sweep_cell", (*line)["id"]}};
  std::unique_ptr<Schedule> schedule;
  SFT_RETURN_IF_ERROR(
      Schedule::Start(context.dataset, dir, stages, start.state, run_info, &schedule));
  const double budget = context.grid->time_budget;
  bool budget_spent = false;
  ScheduleCallbacks hooks;
  hooks.on_iteration = [&](const IterationRecord& record) {
    if (callbacks.on_iteration &&
        !callbacks.on_iteration(record.seconds, schedule->CurrentStage())) {
      *interrupted = true;
      return false;
    }
    if (budget > 0.0 && record.seconds >= budget) {
      budget_spent = true;
      return false;
    }
    return true;
  };
  if (!context.grid->reference.empty()) {
    hooks.score = [&](const TriMesh& mesh, json* out) {
      const SweepEvalOptions& eval = context.grid->eval;
      return ScoreAgainstReference(context.reference, eval.f1_tolerance, mesh, "reference", out,
                                   std::min(eval.mesh_samples, kOuterScoreSamples));
    };
  }
  SFT_RETURN_IF_ERROR(schedule->Run(hooks));
  if (*interrupted) return Status::Ok();
  const ScheduleProgress& p = schedule->progress();
  json trajectory = json::array();
  for (const json& outer : schedule->outer_records()) {
    json point = {{"stage", outer.value("stage", "")}, {"seconds", outer.value("seconds", 0.0)}};
    for (const char* key : {"chamfer", "f1"}) {
      if (outer.contains(key)) point[key] = outer[key];
    }
    trajectory.push_back(point);
  }
  (*line)["trajectory"] = trajectory;
  (*line)["seconds"] = p.seconds;
  (*line)["ended_by"] = budget_spent ? "time_budget" : "iterations";
  (*line)["outer_iterations"] = p.outer_done;
  (*line)["iterations"] = schedule->records().size();
  return Status::Ok();
}

}  // namespace

Status LoadCellStart(const SweepContext& context, const SweepCell& cell, CellStart* start) {
  const SweepGrid& grid = *context.grid;
  start->choice = context.start;
  start->material = grid.material;
  if (cell.init.empty() && cell.material.empty()) {
    start->state = context.start_state;
    return Status::Ok();
  }
  if (cell.init == "reference") {
    if (grid.reference.empty()) {
      return Status::Error("init \"reference\": the grid gives no reference mesh");
    }
    SFT_RETURN_IF_ERROR(ChooseStart(context.dataset, grid.reference, &start->choice));
    start->state.mesh = context.reference;  // read once, by LoadSweepContext.
  } else if (!cell.init.empty()) {
    SFT_RETURN_IF_ERROR(ChooseStart(context.dataset, cell.init, &start->choice));
    SFT_RETURN_IF_ERROR(
        LoadStartMesh(context.dataset, start->choice, InitialMeshOptions(), &start->state.mesh));
  } else {
    start->state.mesh = context.start_state.mesh;
  }
  if (cell.material == "grey") {
    start->material.clear();
  } else if (cell.material == "ground_truth") {
    std::string relative;
    SFT_RETURN_IF_ERROR(GroundTruthPath(context.dataset, "material", &relative));
    if (relative.empty()) {
      return Status::Error(
          "material \"ground_truth\": " + JoinPath(context.dataset.root, "scene.json") +
          " has no ground_truth.material");
    }
    start->material = JoinPath(context.dataset.root, relative);
  } else if (!cell.material.empty()) {
    start->material = cell.material;
  }
  return LoadMaterial(start->material.empty() ? kInitialMaterial : start->material,
                      start->state.mesh, &start->state.material);
}

Status LoadSweepContext(const SweepGrid& grid, SweepContext* context) {
  context->grid = &grid;
  if (!grid.reference.empty()) SFT_RETURN_IF_ERROR(ReadMesh(grid.reference, &context->reference));
  SFT_RETURN_IF_ERROR(ReadDataset(grid.dataset, &context->dataset));
  SFT_RETURN_IF_ERROR(CheckViewsHaveLights(context->dataset));
  SFT_RETURN_IF_ERROR(ChooseStart(context->dataset, grid.init, &context->start));
  ScheduleConfig config;
  SFT_RETURN_IF_ERROR(BaseConfig(grid, &config));
  std::vector<StageOptions> stages;
  SFT_RETURN_IF_ERROR(
      ResolveBudgetedStages(grid, config, context->start.kind == StartKind::kCarved, &stages)
          .Prefixed("config"));
  context->default_stages =
      NormalizedStages(stages, static_cast<int>(context->dataset.views.size()));
  SFT_RETURN_IF_ERROR(LoadStartMesh(context->dataset, context->start, InitialMeshOptions(),
                                    &context->start_state.mesh));
  return LoadMaterial(grid.material.empty() ? kInitialMaterial : grid.material,
                      context->start_state.mesh, &context->start_state.material);
}

Status CellStages(const SweepContext& context, const SweepCell& cell,
                  std::vector<StageOptions>* stages) {
  ScheduleConfig config;
  SFT_RETURN_IF_ERROR(BaseConfig(*context.grid, &config));
  SFT_RETURN_IF_ERROR(MergeScheduleConfig(cell.config, "axes", &config));
  if (cell.views > 0) {
    std::vector<int> views;
    SFT_RETURN_IF_ERROR(
        EvenlySpacedViews(cell.views, static_cast<int>(context.dataset.views.size()), &views));
    SFT_RETURN_IF_ERROR(MergeScheduleConfig({{"views", views}}, "axes", &config));
  }
  // A cell with its own start mesh is never carved.
  const bool carved = cell.init.empty() && context.start.kind == StartKind::kCarved;
  return ResolveBudgetedStages(*context.grid, config, carved, stages);
}

bool IsDefaultStages(const SweepContext& context, const std::vector<StageOptions>& stages) {
  return NormalizedStages(stages, static_cast<int>(context.dataset.views.size())) ==
         context.default_stages;
}

Status RunCell(const SweepContext& context, const SweepCell& cell, const std::string& dir,
               const CellCallbacks& callbacks, json* line, bool* interrupted) {
  *interrupted = false;
  *line = {{"id", cell.id}, {"index", cell.index}, {"settings", cell.settings}};
  auto fail = [&](const Status& status) {
    (*line)["status"] = "error";
    (*line)["error"] = status.message();
    return Status::Ok();
  };
  CellStart start;
  Status status = LoadCellStart(context, cell, &start);
  if (!status.ok()) return fail(status.Prefixed("start"));
  std::vector<StageOptions> stages;
  status = CellStages(context, cell, &stages);
  if (!status.ok()) return fail(status);
  (*line)["default"] = IsDefaultStages(context, stages);
  status = Reconstruct(context, start, stages, dir, callbacks, line, interrupted);
  if (*interrupted) return Status::Ok();
  if (!status.ok()) return fail(status);
  std::vector<int> views;
  status =
      SelectViews(stages.back().fit.views, static_cast<int>(context.dataset.views.size()), &views);
  if (!status.ok()) return fail(status);
  (*line)["views"] = views.size();
  const double scoring_start = NowSeconds();
  status = ScoreCell(context, dir, views, line);
  if (!status.ok()) return fail(status.Prefixed("scoring"));
  (*line)["eval_seconds"] = NowSeconds() - scoring_start;
  (*line)["status"] = "ok";
  return Status::Ok();
}

}  // namespace sft
