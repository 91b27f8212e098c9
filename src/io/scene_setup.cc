#include "src/io/scene_setup.h"

#include <cmath>

#include "src/core/memory.h"

namespace sft {

uint64_t EstimateViewRenderBytes(const Camera& camera) {
  return kViewImageCopies * EstimateImageBytes(camera.width, camera.height, 4);
}

Status CheckViewsFitInMemory(const Dataset& dataset) {
  int largest = -1;
  uint64_t bytes = 0;
  for (const ViewSpec& view : dataset.views) {
    if (view.camera < 0 || view.camera >= static_cast<int>(dataset.cameras.size())) continue;
    const uint64_t b = EstimateViewRenderBytes(dataset.cameras[view.camera]);
    if (b > bytes) {
      bytes = b;
      largest = view.camera;
    }
  }
  if (largest < 0) return Status::Ok();
  const Camera& camera = dataset.cameras[largest];
  std::string why;
  if (!CheckMemoryBudget(bytes,
                         "rendering one view of " + std::to_string(camera.width) + "x" +
                             std::to_string(camera.height) + " pixels",
                         &why)) {
    return Status::Error("cameras[" + std::to_string(largest) + "] (\"" + camera.id +
                         "\"): " + why);
  }
  return Status::Ok();
}

Eigen::Matrix3d ViewWorldFromEnv(const LightSpec& light, const Rigid3d& cam_from_world) {
  if (light.frame != LightFrame::kCamera) return light.world_from_env;
  return cam_from_world.rotation.conjugate().toRotationMatrix() * light.world_from_env;
}

namespace {

// Sets to zero the texels of the world-fixed probe `rgb` whose centre direction d (in the world:
// world_from_env times the equirectangular direction of the texel's centre, src/render/
// environment.h) has d·ground_normal < 0: an infinite black floor under the object that the probe
// does not show. Texels across the horizon blend with their zeroed neighbours over one texel.
void BlackenBelowGround(const LightSpec& light, Image* rgb) {
  for (int y = 0; y < rgb->height; ++y) {
    const double theta = M_PI * (y + 0.5) / rgb->height;
    for (int x = 0; x < rgb->width; ++x) {
      const double phi = 2.0 * M_PI * (0.5 - (x + 0.5) / rgb->width);
      const Eigen::Vector3d env(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                std::cos(theta));
      if ((light.world_from_env * env).dot(light.ground_normal) >= 0.0) continue;
      for (int c = 0; c < rgb->channels; ++c) rgb->at(x, y, c) = 0.0f;
    }
  }
}

}  // namespace

Status MakeDatasetViews(const Dataset& dataset, DatasetViews* out) {
  SFT_RETURN_IF_ERROR(CheckViewsFitInMemory(dataset));
  out->environments.clear();
  out->environments.resize(dataset.lights.size());
  out->view_environments.clear();
  out->view_environments.resize(dataset.views.size());
  std::vector<Image> probes(dataset.lights.size());  // each probe read once.
  std::vector<bool> loaded(dataset.lights.size(), false);
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
        point.camera_frame = light.frame == LightFrame::kCamera;
        view.point_lights.push_back(point);
        continue;
      }
      if (light.type == LightType::kDirectional) {
        DirectionalLight directional;
        directional.direction = light.frame == LightFrame::kCamera
                                    ? world_from_cam.rotation * light.direction
                                    : light.direction;
        directional.irradiance = light.irradiance;
        directional.light_index = l;
        directional.camera_frame = light.frame == LightFrame::kCamera;
        view.directional_lights.push_back(directional);
        continue;
      }
      if (view.environment != nullptr) {
        return Status::Error("views[" + std::to_string(v) +
                             "].lights: more than one environment light in one view is not "
                             "supported");
      }
      if (!loaded[l]) {
        SFT_RETURN_IF_ERROR(LoadProbe(dataset, l, &probes[l]));
        // An infinite floor cuts the map once; a finite one is a disc each ray is tested on.
        if (!light.ground_normal.isZero() && !(light.ground_radius > 0)) {
          BlackenBelowGround(light, &probes[l]);
        }
        loaded[l] = true;
      }
      if (light.frame == LightFrame::kCamera) {
        out->view_environments[v] = std::make_unique<EnvironmentMap>(
            probes[l], ViewWorldFromEnv(light, spec.cam_from_world), light.scale);
        view.environment = out->view_environments[v].get();
        // Its rotation parameters turn the map in the camera frame: δ_world = Rᵀ·θ.
        view.environment_rotation_jacobian = world_from_cam.rotation.toRotationMatrix();
      } else {
        if (out->environments[l] == nullptr) {
          out->environments[l] =
              std::make_unique<EnvironmentMap>(probes[l], light.world_from_env, light.scale);
        }
        view.environment = out->environments[l].get();
        if (light.ground_radius > 0) {
          view.support.radius = light.ground_radius;
          view.support.centre = light.ground_point;
          view.support.normal = light.ground_normal;
        }
      }
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

Shading DatasetShading(const Dataset& dataset) {
  return dataset.gt_shading == "flat" ? Shading::kFlat : Shading::kSmooth;
}

bool ResolveShading(const std::string& name, const Dataset& dataset, Shading* shading) {
  if (name == "auto") {
    *shading = DatasetShading(dataset);
    return true;
  }
  return ShadingFromName(name, shading);
}

}  // namespace sft
