#include "src/optim/reconstruct.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cost_functions/proximal_smoothing.h"
#include "src/geometry/uv_texel_charts.h"
#include "src/optim/fitted_environment.h"
#include "src/optim/problem.h"

namespace sft {
namespace {

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

ActiveParameters TexturePhase(const ReconstructOptions& options) {
  ActiveParameters active;
  active.vertices = false;
  active.albedo = options.fit_albedo;
  active.roughness = options.fit_roughness;
  active.specular = options.fit_specular;
  active.lights = options.fit_lights;
  active.light_positions = options.fit_light_positions;
  active.light_directions = options.fit_light_directions;
  active.environment_rotations = options.fit_environment_rotation;
  active.exposure = options.fit_exposure;
  active.poses = options.fit_poses;
  active.environment = options.fit_environment;
  return active;
}

ActiveParameters GeometryPhase() {
  ActiveParameters active;
  active.vertices = true;
  active.albedo = active.roughness = active.specular = active.lights = false;
  return active;
}

// Light positions (directions) are parameters whenever an earlier fit moved them (`positions`,
// `directions` not empty: one per dataset light) or this fit fits them (starting at the
// dataset's).
Status AddLightGeometry(const Dataset& dataset, const ReconstructOptions& options,
                        const std::vector<Eigen::Vector3d>& positions,
                        const std::vector<Eigen::Vector3d>& directions, SceneParameters* params) {
  const size_t num_lights = dataset.lights.size();
  for (const bool direction : {false, true}) {
    const std::vector<Eigen::Vector3d>& given = direction ? directions : positions;
    bool fit = direction ? options.fit_light_directions : options.fit_light_positions;
    // A pose fit contracts the rows of world-fixed lights (pose_corrections.h): they must be
    // parameters, held when not fitted.
    const LightType type = direction ? LightType::kDirectional : LightType::kPoint;
    for (const LightSpec& light : dataset.lights) {
      fit = fit || (options.fit_poses && light.type == type && light.frame == LightFrame::kWorld);
    }
    if (!fit && given.empty()) continue;
    if (!given.empty() && given.size() != num_lights) {
      return Status::Error(std::string(direction ? "light directions: " : "light positions: ") +
                           std::to_string(given.size()) + " given, the dataset has " +
                           std::to_string(num_lights) + " lights");
    }
    std::vector<Eigen::Vector3d> start = given;
    if (start.empty()) {
      for (const LightSpec& light : dataset.lights) {
        start.push_back(direction ? light.direction : light.position);
      }
    }
    if (direction) {
      params->AddLightDirections(start);
    } else {
      params->AddLightPositions(start);
    }
  }
  return Status::Ok();
}

// Environment rotations are parameters whenever an earlier fit turned a probe (`rotations` not
// empty) or this fit refines them (starting at 0, the dataset's alignment), and whenever a pose fit
// turns a world-fixed map relative to the camera (pose_corrections.h). Only given probes have an
// alignment to refine: a fitted environment's texels are the map in its own frame, so its rotation
// is held at 0 and serves the pose chain only (the texels would absorb any turn).
Status AddEnvironmentRotations(const Dataset& dataset, const ReconstructOptions& options,
                               const std::vector<Eigen::Vector3d>& rotations,
                               SceneParameters* params) {
  bool world_probe = false;
  for (const LightSpec& light : dataset.lights) {
    world_probe =
        world_probe || (light.type == LightType::kEnvironment && light.frame == LightFrame::kWorld);
  }
  const bool needed = options.fit_environment_rotation || (options.fit_poses && world_probe);
  if (!needed && rotations.empty()) return Status::Ok();
  const size_t num_lights = dataset.lights.size();
  if (!rotations.empty() && rotations.size() != num_lights) {
    return Status::Error("environment rotations: " + std::to_string(rotations.size()) +
                         " given, the dataset has " + std::to_string(num_lights) + " lights");
  }
  const int fitted = FittedEnvironmentLight(dataset);
  if (fitted >= 0 && options.fit_environment_rotation) {
    return Status::Error(
        "fit_environment_rotation: the lighting is unknown (a fitted environment); only a given "
        "probe's alignment can be refined");
  }
  if (fitted >= 0 && !rotations.empty() && !rotations[fitted].isZero(0.0)) {
    return Status::Error("environment rotations: the fitted environment's rotation must be 0");
  }
  bool any_probe = false;
  for (const LightSpec& light : dataset.lights) any_probe |= light.type == LightType::kEnvironment;
  if (!any_probe) {
    return Status::Error("fit_environment_rotation: the dataset has no environment light");
  }
  params->AddEnvironmentRotations(
      rotations.empty() ? std::vector<Eigen::Vector3d>(num_lights, Eigen::Vector3d::Zero())
                        : rotations);
  return Status::Ok();
}

// Pose corrections are parameters whenever an earlier fit corrected a pose (`poses` not all zero)
// or this fit refines them. A camera-fixed probe would turn with every pose change: refused.
Status AddPoses(const Dataset& dataset, const ReconstructOptions& options,
                const std::vector<int>& views, const std::vector<PoseDelta>& poses,
                SceneParameters* params) {
  bool any = options.fit_poses;
  for (int v : views) any = any || !poses[v].isZero(0.0);
  if (!any) return Status::Ok();
  for (const LightSpec& light : dataset.lights) {
    if (light.type == LightType::kEnvironment && light.frame == LightFrame::kCamera) {
      if (light.id == kFittedEnvironmentId) {
        return Status::Error(
            "fit_poses: the fitted environment is camera-fixed (environment_frame camera); "
            "refining poses under it is not supported");
      }
      return Status::Error("fit_poses: light '" + light.id +
                           "' is a camera-fixed environment; refining poses under it is not "
                           "supported");
    }
  }
  params->AddPoses(static_cast<int>(views.size()));
  for (size_t k = 0; k < views.size(); ++k) {
    for (int i = 0; i < 6; ++i) params->values()[params->PoseIndex(k, i)] = poses[views[k]][i];
  }
  return Status::Ok();
}

}  // namespace

bool PhaseScheduleFromName(const std::string& name, PhaseSchedule* schedule) {
  if (name == "texture") {
    *schedule = PhaseSchedule::kTexture;
  } else if (name == "geometry") {
    *schedule = PhaseSchedule::kGeometry;
  } else if (name == "alternate") {
    *schedule = PhaseSchedule::kAlternate;
  } else {
    return false;
  }
  return true;
}

const char* PhaseScheduleName(PhaseSchedule schedule) {
  switch (schedule) {
    case PhaseSchedule::kTexture:
      return "texture";
    case PhaseSchedule::kGeometry:
      return "geometry";
    case PhaseSchedule::kAlternate:
      return "alternate";
  }
  return "?";
}

ReconstructOptions::ReconstructOptions() {
  cache.render.spp = 16;
  cache.render.bounces = 2;
}

bool ReconstructOptions::Check(std::string* why) const {
  if (!cache.Check(why) || !problem.Check(why) || !solver.Check(why) || !regularizers.Check(why) ||
      !planner.Check(why)) {
    return false;
  }
  if (outer_iterations < 1 || outer_iterations > 10000) {
    *why = "outer_iterations: must be in [1, 10000]";
    return false;
  }
  if (shading != "auto" && shading != "flat" && shading != "smooth") {
    *why = "shading: expected auto, flat or smooth, got '" + shading + "'";
    return false;
  }
  return true;
}

MeshQuality CompareMeshQuality(const TriMesh& initial, const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> p0, p1;
  std::vector<Eigen::Vector3i> f0, f1;
  MeshToArrays(initial, &p0, &f0);
  MeshToArrays(mesh, &p1, &f1);
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const double min_area = 1e-12 * (hi - lo).squaredNorm();
  MeshQuality quality;
  for (size_t f = 0; f < f1.size() && f < f0.size(); ++f) {
    const Eigen::Vector3i& t = f1[f];
    const Eigen::Vector3d n1 = (p1[t[1]] - p1[t[0]]).cross(p1[t[2]] - p1[t[0]]);
    const Eigen::Vector3d n0 = (p0[t[1]] - p0[t[0]]).cross(p0[t[2]] - p0[t[0]]);
    if (0.5 * n1.norm() <= min_area) {
      ++quality.degenerate_faces;
    } else if (n1.dot(n0) < 0.0) {
      ++quality.flipped_faces;
    }
  }
  return quality;
}

double PsnrFromMse(double mse) {
  if (!(mse > 1e-10)) return 100.0;
  return -10.0 * std::log10(mse);
}

Status Reconstruction::Create(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                              const std::vector<double>& light_scales,
                              const ReconstructOptions& options,
                              std::unique_ptr<Reconstruction>* out,
                              const std::vector<Eigen::Vector3d>& view_gains,
                              const Image& environment,
                              const std::vector<Eigen::Vector3d>& light_positions,
                              const std::vector<Eigen::Vector3d>& light_directions,
                              const std::vector<Eigen::Vector3d>& environment_rotations,
                              const std::vector<PoseDelta>& view_poses) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  std::unique_ptr<Reconstruction> r(new Reconstruction());
  r->dataset_ = &dataset;
  r->options_ = options;
  ResolveShading(options.shading, dataset, &r->options_.cache.render.shading);
  r->mesh_ = mesh;
  r->material_ = material;
  std::vector<Eigen::Vector3d> positions;
  MeshToArrays(mesh, &positions, &r->faces_);
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &r->views_));
  std::vector<int> views;
  SFT_RETURN_IF_ERROR(SelectViews(options.views, static_cast<int>(dataset.views.size()), &views));
  const int num_lights = static_cast<int>(dataset.lights.size());
  const size_t num_dataset_views = dataset.views.size();
  if (!view_gains.empty() && view_gains.size() != num_dataset_views) {
    return Status::Error("exposure gains: " + std::to_string(view_gains.size()) +
                         " views given, the dataset has " + std::to_string(num_dataset_views));
  }
  r->view_gains_ = view_gains;
  if (r->view_gains_.empty()) r->view_gains_.assign(num_dataset_views, Eigen::Vector3d::Ones());
  // Gains are parameters whenever some are not 1 (earlier fits) or this fit fits them.
  bool gains = options.fit_exposure;
  for (int v : views) gains = gains || r->view_gains_[v] != Eigen::Vector3d::Ones();
  const int num_gain_views = gains ? static_cast<int>(views.size()) : 0;
  const int fitted_light = FittedEnvironmentLight(dataset);
  if (fitted_light >= 0) {
    const Image& texels = environment.empty() ? dataset.lights[fitted_light].pixels : environment;
    r->params_ =
        SceneParameters(positions, material, num_lights, num_gain_views, fitted_light, texels);
  } else {
    r->params_ = SceneParameters(positions, material, num_lights, num_gain_views);
  }
  for (int k = 0; gains && k < static_cast<int>(views.size()); ++k) {
    for (int c = 0; c < 3; ++c)
      r->params_.values()[r->params_.GainIndex(k, c)] = r->view_gains_[views[k]][c];
  }
  if (!light_scales.empty()) {
    if (static_cast<int>(light_scales.size()) != num_lights) {
      return Status::Error("light scales: " + std::to_string(light_scales.size()) +
                           " given, the dataset has " + std::to_string(num_lights) + " lights");
    }
    for (int l = 0; l < num_lights; ++l) {
      r->params_.values()[r->params_.layout().LightOffset() + l] = light_scales[l];
    }
  }
  SFT_RETURN_IF_ERROR(
      AddLightGeometry(dataset, options, light_positions, light_directions, &r->params_));
  SFT_RETURN_IF_ERROR(
      AddEnvironmentRotations(dataset, options, environment_rotations, &r->params_));
  if (!view_poses.empty() && view_poses.size() != num_dataset_views) {
    return Status::Error("pose corrections: " + std::to_string(view_poses.size()) +
                         " views given, the dataset has " + std::to_string(num_dataset_views));
  }
  r->view_poses_ = view_poses;
  if (r->view_poses_.empty()) r->view_poses_.assign(num_dataset_views, PoseDelta::Zero());
  SFT_RETURN_IF_ERROR(AddPoses(dataset, options, views, r->view_poses_, &r->params_));
  SFT_RETURN_IF_ERROR(RenderCache::Create(dataset, &r->views_, views, r->faces_, material,
                                          &r->params_, r->options_.cache, &r->cache_));
  r->start_time_ = NowSeconds();
  *out = std::move(r);
  return Status::Ok();
}

Status Reconstruction::PlanEffects(int outer, EffectPlanReport* report, double image_signal_scale,
                                   double step_signal_scale) {
  PlannerContext context;
  context.image_signal_scale = image_signal_scale;
  context.step_signal_scale = step_signal_scale;
  context.ceiling = EffectPlan::From(options_.cache.render, options_.cache.edges);
  context.geometry_phase = options_.phases != PhaseSchedule::kTexture;
  context.fit_specular = options_.fit_specular;
  context.outer_iterations = options_.outer_iterations;
  const AdamOptions& adam = options_.solver.adam;
  if (options_.solver.kind == SolverKind::kAdam && adam.resample) {
    // Every Adam step draws new samples: the noise averages over the stage's steps, each seeing
    // views_per_step of the views (in full-view renders: outer × steps × batch / views).
    const int views = static_cast<int>(cache_->view_indices().size());
    const int batch =
        adam.views_per_step > 0 && adam.views_per_step < views ? adam.views_per_step : views;
    const int64_t renders =
        static_cast<int64_t>(options_.outer_iterations) * options_.solver.steps * batch / views;
    context.outer_iterations = static_cast<int>(std::clamp<int64_t>(renders, 1, 1 << 20));
  }
  for (const LightSpec& light : dataset_->lights) {
    if (light.type == LightType::kEnvironment) {
      context.has_environment = true;
    } else {
      context.has_point_lights = true;
    }
  }
  context.specular_nonzero = params_.values()[params_.layout().SpecularIndex()] > 0.0;
  // Seeds apart from the fit's (options_.seed * 7919 + 2 * outer + phase).
  context.seed = options_.seed * 104729ull + 1000003ull * (static_cast<uint64_t>(outer) + 1);
  return sft::PlanEffects(options_.planner, context, cache_.get(), report);
}

double Reconstruction::ResolvedPosePrior() const {
  const double prior = options_.regularizers.pose_prior;
  if (prior != kPosePriorAuto) return prior;
  for (int v : cache_->view_indices()) {
    const ViewSetup& view = views_.views[v];
    for (const PointLight& light : view.point_lights) {
      if (light.camera_frame) return 0.0;
    }
    for (const DirectionalLight& light : view.directional_lights) {
      if (light.camera_frame) return 0.0;
    }
  }
  return kPosePriorWorldLights;
}

Status Reconstruction::RunOuter(int outer,
                                const std::function<bool(const IterationRecord&)>& on_iteration) {
  std::vector<std::pair<std::string, ActiveParameters>> phases;
  if (options_.phases != PhaseSchedule::kGeometry) {
    phases.push_back({"texture", TexturePhase(options_)});
  }
  if (options_.phases != PhaseSchedule::kTexture) phases.push_back({"geometry", GeometryPhase()});
  bool stop = false;
  for (size_t k = 0; k < phases.size() && !stop; ++k) {
    // Named references, not a structured binding: C++17 lambdas cannot capture bindings (clang).
    const std::string& name = phases[k].first;
    const ActiveParameters& active = phases[k].second;
    cache_->SetActive(active);
    cache_->SetSeed(options_.seed * 7919ull + 2ull * static_cast<uint64_t>(outer) + k);
    const TriMesh rest = Mesh();
    SolverHooks hooks;
    std::vector<Eigen::Vector3d> gain_curvature;
    for (int v = 0; active.exposure && v < params_.num_gain_views(); ++v) {
      gain_curvature.push_back(cache_->GainCurvature(v));
    }
    std::vector<Eigen::Matrix<double, 6, 1>> pose_curvature;
    if (active.poses && params_.num_pose_views() > 0) {
      Eigen::Vector3d lo, hi;
      MeshBounds(rest, &lo, &hi);
      const Eigen::Vector3d centre = 0.5 * (lo + hi);
      for (int v = 0; v < params_.num_pose_views(); ++v) {
        pose_curvature.push_back(cache_->PoseCurvature(v, centre));
      }
    }
    RegularizerOptions regularizers = options_.regularizers;
    regularizers.pose_prior = ResolvedPosePrior();
    hooks.add_regularizers = [&](ceres::Problem* problem) {
      AddRegularizers(rest, active, regularizers, options_.problem.bounds, material_, &params_,
                      problem, gain_curvature, pose_curvature);
    };
    std::vector<double> last_psnr;
    hooks.on_iteration = [&](const IterationInfo& info) {
      IterationRecord record;
      record.outer = outer;
      record.phase = name;
      record.iteration = info.iteration;
      record.cost = info.cost;
      record.accepted = info.accepted;
      record.full = info.full;
      record.seconds = elapsed_offset + NowSeconds() - start_time_;
      // A rejected trial leaves its render in the cache: report the accepted point's PSNR.
      if (info.accepted || last_psnr.empty()) {
        last_psnr.clear();
        for (double mse : cache_->ViewMse()) last_psnr.push_back(PsnrFromMse(mse));
      }
      record.view_psnr = last_psnr;
      const bool go_on = !on_iteration || on_iteration(record);
      stop = stop || !go_on;
      return go_on;
    };
    PhaseRecord phase_record;
    phase_record.outer = outer;
    phase_record.phase = name;
    if (options_.solver.kind == SolverKind::kAdam) {
      std::vector<std::vector<int>> neighbours;
      if (active.vertices && options_.solver.adam.large_steps_lambda > 0) {
        neighbours = VertexNeighbours(rest);
      }
      SFT_RETURN_IF_ERROR(RunAdam(options_.solver, options_.problem, cache_.get(), &params_, hooks,
                                  neighbours, &adam_, &phase_record.stats));
    } else {
      SFT_RETURN_IF_ERROR(RunSolver(options_.solver, options_.problem, cache_.get(), &params_,
                                    hooks, &phase_record.stats));
    }
    phase_record.non_finite_values = cache_->non_finite_values();
    phase_records_.push_back(phase_record);
  }
  return Status::Ok();
}

bool Reconstruction::SetAdamState(const AdamState& state) {
  if (state.m.size() != static_cast<size_t>(params_.layout().size()) ||
      state.v.size() != state.m.size())
    return false;
  adam_ = state;
  return true;
}

TriMesh Reconstruction::Mesh() const {
  TriMesh mesh = mesh_;
  std::vector<Eigen::Vector3d> positions;
  params_.Positions(&positions);
  int v = 0;
  for (auto vh : mesh.vertices()) {
    const Eigen::Vector3d& p = positions[v++];
    mesh.set_point(vh, TriMesh::Point(p.x(), p.y(), p.z()));
  }
  return mesh;
}

Material Reconstruction::CurrentMaterial() const {
  Material material = material_;
  params_.WriteMaterial(&material);
  FillUnsampledTexels(&material.albedo);
  FillUnsampledTexels(&material.roughness);
  // UV textures: the gutter texels no face reads are no part of the fit; fill them from the fitted
  // ones so that filtering across chart borders never pulls in stale values.
  if (material.has_uv_textures()) DilateUvGutters(faces_, &material.uv);
  return material;
}

std::vector<Image> Reconstruction::RenderViews(uint64_t seed) {
  const uint64_t saved = cache_->seed();
  cache_->SetSeed(seed);
  cache_->Render(/*rows=*/false);
  std::vector<Image> images;
  for (int v = 0; v < cache_->num_views(); ++v) images.push_back(cache_->Rendered(v));
  cache_->SetSeed(saved);
  return images;
}

std::vector<Eigen::Vector3d> Reconstruction::ViewGains() const {
  std::vector<Eigen::Vector3d> gains = view_gains_;
  const std::vector<int>& views = cache_->view_indices();
  for (int k = 0; k < params_.num_gain_views(); ++k) gains[views[k]] = params_.Gains(k);
  return gains;
}

std::vector<PoseDelta> Reconstruction::ViewPoses() const {
  std::vector<PoseDelta> poses = view_poses_;
  const std::vector<int>& views = cache_->view_indices();
  for (int k = 0; k < params_.num_pose_views(); ++k) poses[views[k]] = params_.Pose(k);
  return poses;
}

Image Reconstruction::RenderNormals(int v) {
  return cache_->RenderPassImage(v, RenderPass::kNormal);
}

}  // namespace sft
