#include "src/eval/lighting_report.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/light_scales.h"
#include "src/io/lights_file.h"
#include "src/optim/fitted_environment.h"

namespace sft {
namespace {

constexpr int kMapWidth = 512;  // the map's image width in the report (texels repeated).

std::string Triple(const Eigen::Vector3d& v) {
  char text[96];
  std::snprintf(text, sizeof(text), "(%.3f, %.3f, %.3f)", v.x(), v.y(), v.z());
  return text;
}

// Nearest-neighbour enlargement so that a 32×16 map shows its texels as blocks.
Image Enlarged(const Image& map, int width) {
  const int k = std::max(1, width / std::max(1, map.width));
  Image big(map.width * k, map.height * k, 3);
  for (int y = 0; y < big.height; ++y) {
    for (int x = 0; x < big.width; ++x) {
      for (int c = 0; c < 3; ++c)
        big.at(x, y, c) = map.at(x / k, y / k, std::min(c, map.channels - 1));
    }
  }
  return big;
}

// "id (point, world): start … → fitted …, intensity …" for each estimated light.
std::vector<std::pair<std::string, std::string>> LightRows(const std::vector<LightSpec>& start,
                                                           const Dataset& fitted) {
  std::vector<std::pair<std::string, std::string>> rows;
  for (const LightSpec& s : start) {
    const auto it = std::find_if(fitted.lights.begin(), fitted.lights.end(),
                                 [&](const LightSpec& l) { return l.id == s.id; });
    if (it == fitted.lights.end()) continue;
    const bool point = s.type == LightType::kPoint;
    const std::string key = s.id + " (" + (point ? "point" : "directional") + ", " +
                            (s.frame == LightFrame::kCamera ? "camera" : "world") + " frame)";
    const std::string where =
        point ? "position " + Triple(s.position) + " → " + Triple(it->position)
              : "direction " + Triple(s.direction) + " → " + Triple(it->direction);
    const std::string amount =
        point ? "intensity " + Triple(s.intensity) + " → " + Triple(it->intensity) + " W/sr"
              : "irradiance " + Triple(s.irradiance) + " → " + Triple(it->irradiance);
    rows.push_back({key, "start → fitted: " + where + "; " + amount});
  }
  return rows;
}

}  // namespace

Status AddFittedLighting(const std::string& out, const Dataset& dataset, HtmlReport* html) {
  const int map = FittedEnvironmentLight(dataset);
  if (map < 0) return Status::Ok();
  Dataset fitted = dataset;
  const std::string lights_file = JoinPath(out, "lights.json");
  if (FileExists(lights_file)) SFT_RETURN_IF_ERROR(ApplyLightsFile(lights_file, &fitted));
  Image texels = dataset.lights[map].pixels;
  const std::string saved = JoinPath(out, kFittedEnvironmentFile);
  if (FileExists(saved)) SFT_RETURN_IF_ERROR(ReadImage(saved, &texels));
  LightFrame frame = dataset.lights[map].frame;
  SFT_RETURN_IF_ERROR(ReadFittedEnvironmentFrame(out, &frame));
  const double scale = fitted.lights[map].scale;
  Image radiance = ToRgb(texels);
  for (float& value : radiance.data) value = static_cast<float>(value * scale);
  html->AddHeading("Fitted lighting");
  html->AddParagraph(
      "The dataset lists no lights, so the run fitted them. The map: equirectangular, z up, the "
      "image's centre looking along +x, fixed in the " +
      std::string(frame == LightFrame::kCamera ? "camera (it rides with each view)" : "world") +
      "; shown at its own exposure. Albedo × lighting is known up to one scale per channel "
      "(docs/reconstruct.md, \"Unknown lighting\").");
  const std::string file = "report_files/environment.png";
  SFT_RETURN_IF_ERROR(html->WriteImage(
      file, ScaledRgb(Enlarged(radiance, kMapWidth), ExposureScale(radiance, nullptr))));
  html->AddHtml("<p><img src=\"" + file + "\" alt=\"the fitted environment map\"></p>");
  std::vector<std::pair<std::string, std::string>> rows = {
      {"fitted environment", std::to_string(texels.width) + "×" + std::to_string(texels.height) +
                                 " texels, scale " + FormatNumber(scale)}};
  std::vector<LightSpec> start;
  const std::string starts = JoinPath(out, kEstimatedLightsFile);
  if (FileExists(starts)) SFT_RETURN_IF_ERROR(ReadLightsFile(starts, &start));
  for (const auto& row : LightRows(start, fitted)) rows.push_back(row);
  html->AddSummaryTable(rows);
  return Status::Ok();
}

}  // namespace sft
