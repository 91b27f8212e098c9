#include "src/eval/studio_lights.h"

#include <cmath>

namespace sft {
namespace {

// A uniform environment of radiance `value` (a 2×1 map: the renderer interpolates it to a
// constant).
LightSpec UniformEnvironment(const std::string& id, double value) {
  LightSpec light;
  light.id = id;
  light.type = LightType::kEnvironment;
  light.frame = LightFrame::kWorld;
  light.pixels = Image(2, 1, 3, static_cast<float>(value));
  return light;
}

}  // namespace

std::vector<RelightCondition> StudioConditions() {
  RelightCondition key;
  key.name = "key";
  key.source = "studio";
  LightSpec sun;
  sun.id = "key";
  sun.type = LightType::kDirectional;
  sun.frame = LightFrame::kCamera;
  sun.direction = Eigen::Vector3d(-1.0, 1.0, 1.0).normalized();
  sun.irradiance = Eigen::Vector3d::Constant(kStudioKey * M_PI);
  key.lights = {sun, UniformEnvironment("fill", kStudioFill)};
  RelightCondition ambient;
  ambient.name = "ambient";
  ambient.source = "studio";
  ambient.lights = {UniformEnvironment("white", 1.0)};
  return {key, ambient};
}

}  // namespace sft
