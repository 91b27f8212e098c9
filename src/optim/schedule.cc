#include "src/optim/schedule.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/init/self_intersection.h"
#include "src/init/untangle.h"
#include "src/io/scene_setup.h"
#include "src/optim/fitted_environment.h"
#include "src/optim/run_outputs.h"
#include "src/optim/schedule_config.h"
#include "src/optim/uv_stage.h"

namespace sft {
namespace {

using json = nlohmann::json;

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr char kBaselineMesh[] = "baseline_mesh.ply";

// Normals in [0, 1] colours ((n + 1) / 2), background black.
Image NormalColours(const Image& normals) {
  Image out(normals.width, normals.height, 3);
  for (int y = 0; y < normals.height; ++y) {
    for (int x = 0; x < normals.width; ++x) {
      const bool hit = normals.channels < 4 || normals.at(x, y, 3) > 0.0f;
      for (int c = 0; c < 3; ++c) {
        out.at(x, y, c) = hit ? 0.5f * (normals.at(x, y, c) + 1.0f) : 0.0f;
      }
    }
  }
  return out;
}

}  // namespace

bool StageOptions::Check(std::string* why) const {
  if (name.empty()) {
    *why = "name: must not be empty";
    return false;
  }
  if ((texel_resolution < 0 && texel_resolution != kTexelResolutionAuto) || texel_resolution > 64) {
    *why = "texel_resolution: must be in [0, 64] or auto";
    return false;
  }
  if (material_model != "mesh_colors" && material_model != "uv") {
    *why = "material_model: expected \"mesh_colors\" or \"uv\", got \"" + material_model + "\"";
    return false;
  }
  if (texture_size != 0 && (texture_size < 64 || texture_size > 16384)) {
    *why = "texture_size: must be in [64, 16384] (0 = from the pixel footprint)";
    return false;
  }

  if (!(restart_roughness >= 0.0 && restart_roughness <= 1.0) ||
      !(restart_specular >= 0.0 && restart_specular <= 1.0)) {
    *why = "restart_roughness, restart_specular: must be in [0, 1] (0 = keep)";
    return false;
  }
  return fit.Check(why) && topology.Check(why);
}

int64_t Schedule::StepWork(const StageOptions& stage, int dataset_views) {
  // Relative cost of one solver step: pixels (4^-k of the dataset's) × spp, 1000 units for a
  // full-scale step at 16 spp; every phase of an outer iteration counts `steps` steps. An Adam
  // step with a minibatch renders views_per_step of the fitted views.
  const double pixels = std::ldexp(1.0, -2 * stage.fit.cache.image_scale_log2);
  double share = 1.0;
  const int batch = stage.fit.solver.adam.views_per_step;
  const int fitted =
      stage.fit.views.empty() ? dataset_views : static_cast<int>(stage.fit.views.size());
  if (stage.fit.solver.kind == SolverKind::kAdam && batch > 0 && fitted > batch) {
    share = static_cast<double>(batch) / fitted;
  }
  return std::max<int64_t>(
      1, std::llround(1000.0 * pixels * share * stage.fit.cache.render.spp / 16.0));
}

int Schedule::WorkViews() const {
  return dataset_ ? static_cast<int>(dataset_->views.size()) : work_views_;
}

int64_t Schedule::CurrentStepWork() const { return StepWork(CurrentStage(), WorkViews()); }

int Schedule::WorkKindOf(const StageOptions& stage, const std::string& phase) {
  return (stage.fit.solver.kind == SolverKind::kAdam ? 2 : 0) + (phase == "geometry" ? 1 : 0);
}

std::vector<int64_t> Schedule::RemainingWorkByKind() const {
  std::vector<int64_t> work(kNumWorkKinds, 0);
  for (size_t s = progress_.stage; s < stages_.size(); ++s) {
    const StageOptions& stage = stages_[s];
    const int outers = stage.fit.outer_iterations -
                       (static_cast<int>(s) == progress_.stage ? progress_.stage_outer_done : 0);
    const int64_t phase_work =
        static_cast<int64_t>(outers) * stage.fit.solver.steps * StepWork(stage, WorkViews());
    const bool texture = stage.fit.phases != PhaseSchedule::kGeometry;
    const bool geometry = stage.fit.phases != PhaseSchedule::kTexture;
    if (texture) work[WorkKindOf(stage, "texture")] += phase_work;
    if (geometry) work[WorkKindOf(stage, "geometry")] += phase_work;
  }
  return work;
}

int64_t Schedule::RemainingWork() const {
  const std::vector<int64_t> work = RemainingWorkByKind();
  return std::accumulate(work.begin(), work.end(), int64_t{0});
}

std::vector<int64_t> Schedule::TotalWorkByKind(const std::vector<StageOptions>& stages,
                                               int dataset_views) {
  Schedule fresh;
  fresh.stages_ = stages;
  fresh.work_views_ = dataset_views;
  return fresh.RemainingWorkByKind();
}

int64_t Schedule::TotalWork(const std::vector<StageOptions>& stages, int dataset_views) {
  const std::vector<int64_t> work = TotalWorkByKind(stages, dataset_views);
  return std::accumulate(work.begin(), work.end(), int64_t{0});
}

Status Schedule::Start(const Dataset& dataset, const std::string& out,
                       const std::vector<StageOptions>& stages, const ScheduleStart& start,
                       const json& run_info, std::unique_ptr<Schedule>* schedule) {
  if (stages.empty()) return Status::Error("the schedule has no stages");
  std::unique_ptr<Schedule> s(new Schedule());
  s->dataset_ = &dataset;
  s->out_ = out;
  s->stages_ = stages;
  s->run_info_ = run_info;
  s->current_ = start;
  const int fitted_light = FittedEnvironmentLight(dataset);
  if (s->current_.environment.empty() && fitted_light >= 0) {
    s->current_.environment = dataset.lights[fitted_light].pixels;
  }
  s->baseline_ = start.mesh;
  SFT_RETURN_IF_ERROR(MakeDirectories(out));
  SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(out, "initial_mesh.ply"), start.mesh));
  SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(out, kBaselineMesh), start.mesh));
  // Their start, once: the fitted values go to lights.json with every checkpoint.
  SFT_RETURN_IF_ERROR(WriteEstimatedLights(out, dataset));
  *schedule = std::move(s);
  return Status::Ok();
}

Status Schedule::Resume(const Dataset& dataset, const std::string& out,
                        const std::vector<StageOptions>& stages, const json& run_info,
                        const ScheduleProgress& progress,
                        const std::vector<Eigen::Vector3d>& view_gains,
                        std::unique_ptr<Schedule>* schedule) {
  std::unique_ptr<Schedule> s(new Schedule());
  s->dataset_ = &dataset;
  s->out_ = out;
  s->stages_ = stages;
  s->run_info_ = run_info;
  s->progress_ = progress;
  s->progress_.stage_outers_done.resize(stages.size(), 0);
  ScheduleProgress& p = s->progress_;
  // A finished run whose last stage was given more outer iterations (--outer on resume)
  // continues that stage.
  if (p.stage >= static_cast<int>(stages.size()) &&
      stages.back().fit.outer_iterations > p.stage_outers_done.back()) {
    p.stage = static_cast<int>(stages.size()) - 1;
    p.stage_outer_done = p.stage_outers_done.back();
    p.stage_prepared = true;
  }
  SFT_RETURN_IF_ERROR(ReadRunSnapshot(out, dataset, &s->current_.mesh, &s->current_.material,
                                      &s->current_.light_scales, &s->current_.light_positions,
                                      &s->current_.light_directions,
                                      &s->current_.environment_rotations));
  if (!view_gains.empty() && view_gains.size() != dataset.views.size()) {
    return Status::Error(JoinPath(out, "state.json") +
                         ": exposure_gains: " + std::to_string(view_gains.size()) +
                         " views, the dataset has " + std::to_string(dataset.views.size()));
  }
  s->current_.view_gains = view_gains;
  bool have_poses = false;
  SFT_RETURN_IF_ERROR(
      ReadPoses(JoinPath(out, kPosesFile), dataset, &s->current_.view_poses, &have_poses));
  // The caller gave the fitted light the checkpoint's map (kFittedEnvironmentFile).
  if (FittedEnvironmentLight(dataset) >= 0) {
    s->current_.environment = dataset.lights[FittedEnvironmentLight(dataset)].pixels;
  }
  const std::string baseline = JoinPath(out, kBaselineMesh);
  SFT_RETURN_IF_ERROR(
      ReadMesh(FileExists(baseline) ? baseline : JoinPath(out, "mesh.ply"), &s->baseline_));
  if (s->baseline_.n_faces() != s->current_.mesh.n_faces()) {
    return Status::Error(baseline + ": " + std::to_string(s->baseline_.n_faces()) +
                         " faces, the checkpoint's mesh.ply has " +
                         std::to_string(s->current_.mesh.n_faces()));
  }
  SFT_RETURN_IF_ERROR(ReadIterationRecords(out, &s->records_));
  json metrics;
  SFT_RETURN_IF_ERROR(ReadMetricsJson(out, &metrics));
  if (metrics.contains("outer") && metrics["outer"].is_array())
    s->outer_records_ = metrics["outer"];
  if (metrics.contains("topology_changes") && metrics["topology_changes"].is_array()) {
    s->topology_records_ = metrics["topology_changes"];
  }
  if (metrics.contains("stages") && metrics["stages"].is_array()) {
    s->stage_records_ = metrics["stages"];
  }
  if (metrics.contains("material_switches") && metrics["material_switches"].is_array()) {
    s->material_records_ = metrics["material_switches"];
  }
  // Older run folders have no adam_state.bin: their Adam stages resume with fresh moments.
  auto saved_adam = std::make_unique<AdamCheckpoint>();
  bool found = false;
  SFT_RETURN_IF_ERROR(ReadAdamCheckpoint(out, saved_adam.get(), &found));
  if (found) s->saved_adam_ = std::move(saved_adam);
  *schedule = std::move(s);
  return Status::Ok();
}

double Schedule::Elapsed() const { return seconds_at_start_ + NowSeconds() - session_start_; }

Status Schedule::CreateReconstruction() {
  const StageOptions& stage = stages_[progress_.stage];
  SFT_RETURN_IF_ERROR(Reconstruction::Create(
      *dataset_, current_.mesh, current_.material, current_.light_scales, stage.fit,
      &reconstruction_, current_.view_gains, current_.environment, current_.light_positions,
      current_.light_directions, current_.environment_rotations, current_.view_poses));
  reconstruction_->elapsed_offset = Elapsed();
  reconstruction_stage_ = progress_.stage;
  phases_seen_ = 0;
  return Status::Ok();
}

// Gives the fit of a resumed stage the Adam moments of the checkpoint, when they belong to it:
// the same stage and outer iteration (else the stage changed, or a crash left state.json behind
// the moments) and the same parameter layout.
void Schedule::RestoreAdamState(const ScheduleCallbacks& callbacks) {
  if (!saved_adam_) return;
  const std::unique_ptr<AdamCheckpoint> saved = std::move(saved_adam_);
  if (saved->state.m.empty()) return;
  const std::string name = JoinPath(out_, kAdamStateFile);
  std::string line;
  if (saved->stage != progress_.stage || saved->outer_done != progress_.outer_done) {
    line = name + ": moments of stage " + std::to_string(saved->stage + 1) + " after outer " +
           std::to_string(saved->outer_done) + ", the run stands at stage " +
           std::to_string(progress_.stage + 1) + " after outer " +
           std::to_string(progress_.outer_done) + ": Adam starts fresh";
  } else if (!reconstruction_->SetAdamState(saved->state)) {
    line = name + ": " + std::to_string(saved->state.m.size()) +
           " moments do not match the parameters: Adam starts fresh";
  } else {
    line = "resume: Adam's moments restored (step " + std::to_string(saved->state.t) + ")";
  }
  if (callbacks.on_event) callbacks.on_event(line);
}

void Schedule::SyncCurrent() {
  if (!reconstruction_) return;
  current_.mesh = reconstruction_->Mesh();
  current_.material = reconstruction_->CurrentMaterial();
  current_.light_scales = reconstruction_->LightScales();
  std::vector<Eigen::Vector3d> light_positions = reconstruction_->LightPositions();
  if (!light_positions.empty()) current_.light_positions = std::move(light_positions);
  std::vector<Eigen::Vector3d> light_directions = reconstruction_->LightDirections();
  if (!light_directions.empty()) current_.light_directions = std::move(light_directions);
  std::vector<Eigen::Vector3d> rotations = reconstruction_->EnvironmentRotations();
  if (!rotations.empty()) current_.environment_rotations = std::move(rotations);
  current_.view_gains = reconstruction_->ViewGains();
  current_.view_poses = reconstruction_->ViewPoses();
  Image environment = reconstruction_->EnvironmentTexels();
  if (!environment.empty()) current_.environment = std::move(environment);
}

Status Schedule::ChangeTopology(TopologyChange change, const ScheduleCallbacks& callbacks) {
  const StageOptions& stage = stages_[progress_.stage];
  std::vector<int> views;
  SFT_RETURN_IF_ERROR(
      SelectViews(stage.fit.views, static_cast<int>(dataset_->views.size()), &views));
  const int faces_before = static_cast<int>(current_.mesh.n_faces());
  const double start = NowSeconds();
  json record;
  // Topology changes carry mesh colors across; UV textures are sampled into them first and the
  // atlas is rebuilt on the new mesh below.
  if (current_.material.has_uv_textures()) {
    SwitchToMeshColors(ResolveTexelResolution(kTexelResolutionAuto, 1, current_.mesh, *dataset_,
                                              views, stage.fit.cache.image_scale_log2),
                       &current_.material);
  }
  SFT_RETURN_IF_ERROR(ApplyTopologyChange(
      change, stage.topology, *dataset_, views, stage.fit.cache.image_scale_log2,
      stage.texel_resolution, &current_.mesh, &current_.material, &record, held_out_views_));
  record["stage"] = stage.name;
  record["outer"] = progress_.outer_done;
  record["seconds"] = NowSeconds() - start;
  record["at_seconds"] = Elapsed();
  topology_records_.push_back(record);
  ++progress_.topology_changes;
  baseline_ = current_.mesh;
  image_signal_scale_ = step_signal_scale_ = 0.0;
  SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(out_, kBaselineMesh), baseline_));
  if (callbacks.on_event) {
    char line[256];
    std::snprintf(line, sizeof(line), "%s: %s, %d -> %zu faces in %.1f s", stage.name.c_str(),
                  change == TopologyChange::kRemesh ? ("remesh " + stage.topology.remesh).c_str()
                                                    : "resample",
                  faces_before, current_.mesh.n_faces(), record["seconds"].get<double>());
    callbacks.on_event(line);
  }
  return stage.material_model == "uv" ? SwitchMaterialModel(callbacks) : Status::Ok();
}

// Brings the material into the stage's model: a UV atlas baked from the mesh colors for a uv
// stage, mesh colors sampled from the textures for a mesh-colors stage (no-op when it is there).
Status Schedule::SwitchMaterialModel(const ScheduleCallbacks& callbacks) {
  const StageOptions& stage = stages_[progress_.stage];
  const bool uv = stage.material_model == "uv";
  if (uv == current_.material.has_uv_textures()) return Status::Ok();
  json record;
  if (uv) {
    SFT_RETURN_IF_ERROR(SwitchToUvTextures(current_.mesh, *dataset_, stage.texture_size,
                                           &current_.material, &record));
  } else {
    std::vector<int> views;
    SFT_RETURN_IF_ERROR(
        SelectViews(stage.fit.views, static_cast<int>(dataset_->views.size()), &views));
    const int resolution = ResolveTexelResolution(
        stage.texel_resolution == 0 ? kTexelResolutionAuto : stage.texel_resolution, 1,
        current_.mesh, *dataset_, views, stage.fit.cache.image_scale_log2);
    SwitchToMeshColors(resolution, &current_.material);
    record = {{"resolution", resolution}};
  }
  record["to"] = stage.material_model;
  record["stage"] = stage.name;
  record["outer"] = progress_.outer_done;
  material_records_.push_back(record);
  if (callbacks.on_event) {
    char line[256];
    if (uv) {
      std::snprintf(line, sizeof(line),
                    "%s: UV atlas %d² (%s), %d charts, %.0f%% used, %d texels fitted, %.1f s",
                    stage.name.c_str(), record["texture_size"].get<int>(),
                    record["texture_size_from"].get<std::string>().c_str(),
                    record["charts"].get<int>(), 100.0 * record["utilization"].get<double>(),
                    record["fitted_texels"].get<int>(), record["seconds"].get<double>());
    } else {
      std::snprintf(line, sizeof(line), "%s: UV textures sampled into mesh colours, resolution %d",
                    stage.name.c_str(), record["resolution"].get<int>());
    }
    callbacks.on_event(line);
  }
  return Status::Ok();
}

Status Schedule::PrepareStage(const ScheduleCallbacks& callbacks) {
  SyncCurrent();
  image_signal_scale_ = step_signal_scale_ = 0.0;
  const StageOptions& stage = stages_[progress_.stage];
  if (callbacks.on_event) {
    char line[256];
    std::snprintf(line, sizeof(line),
                  "stage %d/%zu %s: %s at 1/%d scale, %d spp, %d outer x %d steps",
                  progress_.stage + 1, stages_.size(), stage.name.c_str(),
                  PhaseScheduleName(stage.fit.phases), 1 << stage.fit.cache.image_scale_log2,
                  stage.fit.cache.render.spp, stage.fit.outer_iterations, stage.fit.solver.steps);
    callbacks.on_event(line);
  }
  if (stage.topology.remesh != "none") {
    SFT_RETURN_IF_ERROR(ChangeTopology(TopologyChange::kRemesh, callbacks));
  }
  if (stage.topology.resample) {
    SFT_RETURN_IF_ERROR(ChangeTopology(TopologyChange::kResample, callbacks));
  }
  if (stage.material_model != "uv") SFT_RETURN_IF_ERROR(SwitchMaterialModel(callbacks));
  std::vector<int> views;
  SFT_RETURN_IF_ERROR(
      SelectViews(stage.fit.views, static_cast<int>(dataset_->views.size()), &views));
  const int resolution =
      ResolveTexelResolution(stage.texel_resolution, current_.material.albedo.resolution(),
                             current_.mesh, *dataset_, views, stage.fit.cache.image_scale_log2);
  // A uv stage resamples the mesh colors before they are baked (texel_resolution as usual).
  if (!current_.material.has_uv_textures() && resolution != current_.material.albedo.resolution()) {
    current_.material = ResampleMaterial(current_.material, resolution);
    if (callbacks.on_event) {
      callbacks.on_event("texels: mesh-colours resolution " + std::to_string(resolution) +
                         (stage.texel_resolution == kTexelResolutionAuto ? " (auto)" : ""));
    }
  }
  if (stage.material_model == "uv") SFT_RETURN_IF_ERROR(SwitchMaterialModel(callbacks));
  RestartLobe(stage, callbacks);
  progress_.stage_prepared = true;
  return CreateReconstruction();
}

// The stage's restart of the glossy lobe (StageOptions::restart_roughness, restart_specular).
void Schedule::RestartLobe(const StageOptions& stage, const ScheduleCallbacks& callbacks) {
  if (stage.restart_roughness > 0.0) {
    std::vector<double>& values = current_.material.RoughnessValues();
    std::fill(values.begin(), values.end(), stage.restart_roughness);
  }
  if (stage.restart_specular > 0.0) current_.material.specular = stage.restart_specular;
  if ((stage.restart_roughness > 0.0 || stage.restart_specular > 0.0) && callbacks.on_event) {
    char line[128];
    std::snprintf(line, sizeof(line), "restart: roughness %g, specular %g (0 = kept)",
                  stage.restart_roughness, stage.restart_specular);
    callbacks.on_event(line);
  }
}

// Smooths away the self-intersections a geometry phase left (StageOptions::topology.untangle);
// `record` gets the counts when there were any. The reconstruction is rebuilt on the moved
// vertices (the topology is unchanged, so texels and the folded-face baseline carry over).
Status Schedule::UntangleCurrent(const ScheduleCallbacks& callbacks, json* record) {
  if (CountSelfIntersectingFaces(current_.mesh) <= 0) return Status::Ok();
  const double start = NowSeconds();
  UntangleReport report;
  const Status status = Untangle(UntangleOptions(), &current_.mesh, &report);
  if (!status.ok()) {
    // Not a reason to stop the run: resampling remains the remedy for what cannot be listed.
    if (callbacks.on_event) callbacks.on_event("untangle skipped: " + status.message());
    return Status::Ok();
  }
  *record = {{"faces_before", report.faces_before},
             {"faces_after", report.faces_after},
             {"rounds", report.rounds},
             {"moved_vertices", report.moved_vertices},
             {"seconds", NowSeconds() - start}};
  if (callbacks.on_event) {
    char line[256];
    std::snprintf(line, sizeof(line),
                  "%s: untangle: %d -> %d self-intersecting faces, %d vertices moved in %.1f s",
                  CurrentStage().name.c_str(), report.faces_before, report.faces_after,
                  report.moved_vertices, NowSeconds() - start);
    callbacks.on_event(line);
  }
  // Unchanged when no round improved on the input.
  return report.faces_after < report.faces_before ? CreateReconstruction() : Status::Ok();
}

// metrics.json's per-outer entry: cost, time, faces, mesh quality against the baseline and the
// callbacks' scores.
Status Schedule::OuterRecord(const ScheduleCallbacks& callbacks, int outer, json* out) {
  const StageOptions& stage = stages_[progress_.stage];
  const MeshQuality quality = CompareMeshQuality(baseline_, current_.mesh);
  const int self_intersecting = CountSelfIntersectingFaces(current_.mesh);
  const IterationRecord* last = records_.empty() ? nullptr : &records_.back();
  *out = {{"outer", outer},
          {"stage", stage.name},
          {"seconds", last ? last->seconds : Elapsed()},
          {"cost", last ? last->cost : 0.0},
          {"faces", current_.mesh.n_faces()},
          {"flipped_faces", quality.flipped_faces},
          {"degenerate_faces", quality.degenerate_faces},
          {"self_intersecting_faces", self_intersecting}};
  json dropped = json::array();
  const std::vector<PhaseRecord>& phases = reconstruction_->phases();
  for (size_t p = phases_seen_; p < phases.size(); ++p) {
    dropped.push_back(phases[p].stats.dropped_jacobian_fraction);
    phase_records_.push_back(phases[p]);
  }
  phases_seen_ = phases.size();
  (*out)["dropped_jacobian_fraction"] = dropped;
  if (callbacks.score) {
    json extra;
    SFT_RETURN_IF_ERROR(callbacks.score(current_.mesh, &extra));
    if (extra.is_object()) out->update(extra);
  }
  return Status::Ok();
}

Status Schedule::FinishStage() {
  const StageOptions& stage = stages_[progress_.stage];
  char name[256];
  std::snprintf(name, sizeof(name), "stages/%02d_%s_normals.png", progress_.stage,
                stage.name.c_str());
  SFT_RETURN_IF_ERROR(MakeDirectories(JoinPath(out_, "stages")));
  const Image normals = reconstruction_->RenderNormals(0);
  SFT_RETURN_IF_ERROR(WritePng(JoinPath(out_, name), NormalColours(normals), /*srgb=*/false));
  stage_records_.push_back({{"stage", stage.name},
                            {"index", progress_.stage},
                            {"end_seconds", Elapsed()},
                            {"faces", current_.mesh.n_faces()},
                            {"normals", name}});
  ++progress_.stage;
  progress_.stage_outer_done = 0;
  progress_.stage_prepared = false;
  return Status::Ok();
}

// The effect planner before an outer iteration (when the stage's effects are "auto"): console
// lines for what changed, the report for metrics.json.
Status Schedule::PlanEffects(const ScheduleCallbacks& callbacks, json* record) {
  const StageOptions& stage = stages_[progress_.stage];
  if (!stage.fit.planner.enabled) return Status::Ok();
  EffectPlanReport report;
  SFT_RETURN_IF_ERROR(reconstruction_->PlanEffects(progress_.outer_done, &report,
                                                   image_signal_scale_, step_signal_scale_));
  image_signal_scale_ = std::max(image_signal_scale_, report.image_signal);
  step_signal_scale_ = std::max(step_signal_scale_, report.step_signal);
  if (callbacks.on_event) {
    for (const std::string& line : PlanChangeLines(report, last_plan_.get())) {
      callbacks.on_event(stage.name + ": " + line);
    }
  }
  *record = report.ToJson();
  last_plan_ = std::make_unique<EffectPlanReport>(report);
  return Status::Ok();
}

namespace {

// One console line per environment light of a fitted rotation: the angle and axis (in the
// probe's frame) it is turned by from the dataset's alignment.
std::vector<std::string> ProbeRotationLines(const Dataset& dataset,
                                            const std::vector<Eigen::Vector3d>& rotations) {
  std::vector<std::string> lines;
  for (size_t l = 0; l < rotations.size() && l < dataset.lights.size(); ++l) {
    if (dataset.lights[l].type != LightType::kEnvironment) continue;
    const Eigen::Vector3d& theta = rotations[l];
    const double angle = theta.norm();
    const Eigen::Vector3d axis =
        angle > 0.0 ? Eigen::Vector3d(theta / angle) : Eigen::Vector3d::UnitZ();
    char line[256];
    std::snprintf(line, sizeof(line),
                  "probe \"%s\" turned %.3f deg about (%.3f, %.3f, %.3f) (%s frame)",
                  dataset.lights[l].id.c_str(), angle * 180.0 / M_PI, axis.x(), axis.y(), axis.z(),
                  dataset.lights[l].frame == LightFrame::kCamera ? "camera" : "world");
    lines.push_back(line);
  }
  return lines;
}

}  // namespace

Status Schedule::RunStageOuter(const ScheduleCallbacks& callbacks, bool* stop) {
  const StageOptions& stage = stages_[progress_.stage];
  const int outer = progress_.outer_done;
  json plan_record;
  SFT_RETURN_IF_ERROR(PlanEffects(callbacks, &plan_record));
  const auto on_iteration = [&](const IterationRecord& record) {
    IterationRecord r = record;
    r.stage = stage.name;
    records_.push_back(r);
    const bool go_on = !callbacks.on_iteration || callbacks.on_iteration(r);
    *stop = *stop || !go_on;
    return go_on;
  };
  // A failure names its stage: the fix is usually one of that stage's keys.
  SFT_RETURN_IF_ERROR(
      reconstruction_->RunOuter(outer, on_iteration).Prefixed("stage " + stage.name));
  SyncCurrent();
  if (callbacks.on_event && stage.fit.fit_environment_rotation) {
    for (const std::string& line : ProbeRotationLines(*dataset_, current_.environment_rotations)) {
      callbacks.on_event(stage.name + ": " + line);
    }
  }
  json untangled;
  if (!*stop && stage.topology.untangle && stage.fit.phases != PhaseSchedule::kTexture) {
    SFT_RETURN_IF_ERROR(UntangleCurrent(callbacks, &untangled));
  }
  if (!*stop) {
    ++progress_.outer_done;
    ++progress_.stage_outer_done;
    progress_.stage_outers_done.resize(stages_.size(), 0);
    progress_.stage_outers_done[progress_.stage] = progress_.stage_outer_done;
  }
  json record;
  SFT_RETURN_IF_ERROR(OuterRecord(callbacks, outer, &record));
  if (!plan_record.is_null()) record["effects"] = plan_record;
  if (!untangled.is_null()) record["untangle"] = untangled;
  outer_records_.push_back(record);
  const bool stage_done = progress_.stage_outer_done >= stage.fit.outer_iterations;
  // CountSelfIntersectingFaces is -1 when CGAL fails: no evidence of folds then.
  const int folds = record["flipped_faces"].get<int>() +
                    std::max(0, record["self_intersecting_faces"].get<int>());
  if (!*stop && !stage_done && stage.topology.resample_fold_fraction > 0.0 &&
      folds > stage.topology.resample_fold_fraction * current_.mesh.n_faces()) {
    SFT_RETURN_IF_ERROR(ChangeTopology(TopologyChange::kResample, callbacks));
    SFT_RETURN_IF_ERROR(CreateReconstruction());
  }
  if (!*stop && stage_done) SFT_RETURN_IF_ERROR(FinishStage());
  return Checkpoint();
}

Status Schedule::Checkpoint() {
  progress_.seconds = Elapsed();
  SFT_RETURN_IF_ERROR(WriteRunSnapshot(out_, *dataset_, current_.mesh, current_.material,
                                       current_.light_scales, current_.light_positions,
                                       current_.light_directions, current_.environment_rotations));
  if (!current_.environment.empty()) {
    const LightSpec& light = dataset_->lights.at(FittedEnvironmentLight(*dataset_));
    SFT_RETURN_IF_ERROR(WriteFittedEnvironment(out_, current_.environment, light.frame));
  }
  // Before state.json (the commit point): see src/optim/adam_checkpoint.h.
  if (reconstruction_ && !reconstruction_->adam_state().m.empty()) {
    AdamCheckpoint adam;
    adam.stage = reconstruction_stage_;
    adam.outer_done = progress_.outer_done;
    adam.state = reconstruction_->adam_state();
    SFT_RETURN_IF_ERROR(WriteAdamCheckpoint(out_, adam));
  } else {
    RemoveAdamCheckpoint(out_);  // no moments (yet) in this fit: none from an earlier one.
  }
  json info = run_info_;
  info["outer"] = outer_records_;
  info["topology_changes"] = topology_records_;
  info["stages"] = stage_records_;
  info["material_switches"] = material_records_;
  info["held_out_views"] = held_out_views_;
  if (extra_metrics_) info.update(extra_metrics_());
  SFT_RETURN_IF_ERROR(WriteMetrics(out_, records_, phase_records_, info));
  RunState state;
  // Gains are part of the state once a stage fits them (or a resumed run brought some).
  bool exposure = false;
  for (const StageOptions& s : stages_) exposure = exposure || s.fit.fit_exposure;
  for (const Eigen::Vector3d& g : current_.view_gains) {
    exposure = exposure || g != Eigen::Vector3d::Ones();
  }
  if (exposure && !current_.view_gains.empty()) {
    state.view_gains = current_.view_gains;
    const int gauge = reconstruction_ ? reconstruction_->view_indices()[kExposureGaugeView] : -1;
    SFT_RETURN_IF_ERROR(WriteExposure(out_, *dataset_, current_.view_gains, gauge));
  }
  // Poses likewise, in poses.json (which --resume reads back).
  bool poses = false;
  for (const StageOptions& s : stages_) poses = poses || s.fit.fit_poses;
  for (const PoseDelta& d : current_.view_poses) poses = poses || !d.isZero(0.0);
  if (poses && !current_.view_poses.empty()) {
    const int gauge = reconstruction_ ? reconstruction_->view_indices()[kPoseGaugeView] : -1;
    SFT_RETURN_IF_ERROR(WritePoses(out_, *dataset_, current_.view_poses, gauge));
  }
  state.run_info = run_info_;
  for (const StageOptions& s : stages_) state.stages.push_back(StageJson(s));
  state.progress = progress_;
  state.finished = finished();
  state.holdout = holdout_;
  state.held_out_views = held_out_views_;
  return WriteRunState(out_, state);
}

Status Schedule::Run(const ScheduleCallbacks& callbacks) {
  session_start_ = NowSeconds();
  seconds_at_start_ = progress_.seconds;
  stopped_ = false;
  while (!finished()) {
    if (!progress_.stage_prepared) {
      SFT_RETURN_IF_ERROR(PrepareStage(callbacks));
    } else if (!reconstruction_) {  // resumed within a stage.
      SFT_RETURN_IF_ERROR(CreateReconstruction());
      RestoreAdamState(callbacks);
    }
    if (progress_.stage_outer_done >= CurrentStage().fit.outer_iterations) {
      // Resumed with fewer outer iterations than this stage already ran.
      SFT_RETURN_IF_ERROR(FinishStage());
      SFT_RETURN_IF_ERROR(Checkpoint());
      continue;
    }
    bool stop = false;
    SFT_RETURN_IF_ERROR(RunStageOuter(callbacks, &stop));
    if (stop) {
      stopped_ = true;
      return Status::Ok();
    }
  }
  if (!reconstruction_) {  // resumed a finished run: the report still needs the final state.
    progress_.stage = static_cast<int>(stages_.size()) - 1;
    SFT_RETURN_IF_ERROR(CreateReconstruction());
    progress_.stage = static_cast<int>(stages_.size());
  }
  return Status::Ok();
}

}  // namespace sft
