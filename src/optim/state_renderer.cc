#include "src/optim/state_renderer.h"

#include <string>

#include "src/optim/fitted_environment.h"

namespace sft {
Status StateRenderer::Create(const Dataset& dataset, std::unique_ptr<StateRenderer>* renderer) {
  std::unique_ptr<StateRenderer> r(new StateRenderer());
  r->dataset_ = dataset;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(r->dataset_, &r->views_));
  *renderer = std::move(r);
  return Status::Ok();
}

Status StateRenderer::Update(const RenderState& state) {
  if (state.scene_id != scene_id_) {
    scene_ = std::make_unique<RenderScene>(state.build_positions, state.faces);
    scene_positions_ = state.build_positions;
    scene_id_ = state.scene_id;
  }
  if (state.positions != scene_positions_) {
    scene_->SetVertices(state.positions);
    scene_positions_ = state.positions;
  }
  if (state.layout.num_environment_texels > 0) SFT_RETURN_IF_ERROR(UpdateEnvironment(state));
  rotated_environments_.Update(state.environment_rotations, views_);
  return Status::Ok();
}

Status StateRenderer::UpdateEnvironment(const RenderState& state) {
  if (FittedEnvironmentLight(dataset_) < 0) {
    // The map the views are set up with is replaced by the state's below.
    SFT_RETURN_IF_ERROR(
        AddFittedEnvironment(state.environment, state.environment_frame, &dataset_));
    SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset_, &views_));
  }
  const int light = FittedEnvironmentLight(dataset_);
  if (light != state.layout.environment_light ||
      state.layout.num_environment_texels != state.environment.width * state.environment.height) {
    return Status::Error("the fitted environment is light " + std::to_string(light) +
                         " of this rank's dataset but light " +
                         std::to_string(state.layout.environment_light) +
                         " of rank 0's (the ranks read different datasets)");
  }
  fitted_environment_.Update(state.environment, dataset_, light);
  return Status::Ok();
}

void StateRenderer::Render(const RenderState& state, const ViewJob& job, ViewResult* result) const {
  ViewSetup view =
      ScaledViewSetup(views_, state.view_indices[job.view], state.image_scale_log2,
                      state.light_scales, state.light_positions, state.light_directions);
  UseFittedLightingAndPose(
      rotated_environments_, state.layout, fitted_environment_, state.view_indices[job.view],
      state.pose_corrections.empty() ? nullptr : &state.pose_corrections[job.view], &view);
  RenderViewJob(*scene_, state.material, view, state.render, state.request, state.layout, job,
                result);
}

}  // namespace sft
