#include "src/capture/support_plane.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace sft {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t k = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

// Median viewing distance: camera centre to the per-axis median of the points.
double ViewingDistance(const std::vector<Eigen::Vector3d>& points,
                       const std::vector<Eigen::Vector3d>& cameras) {
  Eigen::Vector3d middle;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    values.reserve(points.size());
    for (const Eigen::Vector3d& p : points) values.push_back(p[axis]);
    middle[axis] = Median(values);
  }
  std::vector<double> distances;
  for (const Eigen::Vector3d& c : cameras) distances.push_back((c - middle).norm());
  return Median(distances);
}

int CountWithin(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& normal,
                double offset, double band) {
  int count = 0;
  for (const Eigen::Vector3d& p : points) count += std::abs(normal.dot(p) + offset) <= band;
  return count;
}

// Least-squares plane (the smallest principal axis) through the points within `band`.
void Refit(const std::vector<Eigen::Vector3d>& points, double band, Eigen::Vector3d* normal,
           double* offset) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const Eigen::Vector3d& p : points) {
    if (std::abs(normal->dot(p) + *offset) <= band) {
      mean += p;
      ++n;
    }
  }
  if (n < 3) return;
  mean /= n;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    if (std::abs(normal->dot(p) + *offset) <= band) scatter += (p - mean) * (p - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  *normal = solver.eigenvectors().col(0).normalized();
  *offset = -normal->dot(mean);
}

}  // namespace

bool SupportPlaneOptions::Check(std::string* why) const {
  char text[160];
  if (!(distance > 0 && distance <= 0.2)) {
    std::snprintf(text, sizeof(text), "--plane-distance: must be in (0, 0.2], got %g", distance);
  } else if (!(min_fraction > 0 && min_fraction <= 1)) {
    std::snprintf(text, sizeof(text), "plane min_fraction: must be in (0, 1], got %g",
                  min_fraction);
  } else if (!(camera_fraction > 0.5 && camera_fraction <= 1)) {
    std::snprintf(text, sizeof(text), "plane camera_fraction: must be in (0.5, 1], got %g",
                  camera_fraction);
  } else if (iterations < 1 || iterations > 1000000) {
    std::snprintf(text, sizeof(text), "plane iterations: must be in [1, 1e6], got %d", iterations);
  } else {
    return true;
  }
  *why = text;
  return false;
}

SupportPlane FindSupportPlane(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Eigen::Vector3d>& camera_centres,
                              const SupportPlaneOptions& options) {
  SupportPlane plane;
  if (!options.enabled || points.size() < 3 || camera_centres.empty()) return plane;
  const double band = options.distance * ViewingDistance(points, camera_centres);
  if (!(band > 0) || !std::isfinite(band)) return plane;
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  Eigen::Vector3d best_normal = Eigen::Vector3d::UnitZ();
  double best_offset = 0;
  int best = -1;
  for (int it = 0; it < options.iterations; ++it) {
    const Eigen::Vector3d& a = points[pick(rng)];
    const Eigen::Vector3d& b = points[pick(rng)];
    const Eigen::Vector3d& c = points[pick(rng)];
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    if (!(cross.norm() > 1e-12 * band * band)) continue;
    const Eigen::Vector3d normal = cross.normalized();
    const double offset = -normal.dot(a);
    const int count = CountWithin(points, normal, offset, band);
    if (count > best) {
      best = count;
      best_normal = normal;
      best_offset = offset;
    }
  }
  if (best < options.min_fraction * static_cast<double>(points.size())) return plane;
  Refit(points, band, &best_normal, &best_offset);
  int positive = 0, negative = 0;
  for (const Eigen::Vector3d& c : camera_centres) {
    const double d = best_normal.dot(c) + best_offset;
    positive += d > band;
    negative += d < -band;
  }
  const double needed = options.camera_fraction * static_cast<double>(camera_centres.size());
  if (negative > positive) {
    best_normal = -best_normal;
    best_offset = -best_offset;
    std::swap(positive, negative);
  }
  if (positive < needed) return plane;
  plane.found = true;
  plane.normal = best_normal;
  plane.offset = best_offset;
  plane.band = band;
  plane.inliers = CountWithin(points, best_normal, best_offset, band);
  for (const Eigen::Vector3d& p : points) plane.off_object += plane.OffObject(p);
  return plane;
}

bool FindSupportDisc(const SupportPlane& plane, const std::vector<Eigen::Vector3d>& points,
                     const Eigen::Vector3d& object_centre, double quantile, Eigen::Vector3d* centre,
                     double* radius) {
  if (!plane.found) return false;
  *centre = object_centre - plane.SignedDistance(object_centre) * plane.normal;
  std::vector<double> distances;
  for (const Eigen::Vector3d& p : points) {
    if (std::abs(plane.SignedDistance(p)) > plane.band) continue;
    const Eigen::Vector3d d = p - *centre;
    distances.push_back((d - d.dot(plane.normal) * plane.normal).norm());
  }
  if (distances.empty()) return false;
  const size_t k = std::min(distances.size() - 1,
                            static_cast<size_t>(std::clamp(quantile, 0.0, 1.0) * distances.size()));
  std::nth_element(distances.begin(), distances.begin() + k, distances.end());
  *radius = distances[k];
  return *radius > 0;
}

}  // namespace sft
