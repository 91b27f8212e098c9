#include "src/optim/fitted_environment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/lights_file.h"

namespace sft {

bool EnvironmentEstimateOptions::Check(std::string* why) const {
  if (width < 2 || width > 512 || height < 1 || height > 256) {
    *why = "environment size: width must be in [2, 512] and height in [1, 256]";
    return false;
  }
  if (!(assumed_albedo > 0.0 && assumed_albedo <= 1.0)) {
    *why = "assumed_albedo: must be in (0, 1]";
    return false;
  }
  if (find_lamp && !lights.empty()) {
    *why = "find_lamp: looks for a lamp when none is given; give it or estimate_lights, not both";
    return false;
  }
  if (!(lamp_distance >= 0.5 && lamp_distance <= 1000.0)) {
    *why = "lamp_distance: must be in [0.5, 1000] (half bounding-box diagonals)";
    return false;
  }
  for (size_t k = 0; k < lights.size(); ++k) {
    const std::string name =
        "estimate_lights: lights[" + std::to_string(k) + "] (\"" + lights[k].id + "\")";
    if (lights[k].type == LightType::kEnvironment) {
      *why = name + ": an environment light; unknown lighting's map is the fitted environment " +
             "(environment_size), so estimate point or directional lights beside it";
      return false;
    }
    if (lights[k].id == kFittedEnvironmentId) {
      *why = name + ": the id is the fitted environment's; choose another";
      return false;
    }
    for (size_t j = 0; j < k; ++j) {
      if (lights[j].id == lights[k].id) {
        *why = name + ": the id is also lights[" + std::to_string(j) + "]'s";
        return false;
      }
    }
  }
  return true;
}

bool LightingUnknown(const Dataset& dataset) {
  if (dataset.views.empty()) return false;
  for (const ViewSpec& view : dataset.views) {
    if (!view.lights.empty()) return false;
  }
  return true;
}

Status InitialEnvironment(const Dataset& dataset, const EnvironmentEstimateOptions& options,
                          Image* texels) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  double sum[3] = {0.0, 0.0, 0.0};
  double count = 0.0;
  for (size_t v = 0; v < dataset.views.size(); ++v) {
    Image rgb, mask;
    SFT_RETURN_IF_ERROR(LoadViewImage(dataset, static_cast<int>(v), &rgb));
    const bool masked = !dataset.views[v].mask.empty();
    if (masked) SFT_RETURN_IF_ERROR(LoadViewMask(dataset, static_cast<int>(v), &mask));
    for (int y = 0; y < rgb.height; ++y) {
      for (int x = 0; x < rgb.width; ++x) {
        if (masked && !(mask.at(x, y, 0) > 0.5f)) continue;
        for (int c = 0; c < 3; ++c) {
          const float value = rgb.at(x, y, std::min(c, rgb.channels - 1));
          if (std::isfinite(value)) sum[c] += value;
        }
        count += 1.0;
      }
    }
  }
  *texels = Image(options.width, options.height, 3);
  for (int c = 0; c < 3; ++c) {
    // A black or empty capture still gets a map light sampling can use.
    const double mean = count > 0.0 ? sum[c] / count : 0.0;
    const float value = static_cast<float>(std::max(mean, 1e-3) / options.assumed_albedo);
    for (int y = 0; y < options.height; ++y) {
      for (int x = 0; x < options.width; ++x) texels->at(x, y, c) = value;
    }
  }
  return Status::Ok();
}

bool LightFrameFromName(const std::string& name, LightFrame* frame) {
  if (name == "world" || name == "camera") {
    *frame = name == "camera" ? LightFrame::kCamera : LightFrame::kWorld;
    return true;
  }
  return false;
}

const char* LightFrameName(LightFrame frame) {
  return frame == LightFrame::kCamera ? "camera" : "world";
}

Status WriteFittedEnvironment(const std::string& run, const Image& texels, LightFrame frame) {
  SFT_RETURN_IF_ERROR(WriteExr(JoinPath(run, kFittedEnvironmentFile), texels));
  const nlohmann::json info = {{"format", "sft-fitted-environment/1"},
                               {"frame", LightFrameName(frame)}};
  return WriteTextFile(JoinPath(run, kFittedEnvironmentInfoFile), info.dump(1) + "\n");
}

Status ReadFittedEnvironmentFrame(const std::string& run, LightFrame* frame) {
  *frame = LightFrame::kWorld;
  const std::string path = JoinPath(run, kFittedEnvironmentInfoFile);
  if (!FileExists(path)) return Status::Ok();
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  const nlohmann::json info = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!info.is_object() || info.value("format", "") != "sft-fitted-environment/1") {
    return Status::Error(path + ": not a fitted environment's info (expected format " +
                         "\"sft-fitted-environment/1\")");
  }
  const nlohmann::json& name = info.contains("frame") ? info["frame"] : nlohmann::json();
  if (!name.is_string() || !LightFrameFromName(name.get<std::string>(), frame)) {
    return Status::Error(path + ": frame: expected \"world\" or \"camera\"");
  }
  return Status::Ok();
}

Status AddFittedEnvironment(const Image& texels, LightFrame frame, Dataset* dataset) {
  if (FittedEnvironmentLight(*dataset) >= 0) {
    return Status::Error("the dataset has a fitted environment already");
  }
  if (texels.width < 2 || texels.height < 1 || texels.channels < 3) {
    return Status::Error("fitted environment: needs at least 2 × 1 RGB texels");
  }
  LightSpec light;
  light.id = kFittedEnvironmentId;
  light.type = LightType::kEnvironment;
  light.frame = frame;
  light.pixels = texels;
  const int index = static_cast<int>(dataset->lights.size());
  dataset->lights.push_back(std::move(light));
  for (ViewSpec& view : dataset->views) {
    view.light_ids.push_back(kFittedEnvironmentId);
    view.lights.push_back(index);
  }
  return Status::Ok();
}

Status AddEstimatedLights(const std::vector<LightSpec>& lights, Dataset* dataset) {
  EnvironmentEstimateOptions options;
  options.lights = lights;
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  for (const LightSpec& light : lights) {
    for (const LightSpec& known : dataset->lights) {
      if (known.id == light.id) {
        return Status::Error("estimate_lights: light \"" + light.id +
                             "\": the dataset has a light of that id; choose another");
      }
    }
  }
  // The map stays the last light (the order the MPI workers rebuild): take it out, add the
  // lights, put it back.
  const int fitted = FittedEnvironmentLight(*dataset);
  LightSpec map;
  if (fitted >= 0) {
    if (fitted + 1 != static_cast<int>(dataset->lights.size())) {
      return Status::Error("estimate_lights: the fitted environment is not the last light");
    }
    map = std::move(dataset->lights.back());
    dataset->lights.pop_back();
    for (ViewSpec& view : dataset->views) {
      if (view.lights.empty() || view.lights.back() != fitted) {
        return Status::Error("estimate_lights: a view lists the fitted environment out of order");
      }
      view.lights.pop_back();
      view.light_ids.pop_back();
    }
  }
  for (const LightSpec& light : lights) {
    const int index = static_cast<int>(dataset->lights.size());
    dataset->lights.push_back(light);
    for (ViewSpec& view : dataset->views) {
      view.light_ids.push_back(light.id);
      view.lights.push_back(index);
    }
  }
  if (fitted >= 0) return AddFittedEnvironment(map.pixels, map.frame, dataset);
  return Status::Ok();
}

std::vector<LightSpec> EstimatedLights(const Dataset& dataset) {
  // Every view lists them (the dataset's own lights, if it defines any, no view lists).
  std::vector<LightSpec> lights;
  const int fitted = FittedEnvironmentLight(dataset);
  if (fitted < 0 || dataset.views.empty()) return lights;
  for (int l : dataset.views.front().lights) {
    if (l != fitted) lights.push_back(dataset.lights.at(l));
  }
  return lights;
}

Status WriteEstimatedLights(const std::string& run, const Dataset& dataset) {
  const std::vector<LightSpec> lights = EstimatedLights(dataset);
  if (lights.empty()) return Status::Ok();
  return WriteLightsFile(JoinPath(run, kEstimatedLightsFile), lights);
}

int FittedEnvironmentLight(const Dataset& dataset) {
  for (size_t l = 0; l < dataset.lights.size(); ++l) {
    if (dataset.lights[l].id == kFittedEnvironmentId && !dataset.lights[l].pixels.empty()) {
      return static_cast<int>(l);
    }
  }
  return -1;
}

namespace {

// The estimated lights of PrepareUnknownLighting: the run folder's when it has them, else
// `given`; *names lists their ids for the console line ("" when none).
Status EstimatedLightsToAdd(const std::string& run, const std::vector<LightSpec>& given,
                            std::vector<LightSpec>* lights, std::string* names) {
  *lights = given;
  const std::string saved = run.empty() ? "" : JoinPath(run, kEstimatedLightsFile);
  if (!saved.empty() && FileExists(saved)) SFT_RETURN_IF_ERROR(ReadLightsFile(saved, lights));
  names->clear();
  for (const LightSpec& light : *lights) {
    *names += (names->empty() ? "" : ", ") + light.id;
  }
  return Status::Ok();
}

}  // namespace

Status PrepareUnknownLighting(const std::string& run, const EnvironmentEstimateOptions& options,
                              Dataset* dataset, std::string* note) {
  note->clear();
  if (!LightingUnknown(*dataset)) {
    if (options.find_lamp) {
      return Status::Error(
          "find_lamp: the dataset lists its lights (its lighting is known); a lamp is looked for "
          "under unknown lighting only");
    }
    if (options.lights.empty()) return Status::Ok();
    return Status::Error(
        "estimate_lights: the dataset lists its lights (its lighting is known); estimated lights "
        "join unknown lighting only (fit a dataset light's place with fit_light_positions or "
        "fit_light_directions)");
  }
  std::vector<LightSpec> lights;
  std::string names;
  SFT_RETURN_IF_ERROR(EstimatedLightsToAdd(run, options.lights, &lights, &names));
  SFT_RETURN_IF_ERROR(AddEstimatedLights(lights, dataset));
  const std::string beside = lights.empty()
                                 ? ""
                                 : " and " + std::to_string(lights.size()) + " estimated light" +
                                       (lights.size() == 1 ? "" : "s") + " (" + names + ")";
  Image texels;
  LightFrame frame = options.frame;
  const std::string saved = run.empty() ? "" : JoinPath(run, kFittedEnvironmentFile);
  if (!saved.empty() && FileExists(saved)) {
    SFT_RETURN_IF_ERROR(ReadFittedEnvironmentFrame(run, &frame));
    Image image;
    SFT_RETURN_IF_ERROR(ReadImage(saved, &image));
    if (image.width < 2 || image.height < 1 || image.channels < 3) {
      return Status::Error(saved + ": not a fitted environment (needs at least 2 × 1 RGB texels)");
    }
    texels = ToRgb(image);
    for (size_t k = 0; k < texels.data.size(); ++k) {
      if (!std::isfinite(texels.data[k]) || texels.data[k] < 0.0f) {
        const int texel = static_cast<int>(k / 3);
        return Status::Error(saved + ": texel (" + std::to_string(texel % texels.width) + ", " +
                             std::to_string(texel / texels.width) +
                             ") is negative or not finite (radiance must be finite and >= 0)");
      }
    }
    *note = std::string("lighting: unknown in the dataset; continuing the fitted ") +
            std::to_string(texels.width) + "×" + std::to_string(texels.height) + " " +
            LightFrameName(frame) + "-fixed environment of " + saved + beside;
  } else {
    SFT_RETURN_IF_ERROR(InitialEnvironment(*dataset, options, &texels));
    *note = std::string("lighting: unknown in the dataset (no view lists lights); fitting a ") +
            (frame == LightFrame::kCamera ? "camera-fixed " : "world-fixed ") +
            std::to_string(texels.width) + "×" + std::to_string(texels.height) + " environment" +
            beside + " with the material (albedo is then known up to one scale per channel)";
  }
  return AddFittedEnvironment(texels, frame, dataset);
}

namespace {

// Texel t's direction on a w × h lat-long grid (any fixed convention serves: both maps share it).
Eigen::Vector3d TexelDirection(int t, int w, int h) {
  const double theta = M_PI * ((t / w) + 0.5) / h, phi = 2.0 * M_PI * ((t % w) + 0.5) / w;
  return {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
}

// √(Σ_t w_t‖a_t − b_t‖² / Σ_t w_t‖b_t‖²) over RGB triples.
double RelativeRmse(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                    const std::vector<double>& weight) {
  double error = 0.0, norm = 0.0;
  for (size_t t = 0; t < a.size(); ++t) {
    error += weight[t] * (a[t] - b[t]).squaredNorm();
    norm += weight[t] * b[t].squaredNorm();
  }
  return norm > 0.0 ? std::sqrt(error / norm) : std::numeric_limits<double>::infinity();
}

// The irradiance at every texel's direction of a map given per texel with solid angles `weight`.
std::vector<Eigen::Vector3d> Irradiance(const std::vector<Eigen::Vector3d>& radiance,
                                        const std::vector<double>& weight, int w, int h) {
  std::vector<Eigen::Vector3d> dirs(radiance.size());
  for (size_t t = 0; t < dirs.size(); ++t) dirs[t] = TexelDirection(static_cast<int>(t), w, h);
  std::vector<Eigen::Vector3d> irradiance(radiance.size(), Eigen::Vector3d::Zero());
  for (size_t n = 0; n < dirs.size(); ++n) {
    for (size_t t = 0; t < dirs.size(); ++t) {
      const double cosine = dirs[n].dot(dirs[t]);
      if (cosine > 0.0) irradiance[n] += radiance[t] * (weight[t] * cosine);
    }
  }
  return irradiance;
}

}  // namespace

Status FittedEnvironmentError(const Image& fitted, const Image& truth,
                              const Eigen::Vector3d& albedo_scale, EnvironmentError* error) {
  if (fitted.empty() || fitted.channels < 3 || truth.empty() || truth.channels < 3) {
    return Status::Error("environment error: needs two non-empty RGB maps");
  }
  for (int c = 0; c < 3; ++c) {
    if (!(albedo_scale[c] > 0.0 && std::isfinite(albedo_scale[c]))) {
      return Status::Error("environment error: the albedo scale must be finite and > 0");
    }
  }
  const int w = fitted.width, h = fitted.height;
  // Box filter of the truth onto the fitted grid, every truth pixel weighed by its solid angle
  // (2π/W_t · π/H_t · sin θ); a texel's weight sums to its solid angle.
  const double pixel = 2.0 * M_PI * M_PI / (static_cast<double>(truth.width) * truth.height);
  std::vector<Eigen::Vector3d> ours(w * h), theirs(w * h, Eigen::Vector3d::Zero());
  std::vector<double> weight(w * h, 0.0);
  for (int y = 0; y < truth.height; ++y) {
    const double solid_angle = pixel * std::sin(M_PI * (y + 0.5) / truth.height);
    const int ty = std::min(h - 1, static_cast<int>(static_cast<int64_t>(y) * h / truth.height));
    for (int x = 0; x < truth.width; ++x) {
      const int tx = std::min(w - 1, static_cast<int>(static_cast<int64_t>(x) * w / truth.width));
      const int t = ty * w + tx;
      weight[t] += solid_angle;
      for (int c = 0; c < 3; ++c) theirs[t][c] += solid_angle * truth.at(x, y, c);
    }
  }
  for (int t = 0; t < w * h; ++t) {
    // A texel finer than the truth's pixels gets none (weight 0: left out).
    if (weight[t] > 0.0) theirs[t] /= weight[t];
    for (int c = 0; c < 3; ++c) ours[t][c] = fitted.at(t % w, t / w, c) / albedo_scale[c];
  }
  error->radiance = RelativeRmse(ours, theirs, weight);
  error->irradiance =
      RelativeRmse(Irradiance(ours, weight, w, h), Irradiance(theirs, weight, w, h), weight);
  if (!std::isfinite(error->radiance) || !std::isfinite(error->irradiance)) {
    return Status::Error("environment error: the true environment is black or not finite");
  }
  return Status::Ok();
}

}  // namespace sft
