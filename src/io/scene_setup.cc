#include "src/io/scene_setup.h"

namespace sft {

Status MakeDatasetViews(const Dataset& dataset, DatasetViews* out) {
  out->environments.clear();
  out->environments.resize(dataset.lights.size());
  out->views.clear();
  for (size_t v = 0; v < dataset.views.size(); ++v) {
    const ViewSpec& spec = dataset.views[v];
    ViewSetup view;
    view.camera = dataset.cameras.at(spec.camera);
    view.cam_from_world = spec.cam_from_world;
    view.view_index = v;
    const Rigid3d world_from_cam = spec.cam_from_world.Inverse();
    for (int l : spec.lights) {
      const LightSpec& light = dataset.lights.at(l);
      if (light.type == LightType::kPoint) {
        PointLight point;
        point.position =
            light.frame == LightFrame::kCamera ? world_from_cam * light.position : light.position;
        point.intensity = light.intensity;
        point.light_index = l;
        view.point_lights.push_back(point);
        continue;
      }
      if (view.environment != nullptr) {
        return Status::Error("views[" + std::to_string(v) +
                             "].lights: more than one environment light in one view is not "
                             "supported");
      }
      if (out->environments[l] == nullptr) {
        Image probe;
        SFT_RETURN_IF_ERROR(LoadProbe(dataset, l, &probe));
        out->environments[l] =
            std::make_unique<EnvironmentMap>(probe, light.world_from_env, light.scale);
      }
      view.environment = out->environments[l].get();
      view.environment_light_index = l;
    }
    view.environment_background =
        dataset.background == Background::kEnvironment && view.environment != nullptr;
    out->views.push_back(std::move(view));
  }
  return Status::Ok();
}

Status SelectViews(const std::vector<int>& requested, int num_views, std::vector<int>* selected) {
  selected->clear();
  if (requested.empty()) {
    for (int v = 0; v < num_views; ++v) selected->push_back(v);
    return Status::Ok();
  }
  for (int v : requested) {
    if (v < 0 || v >= num_views) {
      return Status::Error("views: view " + std::to_string(v) + " out of range [0, " +
                           std::to_string(num_views) + ")");
    }
    selected->push_back(v);
  }
  return Status::Ok();
}

}  // namespace sft
