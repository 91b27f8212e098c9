#include "src/render/internal/shading_normal.h"

#include <cmath>

namespace sft {
namespace render_internal {

void ShadingNormalChain::SetFlat(const RenderScene& scene, int face, double sign) {
  const auto& p = scene.positions();
  corners_ = scene.faces()[face];
  flat_ = NormalChain(p[corners_[0]], p[corners_[1]], p[corners_[2]], sign);
  smooth_ = false;
}

void ShadingNormalChain::SetSmooth(const RenderScene& scene, const VertexNormalJacobian& jacobian,
                                   int face, const Eigen::Vector3d& barycentrics, double sign,
                                   bool sliding) {
  SetFlat(scene, face, sign);
  Eigen::Vector3d normals[3];
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j) {
    normals[j] = scene.VertexNormal(corners_[j]);
    m += barycentrics[j] * normals[j];
  }
  const double len = m.norm();
  if (!(len > 0.0) || !std::isfinite(len) || flat_.unit_normal().isZero()) return;
  const auto& p = scene.positions();
  const Eigen::Vector3d e1 = p[corners_[1]] - p[corners_[0]];
  const Eigen::Vector3d e2 = p[corners_[2]] - p[corners_[0]];
  const Eigen::Vector3d n = e1.cross(e2);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0.0) || !std::isfinite(n2)) return;
  const Eigen::Vector3d unit = m / len;
  smooth_ = true;
  use_sliding_ = sliding;
  jacobian_ = &jacobian;
  barycentrics_ = barycentrics;
  projection_ = sign * (Eigen::Matrix3d::Identity() - unit * unit.transpose()) / len;
  const Eigen::Vector3d g1 = e2.cross(n) / n2, g2 = n.cross(e1) / n2;
  sliding_ =
      (normals[1] - normals[0]) * g1.transpose() + (normals[2] - normals[0]) * g2.transpose();
}

void ShadingNormalChain::Map(const Eigen::Matrix3d& g, const PointJacobian& point,
                             VertexGradients* out) const {
  if (!smooth_) {
    const Eigen::Matrix<double, 3, 9> corners = flat_.Map(g);
    for (int j = 0; j < 3; ++j) out->emplace_back(corners_[j], corners.middleCols<3>(3 * j));
    return;
  }
  const Eigen::Matrix3d g_m = g * projection_;  // ∂/∂m.
  for (int j = 0; j < 3; ++j) {
    if (barycentrics_[j] == 0.0) continue;
    const Eigen::Matrix3d g_j = barycentrics_[j] * g_m;
    for (const auto* e = jacobian_->begin(corners_[j]); e != jacobian_->end(corners_[j]); ++e) {
      out->emplace_back(e->vertex, g_j * e->d);
    }
  }
  if (!use_sliding_ || !point.valid) return;
  const Eigen::Matrix3d g_delta = g_m * sliding_;  // ∂/∂δ.
  for (int j = 0; j < 3; ++j) out->emplace_back(corners_[j], -barycentrics_[j] * g_delta);
  for (int e = 0; e < point.count; ++e) out->emplace_back(point.vertex[e], g_delta * point.m[e]);
}

}  // namespace render_internal
}  // namespace sft
