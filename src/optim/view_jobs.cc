#include "src/optim/view_jobs.h"

#include <glog/logging.h>

#include "src/render/camera.h"

namespace sft {
namespace {

ViewRunner* g_view_runner = nullptr;

}  // namespace

ViewSetup ScaledViewSetup(const DatasetViews& views, int dataset_view, int image_scale_log2,
                          const std::vector<double>& light_scales,
                          const std::vector<Eigen::Vector3d>& light_positions,
                          const std::vector<Eigen::Vector3d>& light_directions) {
  ViewSetup view = views.views[dataset_view];
  view.camera = DownscaledCamera(view.camera, image_scale_log2);
  const Rigid3d world_from_cam = view.cam_from_world.Inverse();
  for (PointLight& light : view.point_lights) {
    if (light.light_index < 0) continue;
    light.intensity *= light_scales[light.light_index];
    if (light_positions.empty()) continue;
    const Eigen::Vector3d& p = light_positions.at(light.light_index);
    light.position = light.camera_frame ? world_from_cam * p : p;
  }
  for (DirectionalLight& light : view.directional_lights) {
    if (light.light_index < 0) continue;
    light.irradiance *= light_scales[light.light_index];
    if (light_directions.empty()) continue;
    const Eigen::Vector3d& v = light_directions.at(light.light_index);
    light.parameter_norm = v.norm();
    CHECK(light.parameter_norm > 0.0) << "light " << light.light_index << ": zero direction";
    const Eigen::Vector3d d = v / light.parameter_norm;
    light.direction = light.camera_frame ? world_from_cam.rotation * d : d;
  }
  if (view.environment_light_index >= 0) {
    view.environment_scale *= light_scales[view.environment_light_index];
  }
  return view;
}

void FittedEnvironmentMaps::Update(const Image& texels, const Dataset& dataset, int light) {
  if (!maps_.empty() && texels.width == texels_.width && texels.height == texels_.height &&
      texels.channels == texels_.channels && texels.data == texels_.data) {
    return;
  }
  const LightSpec& spec = dataset.lights.at(light);
  per_view_ = spec.frame == LightFrame::kCamera;
  maps_.clear();
  if (!per_view_) {
    maps_.push_back(std::make_unique<EnvironmentMap>(texels, spec.world_from_env, spec.scale));
  } else {
    for (const ViewSpec& view : dataset.views) {
      maps_.push_back(std::make_unique<EnvironmentMap>(
          texels, ViewWorldFromEnv(spec, view.cam_from_world), spec.scale));
    }
  }
  texels_ = texels;
}

void RotatedEnvironmentMaps::Update(const std::vector<Eigen::Vector3d>& rotations,
                                    const DatasetViews& views) {
  if (rotations == rotations_ && maps_.size() == views.views.size()) return;
  rotations_ = rotations;
  maps_.assign(views.views.size(), nullptr);
  jacobians_.assign(views.views.size(), Eigen::Matrix3d::Identity());
  if (rotations.empty()) return;
  // World-fixed probes are turned once and shared, as MakeDatasetViews shares them.
  std::vector<std::shared_ptr<const EnvironmentMap>> shared(views.environments.size());
  for (size_t v = 0; v < views.views.size(); ++v) {
    const ViewSetup& view = views.views[v];
    const int light = view.environment_light_index;
    if (view.environment == nullptr || light < 0) continue;
    const Eigen::Vector3d& theta = rotations.at(light);
    const Eigen::Matrix3d turn = RotationFromVector(theta);
    const Eigen::Matrix3d left = RotationLeftJacobian(theta);
    if (views.view_environments[v] != nullptr) {
      // Camera-fixed: cam_from_env ← exp([θ]×)·cam_from_env, i.e. the world turn Rᵀ·exp([θ]×)·R.
      const Eigen::Matrix3d world_from_cam =
          view.cam_from_world.rotation.conjugate().toRotationMatrix();
      maps_[v] = std::make_shared<const EnvironmentMap>(
          view.environment->Rotated(world_from_cam * turn * world_from_cam.transpose()));
      jacobians_[v] = world_from_cam * left;
      continue;
    }
    if (shared.at(light) == nullptr) {
      shared[light] = std::make_shared<const EnvironmentMap>(view.environment->Rotated(turn));
    }
    maps_[v] = shared[light];
    jacobians_[v] = left;
  }
}

void RotatedEnvironmentMaps::Use(int dataset_view, ViewSetup* view) const {
  if (rotations_.empty() || dataset_view < 0 || dataset_view >= static_cast<int>(maps_.size()) ||
      maps_[dataset_view] == nullptr) {
    return;
  }
  view->environment = maps_[dataset_view].get();
  view->environment_rotation_jacobian = jacobians_[dataset_view];
}

const EnvironmentMap* FittedEnvironmentMaps::ForView(int dataset_view) const {
  if (maps_.empty()) return nullptr;
  if (!per_view_) return maps_[0].get();
  CHECK(dataset_view >= 0 && dataset_view < static_cast<int>(maps_.size())) << dataset_view;
  return maps_[dataset_view].get();
}

void UseFittedLightingAndPose(const RotatedEnvironmentMaps& rotated, const ParameterLayout& layout,
                              const FittedEnvironmentMaps& fitted, int dataset_view,
                              const PoseDelta* pose, ViewSetup* view) {
  rotated.Use(dataset_view, view);
  if (layout.FitsEnvironment(view->environment_light_index)) {
    view->environment = fitted.ForView(dataset_view);
  }
  if (pose != nullptr) ApplyPoseCorrection(*pose, view);
}

void RenderViewJob(const RenderScene& scene, const Material& material, const ViewSetup& view,
                   const RenderOptions& render_options, const DerivativeRequest& request_options,
                   const ParameterLayout& layout, const ViewJob& job, ViewResult* result) {
  RenderOptions render = render_options;
  render.seed = job.seed;
  RenderStats stats;
  if (job.pass == ViewPass::kImage) {
    RenderView(scene, material, view, render, &result->image, &stats);
  } else {
    DerivativeRequest request = request_options;
    request.jacobian_rows = job.pass == ViewPass::kRows;
    request.adjoint_weights = job.pass == ViewPass::kAdjoint ? &job.weights : nullptr;
    DerivativeOutput output;
    RenderViewWithDerivatives(scene, material, view, render, request, layout, &result->image,
                              &output, &stats);
    result->rows = std::move(output.rows);
    result->gradient = std::move(output.gradient);
    result->gradient_parts = std::move(output.gradient_parts);
  }
  result->non_finite = stats.NonFinite();
  result->seconds = stats.seconds;
}

void SetViewRunner(ViewRunner* runner) { g_view_runner = runner; }
ViewRunner* CurrentViewRunner() { return g_view_runner; }

}  // namespace sft
