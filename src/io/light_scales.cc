#include "src/io/light_scales.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"

namespace sft {

Status WriteLightScales(const std::string& path, const Dataset& dataset,
                        const std::vector<double>& scales) {
  nlohmann::ordered_json json;
  json["format"] = "sft-light-scales/1";
  json["lights"] = nlohmann::ordered_json::array();
  for (size_t l = 0; l < dataset.lights.size(); ++l) {
    json["lights"].push_back({{"id", dataset.lights[l].id}, {"scale", scales.at(l)}});
  }
  return WriteTextFile(path, json.dump(1) + "\n");
}

Status ReadLightScales(const std::string& path, const Dataset& dataset,
                       std::vector<double>* scales) {
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
      }
    }
    if (!found) return Status::Error(where + ".id: the dataset has no light with this id");
  }
  for (size_t l = 0; l < dataset.lights.size(); ++l) {
    if (std::isnan((*scales)[l])) {
      return Status::Error(path + ": no scale for light \"" + dataset.lights[l].id + "\"");
    }
  }
  return Status::Ok();
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
