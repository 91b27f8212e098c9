#include "src/capture/import_normalization.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sft {
namespace {

bool InsideMask(const ObservingView& view, const Eigen::Vector3d& p_in_world) {
  const Eigen::Vector3d p_in_cam = view.cam_from_world * p_in_world;
  if (!(p_in_cam.z() > 0)) return false;
  const Eigen::Vector2d pixel = view.camera.ImageFromCam(p_in_cam);
  if (!pixel.allFinite()) return false;
  const double x = std::floor(pixel.x()), y = std::floor(pixel.y());
  const MaskBits& mask = *view.mask;
  if (x < 0 || y < 0 || x >= mask.width || y >= mask.height) return false;
  return mask.inside[static_cast<size_t>(y) * mask.width + static_cast<size_t>(x)] != 0;
}

bool NearOpticalAxis(const ObservingView& view, const Eigen::Vector3d& p_in_world, double cone) {
  const Eigen::Vector3d p_in_cam = view.cam_from_world * p_in_world;
  if (!(p_in_cam.z() > 0)) return false;
  const Eigen::Vector2d focal = view.camera.Focal();
  const double half_x = 0.5 * view.camera.width / focal.x();
  const double half_y = 0.5 * view.camera.height / focal.y();
  const double u = p_in_cam.x() / p_in_cam.z() / (cone * half_x);
  const double v = p_in_cam.y() / p_in_cam.z() / (cone * half_y);
  return u * u + v * v <= 1.0;
}

// The value at percentile `q` (in [0, 100]) of `values` (nearest rank; reorders `values`).
double Percentile(std::vector<double>* values, double q) {
  const size_t n = values->size();
  const size_t k = std::min(n - 1, static_cast<size_t>(std::floor(q / 100.0 * (n - 1) + 0.5)));
  std::nth_element(values->begin(), values->begin() + k, values->end());
  return (*values)[k];
}

// The support plane among the points that registered views observe (docs/import.md).
SupportPlane FindPlane(const ColmapModel& model,
                       const std::unordered_map<uint32_t, ObservingView>& views,
                       const SupportPlaneOptions& options) {
  std::vector<Eigen::Vector3d> points, centres;
  for (const ColmapPoint3D& point : model.points) {
    for (const ColmapTrackElement& e : point.track) {
      if (views.count(e.image_id) > 0) {
        points.push_back(point.xyz);
        break;
      }
    }
  }
  for (const auto& [id, view] : views) centres.push_back(view.cam_from_world.Inverse().translation);
  return FindSupportPlane(points, centres, options);
}

std::string Text(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

}  // namespace

bool NormalizationOptions::Check(std::string* why) const {
  if (!(axis_cone > 0 && axis_cone <= 1)) {
    *why = "--axis-cone: must be in (0, 1], got " + Text(axis_cone);
    return false;
  }
  if (!(percentile >= 0 && percentile < 50)) {
    *why = "--percentile: must be in [0, 50), got " + Text(percentile);
    return false;
  }
  if (min_points < 1) {
    *why = "min_points: must be >= 1, got " + std::to_string(min_points);
    return false;
  }
  return plane.Check(why);
}

Status ComputeNormalization(const ColmapModel& model,
                            const std::unordered_map<uint32_t, ObservingView>& views,
                            const NormalizationOptions& options, NormalizationResult* result) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("normalisation: " + why);
  bool masks = !views.empty();
  for (const auto& [id, view] : views) masks = masks && view.mask != nullptr;
  *result = NormalizationResult();
  result->method = masks ? "masks" : "optical_axes";
  result->used.assign(model.points.size(), false);
  if (!masks) result->plane = FindPlane(model, views, options.plane);
  std::vector<Eigen::Vector3d> kept;
  for (size_t i = 0; i < model.points.size(); ++i) {
    const ColmapPoint3D& point = model.points[i];
    int observing = 0, votes = 0;
    for (const ColmapTrackElement& e : point.track) {
      const auto it = views.find(e.image_id);
      if (it == views.end()) continue;
      ++observing;
      votes += masks ? InsideMask(it->second, point.xyz)
                     : NearOpticalAxis(it->second, point.xyz, options.axis_cone);
    }
    if (observing == 0) continue;
    ++result->points_total;
    // Masks: a strict majority; optical axes: at least half (docs/import.md).
    const bool object = masks ? 2 * votes > observing
                              : 2 * votes >= observing && !result->plane.OffObject(point.xyz);
    if (!object) continue;
    result->used[i] = true;
    kept.push_back(point.xyz);
  }
  result->points_used = static_cast<int>(kept.size());
  if (result->points_used < options.min_points) {
    return Status::Error("normalisation: only " + std::to_string(result->points_used) + " of " +
                         std::to_string(result->points_total) + " sparse points " +
                         (masks
                              ? "project inside the masks in most of their views"
                              : "are seen near the optical axes by at least half of their views") +
                         " (need " + std::to_string(options.min_points) + ")");
  }
  Eigen::Vector3d lo, hi;
  const double q = masks ? 0.0 : options.percentile;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values(kept.size());
    for (size_t i = 0; i < kept.size(); ++i) values[i] = kept[i][axis];
    lo[axis] = Percentile(&values, q);
    hi[axis] = Percentile(&values, 100.0 - q);
  }
  result->centre = 0.5 * (lo + hi);
  result->diagonal = (hi - lo).norm();
  if (!(result->diagonal > 0) || !std::isfinite(result->diagonal)) {
    return Status::Error("normalisation: the object's sparse points have zero extent");
  }
  return Status::Ok();
}

}  // namespace sft
