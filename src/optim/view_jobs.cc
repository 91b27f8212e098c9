#include "src/optim/view_jobs.h"

#include "src/render/camera.h"

namespace sft {
namespace {

ViewRunner* g_view_runner = nullptr;

}  // namespace

ViewSetup ScaledViewSetup(const DatasetViews& views, int dataset_view, int image_scale_log2,
                          const std::vector<double>& light_scales,
                          const std::vector<Eigen::Vector3d>& light_positions) {
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
  if (view.environment_light_index >= 0) {
    view.environment_scale *= light_scales[view.environment_light_index];
  }
  return view;
}

void UseFittedEnvironment(const ParameterLayout& layout, const EnvironmentMap* fitted,
                          ViewSetup* view) {
  if (layout.FitsEnvironment(view->environment_light_index)) view->environment = fitted;
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
