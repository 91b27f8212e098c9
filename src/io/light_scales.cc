#include "src/io/light_scales.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"

namespace sft {

namespace {

const char* FrameName(LightFrame frame) {
  return frame == LightFrame::kCamera ? "camera" : "world";
}

// Reads entry `entry`'s optional "frame" and "position" for point light `light` into *position.
Status ReadPosition(const nlohmann::json& entry, const std::string& where, const LightSpec& light,
                    bool* found, Eigen::Vector3d* position) {
  *found = false;
  if (!entry.contains("position")) return Status::Ok();
  if (light.type != LightType::kPoint) {
    return Status::Error(where + ".position: light \"" + light.id + "\" is not a point light");
  }
  const nlohmann::json& p = entry["position"];
  if (!p.is_array() || p.size() != 3) return Status::Error(where + ".position: expected 3 numbers");
  for (int k = 0; k < 3; ++k) {
    if (!p[k].is_number() || !std::isfinite(p[k].get<double>())) {
      return Status::Error(where + ".position: expected 3 finite numbers");
    }
    (*position)[k] = p[k].get<double>();
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
                        const std::vector<Eigen::Vector3d>& positions) {
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
    json["lights"].push_back(entry);
  }
  return WriteTextFile(path, json.dump(1) + "\n");
}

Status ReadLightScales(const std::string& path, const Dataset& dataset, std::vector<double>* scales,
                       std::vector<Eigen::Vector3d>* positions) {
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
  std::vector<Eigen::Vector3d> read(dataset.lights.size());
  for (size_t l = 0; l < dataset.lights.size(); ++l) read[l] = dataset.lights[l].position;
  bool any_position = false;
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
        bool has_position = false;
        SFT_RETURN_IF_ERROR(ReadPosition(entry, where, dataset.lights[l], &has_position, &read[l]));
        any_position = any_position || has_position;
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
  return Status::Ok();
}

void ApplyLightPositions(const std::vector<Eigen::Vector3d>& positions, Dataset* dataset) {
  for (size_t l = 0; l < dataset->lights.size() && l < positions.size(); ++l) {
    LightSpec& light = dataset->lights[l];
    if (light.type == LightType::kPoint) light.position = positions[l];
  }
}

void ApplyLightScales(const std::vector<double>& scales, Dataset* dataset) {
  for (size_t l = 0; l < dataset->lights.size() && l < scales.size(); ++l) {
    LightSpec& light = dataset->lights[l];
    if (light.type == LightType::kPoint) {
      light.intensity *= scales[l];
    } else {
      light.scale *= scales[l];
    }
  }
}

}  // namespace sft
