#include "src/io/light_scales.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"
#include "src/render/environment.h"

namespace sft {

namespace {

const char* FrameName(LightFrame frame) {
  return frame == LightFrame::kCamera ? "camera" : "world";
}

// Reads entry `entry`'s optional "frame" and `key` ("position" of a point light, "direction" of
// a directional light, whose type `type` is) for light `light` into *value.
Status ReadLightVector(const nlohmann::json& entry, const std::string& where,
                       const LightSpec& light, const char* key, LightType type, bool* found,
                       Eigen::Vector3d* value) {
  *found = false;
  if (!entry.contains(key)) return Status::Ok();
  const std::string field = where + "." + key;
  if (light.type != type) {
    return Status::Error(field + ": light \"" + light.id + "\" is not " +
                         (type == LightType::kPoint         ? "a point"
                          : type == LightType::kDirectional ? "a directional"
                                                            : "an environment") +
                         " light");
  }
  const nlohmann::json& p = entry[key];
  if (!p.is_array() || p.size() != 3) return Status::Error(field + ": expected 3 numbers");
  for (int k = 0; k < 3; ++k) {
    if (!p[k].is_number() || !std::isfinite(p[k].get<double>())) {
      return Status::Error(field + ": expected 3 finite numbers");
    }
    (*value)[k] = p[k].get<double>();
  }
  if (type == LightType::kDirectional && !(value->norm() > 0.0)) {
    return Status::Error(field + ": must not be zero");
  }
  if (entry.value("frame", "world") != std::string(FrameName(light.frame))) {
    return Status::Error(where + ".frame: expected \"" + FrameName(light.frame) +
                         "\", the dataset light's frame");
  }
  *found = true;
  return Status::Ok();
}

}  // namespace

Status WriteLightScales(const std::string& path, const Dataset& dataset,
                        const std::vector<double>& scales,
                        const std::vector<Eigen::Vector3d>& positions,
                        const std::vector<Eigen::Vector3d>& directions,
                        const std::vector<Eigen::Vector3d>& rotations) {
  nlohmann::ordered_json json;
  json["format"] = "sft-light-scales/1";
  json["lights"] = nlohmann::ordered_json::array();
  for (size_t l = 0; l < dataset.lights.size(); ++l) {
    const LightSpec& light = dataset.lights[l];
    nlohmann::ordered_json entry = {{"id", light.id}, {"scale", scales.at(l)}};
    if (!positions.empty() && light.type == LightType::kPoint) {
      const Eigen::Vector3d& p = positions.at(l);
      entry["frame"] = FrameName(light.frame);
      entry["position"] = {p.x(), p.y(), p.z()};
    }
    if (!directions.empty() && light.type == LightType::kDirectional) {
      const Eigen::Vector3d d = directions.at(l).normalized();
      entry["frame"] = FrameName(light.frame);
      entry["direction"] = {d.x(), d.y(), d.z()};
    }
    if (!rotations.empty() && light.type == LightType::kEnvironment) {
      const Eigen::Vector3d& r = rotations.at(l);
      entry["frame"] = FrameName(light.frame);
      entry["rotation"] = {r.x(), r.y(), r.z()};
    }
    json["lights"].push_back(entry);
  }
  return WriteTextFile(path, json.dump(1) + "\n");
}

Status ReadLightScales(const std::string& path, const Dataset& dataset, std::vector<double>* scales,
                       std::vector<Eigen::Vector3d>* positions,
                       std::vector<Eigen::Vector3d>* directions,
                       std::vector<Eigen::Vector3d>* rotations) {
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded() || !json.is_object()) return Status::Error(path + ": not a JSON object");
  if (json.value("format", "") != "sft-light-scales/1") {
    return Status::Error(path + ": format: expected \"sft-light-scales/1\"");
  }
  const auto lights = json.find("lights");
  if (lights == json.end() || !lights->is_array()) {
    return Status::Error(path + ": lights: expected an array");
  }
  scales->assign(dataset.lights.size(), std::nan(""));
  std::vector<Eigen::Vector3d> read(dataset.lights.size()), read_directions(dataset.lights.size());
  for (size_t l = 0; l < dataset.lights.size(); ++l) {
    read[l] = dataset.lights[l].position;
    read_directions[l] = dataset.lights[l].direction;
  }
  std::vector<Eigen::Vector3d> read_rotations(dataset.lights.size(), Eigen::Vector3d::Zero());
  bool any_position = false, any_direction = false, any_rotation = false;
  for (size_t i = 0; i < lights->size(); ++i) {
    const nlohmann::json& entry = (*lights)[i];
    const std::string where = path + ": lights[" + std::to_string(i) + "]";
    if (!entry.is_object() || !entry.contains("id") || !entry["id"].is_string() ||
        !entry.contains("scale") || !entry["scale"].is_number()) {
      return Status::Error(where + ": expected {\"id\": string, \"scale\": number}");
    }
    const double scale = entry["scale"].get<double>();
    if (!(scale > 0.0) || !std::isfinite(scale)) {
      return Status::Error(where + ".scale: must be finite and > 0");
    }
    bool found = false;
    for (size_t l = 0; l < dataset.lights.size(); ++l) {
      if (dataset.lights[l].id == entry["id"].get<std::string>()) {
        (*scales)[l] = scale;
        found = true;
        const LightSpec& light = dataset.lights[l];
        bool has = false;
        SFT_RETURN_IF_ERROR(
            ReadLightVector(entry, where, light, "position", LightType::kPoint, &has, &read[l]));
        any_position = any_position || has;
        SFT_RETURN_IF_ERROR(ReadLightVector(entry, where, light, "direction",
                                            LightType::kDirectional, &has, &read_directions[l]));
        any_direction = any_direction || has;
        SFT_RETURN_IF_ERROR(ReadLightVector(entry, where, light, "rotation",
                                            LightType::kEnvironment, &has, &read_rotations[l]));
        any_rotation = any_rotation || has;
      }
    }
    if (!found) return Status::Error(where + ".id: the dataset has no light with this id");
  }
  for (size_t l = 0; l < dataset.lights.size(); ++l) {
    if (std::isnan((*scales)[l])) {
      return Status::Error(path + ": no scale for light \"" + dataset.lights[l].id + "\"");
    }
  }
  if (positions != nullptr) {
    positions->clear();
    if (any_position) *positions = std::move(read);
  }
  if (directions != nullptr) {
    directions->clear();
    if (any_direction) *directions = std::move(read_directions);
  }
  if (rotations != nullptr) {
    rotations->clear();
    if (any_rotation) *rotations = std::move(read_rotations);
  }
  return Status::Ok();
}

void ApplyLightPositions(const std::vector<Eigen::Vector3d>& positions, Dataset* dataset) {
  for (size_t l = 0; l < dataset->lights.size() && l < positions.size(); ++l) {
    LightSpec& light = dataset->lights[l];
    if (light.type == LightType::kPoint) light.position = positions[l];
  }
}

void ApplyLightDirections(const std::vector<Eigen::Vector3d>& directions, Dataset* dataset) {
  for (size_t l = 0; l < dataset->lights.size() && l < directions.size(); ++l) {
    LightSpec& light = dataset->lights[l];
    if (light.type == LightType::kDirectional) light.direction = directions[l].normalized();
  }
}

void ApplyEnvironmentRotations(const std::vector<Eigen::Vector3d>& rotations, Dataset* dataset) {
  for (size_t l = 0; l < dataset->lights.size() && l < rotations.size(); ++l) {
    LightSpec& light = dataset->lights[l];
    if (light.type == LightType::kEnvironment) {
      light.world_from_env = RotationFromVector(rotations[l]) * light.world_from_env;
    }
  }
}

Status ApplyLightsFile(const std::string& path, Dataset* dataset) {
  std::vector<double> scales;
  std::vector<Eigen::Vector3d> positions, directions, rotations;
  SFT_RETURN_IF_ERROR(
      ReadLightScales(path, *dataset, &scales, &positions, &directions, &rotations));
  ApplyLightScales(scales, dataset);
  ApplyLightPositions(positions, dataset);
  ApplyLightDirections(directions, dataset);
  ApplyEnvironmentRotations(rotations, dataset);
  return Status::Ok();
}

void ApplyLightScales(const std::vector<double>& scales, Dataset* dataset) {
  for (size_t l = 0; l < dataset->lights.size() && l < scales.size(); ++l) {
    LightSpec& light = dataset->lights[l];
    if (light.type == LightType::kPoint) {
      light.intensity *= scales[l];
    } else if (light.type == LightType::kDirectional) {
      light.irradiance *= scales[l];
    } else {
      light.scale *= scales[l];
    }
  }
}

}  // namespace sft
