#include "src/optim/lamp_finder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "src/optim/fitted_environment.h"

namespace sft {
namespace {

// The env-frame direction at the centre of texel (x, y) of a W × H map (src/render/
// environment.h: u = 0.5 − atan2(y, x)/(2π), v = acos(z)/π).
Eigen::Vector3d TexelDirection(int x, int y, int width, int height) {
  const double u = (x + 0.5) / width, v = (y + 0.5) / height;
  const double theta = M_PI * v, phi = 2.0 * M_PI * (0.5 - u);
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// The solid angle of row y's texels (sr): a band of the sphere split into `width` cells.
double TexelSolidAngle(int y, int width, int height) {
  return 2.0 * M_PI / width * (std::cos(M_PI * y / height) - std::cos(M_PI * (y + 1) / height));
}

double Luminance(const Image& texels, int x, int y) {
  return std::max(
      0.0,
      (static_cast<double>(texels.at(x, y, 0)) + texels.at(x, y, 1) + texels.at(x, y, 2)) / 3.0);
}

// The texels 8-connected to `seed` (index y·W + x; u wraps, v does not) whose luminance is above
// `threshold`.
std::vector<int> ConnectedAbove(const std::vector<double>& luminance, int width, int height,
                                int seed, double threshold) {
  std::vector<char> seen(luminance.size(), 0);
  std::vector<int> lobe, stack = {seed};
  seen[seed] = 1;
  while (!stack.empty()) {
    const int t = stack.back();
    stack.pop_back();
    lobe.push_back(t);
    const int x = t % width, y = t / width;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int ny = y + dy, nx = (x + dx + width) % width;
        if (ny < 0 || ny >= height) continue;
        const int n = ny * width + nx;
        if (seen[n] || !(luminance[n] > threshold)) continue;
        seen[n] = 1;
        stack.push_back(n);
      }
    }
  }
  return lobe;
}

}  // namespace

std::string LampSearch::Describe() const {
  char line[320];
  if (!found) {
    std::snprintf(line, sizeof(line),
                  "find_lamp: the map fitted alone has no bright lobe (brightest texel %.1f× the "
                  "median, below %.0f×, %.1f s); fitting the map alone",
                  contrast, kMinLobeContrast, seconds);
  } else {
    std::snprintf(line, sizeof(line),
                  "find_lamp: the map fitted alone has a lobe of %d texels %.1f× the median (%.1f "
                  "s); %s starts at (%.3f, %.3f, %.3f) in the %s frame, intensity %.3g",
                  lobe_texels, contrast, seconds, kFoundLampId, lamp.position.x(),
                  lamp.position.y(), lamp.position.z(),
                  lamp.frame == LightFrame::kCamera ? "camera" : "world", lamp.intensity.mean());
  }
  return line;
}

Status LampFromEnvironment(const Image& texels, const Eigen::Matrix3d& frame_from_env,
                           LightFrame frame, const Eigen::Vector3d& centre, double distance,
                           LampSearch* search) {
  const int width = texels.width, height = texels.height;
  if (width < 1 || height < 1 || texels.channels < 3) {
    return Status::Error("find_lamp: the fitted map has no RGB texels");
  }
  *search = LampSearch();
  std::vector<double> luminance(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) luminance[y * width + x] = Luminance(texels, x, y);
  }
  std::vector<double> sorted = luminance;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  const int brightest =
      static_cast<int>(std::max_element(luminance.begin(), luminance.end()) - luminance.begin());
  const double peak = luminance[brightest];
  // A black median: any light at all stands out.
  search->contrast = median > 0.0 ? peak / median : (peak > 0.0 ? HUGE_VAL : 0.0);
  if (!(search->contrast >= kMinLobeContrast)) return Status::Ok();
  const std::vector<int> lobe =
      ConnectedAbove(luminance, width, height, brightest, median + 0.5 * (peak - median));
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int t : lobe) {
    const int x = t % width, y = t / width;
    sum += (luminance[t] - median) * TexelSolidAngle(y, width, height) *
           TexelDirection(x, y, width, height);
  }
  const Eigen::Vector3d omega = (frame_from_env * sum).normalized();
  Eigen::Vector3d irradiance = Eigen::Vector3d::Zero();
  Eigen::Vector3d median_rgb;  // the per-channel level the lobe stands on.
  for (int c = 0; c < 3; ++c) {
    std::vector<float> channel(luminance.size());
    for (size_t t = 0; t < channel.size(); ++t) channel[t] = texels.data[t * texels.channels + c];
    std::nth_element(channel.begin(), channel.begin() + channel.size() / 2, channel.end());
    median_rgb[c] = channel[channel.size() / 2];
  }
  for (int t : lobe) {
    const int x = t % width, y = t / width;
    const double cosine =
        std::max(0.0, omega.dot(frame_from_env * TexelDirection(x, y, width, height)));
    for (int c = 0; c < 3; ++c) {
      irradiance[c] += std::max(0.0, texels.at(x, y, c) - median_rgb[c]) *
                       TexelSolidAngle(y, width, height) * cosine;
    }
  }
  search->found = true;
  search->direction = omega;
  search->lobe_texels = static_cast<int>(lobe.size());
  LightSpec& lamp = search->lamp;
  lamp.id = kFoundLampId;
  lamp.type = LightType::kPoint;
  lamp.frame = frame;
  lamp.position = centre + distance * omega;
  // A lobe of one grey-level excess still gets a lamp the fit can scale.
  lamp.intensity = (irradiance * distance * distance).cwiseMax(1e-6);
  return Status::Ok();
}

Eigen::Vector3d ObjectCentreInFrame(const TriMesh& mesh, const Dataset& dataset,
                                    const std::vector<int>& views, LightFrame frame) {
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  if (frame == LightFrame::kWorld || dataset.views.empty()) return centre;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t v = 0; v < dataset.views.size(); ++v) {
    if (!views.empty() && std::find(views.begin(), views.end(), static_cast<int>(v)) == views.end())
      continue;
    sum += dataset.views[v].cam_from_world * centre;
    ++count;
  }
  return count > 0 ? Eigen::Vector3d(sum / count) : centre;
}

Status FindLamp(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                const ReconstructOptions& fit, double lamp_distance,
                const std::function<bool(const IterationRecord&)>& on_iteration,
                LampSearch* search) {
  const int map = FittedEnvironmentLight(dataset);
  if (map < 0) return Status::Error("find_lamp: the dataset has no fitted environment");
  const auto start = std::chrono::steady_clock::now();
  ReconstructOptions options = fit;
  options.fit_lights = false;
  options.fit_light_positions = false;
  options.fit_light_directions = false;
  std::unique_ptr<Reconstruction> r;
  SFT_RETURN_IF_ERROR(Reconstruction::Create(dataset, mesh, material, {}, options, &r));
  bool stopped = false;
  for (int k = 0; k < options.outer_iterations && !stopped; ++k) {
    if (options.planner.enabled) {
      EffectPlanReport report;
      SFT_RETURN_IF_ERROR(r->PlanEffects(k, &report));
    }
    SFT_RETURN_IF_ERROR(r->RunOuter(k, [&](const IterationRecord& record) {
      stopped = on_iteration && !on_iteration(record);
      return !stopped;
    }));
  }
  if (stopped) return Status::Error("interrupted while looking for the lamp (nothing written)");
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-9);
  const LightSpec& light = dataset.lights[map];
  SFT_RETURN_IF_ERROR(
      LampFromEnvironment(r->EnvironmentTexels(), light.world_from_env, light.frame,
                          ObjectCentreInFrame(mesh, dataset, r->view_indices(), light.frame),
                          lamp_distance * radius, search));
  search->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace sft
