#include "src/render/internal/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sft {
namespace render_internal {

DiscreteDistribution::DiscreteDistribution(const std::vector<double>& weights)
    : weights_(weights), cumulative_(weights.size()) {
  const int n = static_cast<int>(weights.size());
  for (int i = 0; i < n; ++i) cumulative_[i] = total_ += weights[i];
  if (!(total_ > 0.0) || !std::isfinite(total_)) return;
  cells_.resize(n);
  std::vector<double> scaled(n);
  std::vector<int> small, large;
  for (int i = 0; i < n; ++i) {
    scaled[i] = weights[i] * n / total_;
    (scaled[i] < 1.0 ? small : large).push_back(i);
  }
  while (!small.empty() && !large.empty()) {
    const int s = small.back(), l = large.back();
    small.pop_back();
    cells_[s] = {scaled[s], l};
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // Left-overs are 1 up to rounding.
  for (int i : small) cells_[i] = {1.0, i};
  for (int i : large) cells_[i] = {1.0, i};
}

int DiscreteDistribution::SampleInverse(double u) const {
  const double target = u * cumulative_.back();
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), target);
  return std::min<int>(static_cast<int>(it - cumulative_.begin()),
                       static_cast<int>(cumulative_.size()) - 1);
}

int DiscreteDistribution::Sample(double u) const {
  const double scaled = u * static_cast<double>(cells_.size());
  const int i = std::min(static_cast<int>(scaled), static_cast<int>(cells_.size()) - 1);
  return scaled - i < cells_[i].probability ? i : cells_[i].alias;
}

FrustumBounds ViewFrustum(const Camera& camera, double scene_extent) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  FrustumBounds b{kInf, -kInf, kInf, -kInf, 0.0};
  constexpr int kSteps = 16;
  for (int i = 0; i <= kSteps; ++i) {
    const double t = static_cast<double>(i) / kSteps;
    for (const Eigen::Vector2d& pixel :
         {Eigen::Vector2d(t * camera.width, 0.0), Eigen::Vector2d(t * camera.width, camera.height),
          Eigen::Vector2d(0.0, t * camera.height),
          Eigen::Vector2d(camera.width, t * camera.height)}) {
      const Eigen::Vector3d ray = camera.CamFromImage(pixel);
      b.u_min = std::min(b.u_min, ray.x());
      b.u_max = std::max(b.u_max, ray.x());
      b.v_min = std::min(b.v_min, ray.y());
      b.v_max = std::max(b.v_max, ray.y());
    }
  }
  const double mu = 0.05 * (b.u_max - b.u_min), mv = 0.05 * (b.v_max - b.v_min);
  b.u_min -= mu;
  b.u_max += mu;
  b.v_min -= mv;
  b.v_max += mv;
  b.z_min = 1e-7 * scene_extent;
  return b;
}

bool ClipSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const FrustumBounds& f,
                 double* s0, double* s1) {
  *s0 = 0.0;
  *s1 = 1.0;
  // Half-spaces h(p) ≥ 0, each linear in p.
  auto clip = [&](double ha, double hb) {
    if (ha >= 0.0 && hb >= 0.0) return true;
    if (ha < 0.0 && hb < 0.0) return false;
    const double s = ha / (ha - hb);
    if (ha < 0.0)
      *s0 = std::max(*s0, s);
    else
      *s1 = std::min(*s1, s);
    return *s0 < *s1;
  };
  return clip(a.z() - f.z_min, b.z() - f.z_min) &&
         clip(a.x() - f.u_min * a.z(), b.x() - f.u_min * b.z()) &&
         clip(f.u_max * a.z() - a.x(), f.u_max * b.z() - b.x()) &&
         clip(a.y() - f.v_min * a.z(), b.y() - f.v_min * b.z()) &&
         clip(f.v_max * a.z() - a.y(), f.v_max * b.z() - b.y()) && *s1 - *s0 > 0.0;
}

bool AngleUniformEdgePoint(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& x, double xi, double* s, double* subtended) {
  const Eigen::Vector3d da = a - x, db = b - x;
  const Eigen::Vector3d k = da.cross(db);
  const double k_norm = k.norm();
  if (!(k_norm > 0.0) || !std::isfinite(k_norm)) return false;
  *subtended = std::atan2(k_norm, da.dot(db));
  if (!(*subtended > 0.0)) return false;
  const Eigen::Vector3d ua = da.normalized();
  const Eigen::Vector3d w = (k / k_norm).cross(ua);  // in the plane, ⊥ ua, towards b.
  const double theta = xi * *subtended;
  const Eigen::Vector3d omega = std::cos(theta) * ua + std::sin(theta) * w;
  // (a − x + s(b − a)) × ω = 0 along k.
  const double denominator = (b - a).cross(omega).dot(k);
  if (!(std::abs(denominator) > 0.0)) return false;
  *s = std::clamp(-da.cross(omega).dot(k) / denominator, 0.0, 1.0);
  return std::isfinite(*s);
}

}  // namespace render_internal
}  // namespace sft
