#include "src/render/geometry_derivatives.h"

#include <cmath>

namespace sft {

NormalChain::NormalChain(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                         const Eigen::Vector3d& p2, double sign)
    : e1_(p1 - p0), e2_(p2 - p0) {
  const Eigen::Vector3d n = e1_.cross(e2_);
  const double length = n.norm();
  if (!(length > 0.0) || !std::isfinite(length)) return;  // degenerate: all maps are zero.
  unit_normal_ = n / length;
  projection_ =
      sign / length * (Eigen::Matrix3d::Identity() - unit_normal_ * unit_normal_.transpose());
}

Eigen::Matrix<double, 3, 9> NormalChain::Map(const Eigen::Matrix3d& g) const {
  Eigen::Matrix<double, 3, 9> out;
  for (int c = 0; c < 3; ++c) {
    const Eigen::Vector3d g_hat = projection_ * g.row(c).transpose();
    out.block<1, 3>(c, 0) = (e1_ - e2_).cross(g_hat).transpose();
    out.block<1, 3>(c, 3) = e2_.cross(g_hat).transpose();
    out.block<1, 3>(c, 6) = g_hat.cross(e1_).transpose();
  }
  return out;
}

bool HitPointDerivatives(const Eigen::Vector3d& d, const Eigen::Vector3d& unit_normal,
                         const Eigen::Vector3d& barycentrics,
                         std::array<Eigen::Matrix3d, 3>* d_x_d_p, Eigen::Matrix3d* d_x_d_o) {
  const double cosine = unit_normal.dot(d);
  if (!(std::abs(cosine) > kMinHitCosine * d.norm())) return false;
  const Eigen::Matrix3d along = d * unit_normal.transpose() / cosine;
  for (int j = 0; j < 3; ++j) (*d_x_d_p)[j] = barycentrics[j] * along;
  *d_x_d_o = Eigen::Matrix3d::Identity() - along;
  return true;
}

void PointJacobian::Advance(bool fixed_origin, const Eigen::Vector3d& d,
                            const Eigen::Vector3d& unit_normal, const Eigen::Vector3d& barycentrics,
                            const Eigen::Vector3i& face_vertices) {
  if (fixed_origin) {
    count = 0;
    valid = true;
  }
  if (!valid) return;
  std::array<Eigen::Matrix3d, 3> d_x_d_p;
  Eigen::Matrix3d d_x_d_o;
  if (!HitPointDerivatives(d, unit_normal, barycentrics, &d_x_d_p, &d_x_d_o) ||
      count + 3 > kMaxEntries) {
    valid = false;
    count = 0;
    return;
  }
  for (int e = 0; e < count; ++e) m[e] = d_x_d_o * m[e];
  for (int j = 0; j < 3; ++j) {
    vertex[count] = face_vertices[j];
    m[count] = d_x_d_p[j];
    ++count;
  }
}

}  // namespace sft
