#include "src/render/camera.h"

#include <cmath>

namespace sft {
namespace {

struct ModelInfo {
  CameraModel model;
  const char* name;
  int num_params;
};
constexpr ModelInfo kModels[] = {
    {CameraModel::kSimplePinhole, "SIMPLE_PINHOLE", 3},
    {CameraModel::kPinhole, "PINHOLE", 4},
    {CameraModel::kSimpleRadial, "SIMPLE_RADIAL", 4},
    {CameraModel::kRadial, "RADIAL", 5},
    {CameraModel::kOpenCV, "OPENCV", 8},
};

const ModelInfo& Info(CameraModel model) {
  for (const ModelInfo& info : kModels) {
    if (info.model == model) return info;
  }
  return kModels[1];
}

// The distortion coefficients (k1, k2, p1, p2) of the model, zero where it has none; false for
// the pinhole models (no distortion at all).
bool DistortionCoefficients(const Camera& camera, double* k1, double* k2, double* p1, double* p2) {
  const std::vector<double>& p = camera.params;
  *k1 = *k2 = *p1 = *p2 = 0.0;
  switch (camera.model) {
    case CameraModel::kSimplePinhole:
    case CameraModel::kPinhole:
      return false;
    case CameraModel::kSimpleRadial:
      *k1 = p[3];
      break;
    case CameraModel::kRadial:
      *k1 = p[3];
      *k2 = p[4];
      break;
    case CameraModel::kOpenCV:
      *k1 = p[4];
      *k2 = p[5];
      *p1 = p[6];
      *p2 = p[7];
      break;
  }
  return true;
}

// COLMAP's distortion offsets (du, dv) of normalized coordinates (u, v).
Eigen::Vector2d Distortion(const Camera& camera, const Eigen::Vector2d& uv) {
  double k1, k2, p1, p2;
  if (!DistortionCoefficients(camera, &k1, &k2, &p1, &p2)) return Eigen::Vector2d::Zero();
  const double u = uv.x(), v = uv.y();
  const double u2 = u * u, v2 = v * v, uv_ = u * v, r2 = u2 + v2;
  const double radial = k1 * r2 + k2 * r2 * r2;
  return {u * radial + 2.0 * p1 * uv_ + p2 * (r2 + 2.0 * u2),
          v * radial + 2.0 * p2 * uv_ + p1 * (r2 + 2.0 * v2)};
}

// ∂Distortion/∂(u, v) of the function above.
Eigen::Matrix2d DistortionJacobian(const Camera& camera, const Eigen::Vector2d& uv) {
  double k1, k2, p1, p2;
  if (!DistortionCoefficients(camera, &k1, &k2, &p1, &p2)) return Eigen::Matrix2d::Zero();
  const double u = uv.x(), v = uv.y();
  const double r2 = u * u + v * v;
  const double radial = k1 * r2 + k2 * r2 * r2;
  const double d_radial = 2.0 * (k1 + 2.0 * k2 * r2);  // ∂radial/∂u = d_radial·u, same for v.
  Eigen::Matrix2d j;
  j(0, 0) = radial + u * d_radial * u + 2.0 * p1 * v + 6.0 * p2 * u;
  j(0, 1) = u * d_radial * v + 2.0 * p1 * u + 2.0 * p2 * v;
  j(1, 0) = v * d_radial * u + 2.0 * p2 * v + 2.0 * p1 * u;
  j(1, 1) = radial + v * d_radial * v + 2.0 * p2 * u + 6.0 * p1 * v;
  return j;
}

}  // namespace

bool CameraModelFromName(const std::string& name, CameraModel* model) {
  for (const ModelInfo& info : kModels) {
    if (name == info.name) {
      *model = info.model;
      return true;
    }
  }
  return false;
}

std::string CameraModelName(CameraModel model) { return Info(model).name; }
int CameraModelNumParams(CameraModel model) { return Info(model).num_params; }

bool Camera::Check(std::string* why) const {
  if (width <= 0 || height <= 0) {
    *why = "width/height: must be positive, got " + std::to_string(width) + "x" +
           std::to_string(height);
    return false;
  }
  const int n = CameraModelNumParams(model);
  if (static_cast<int>(params.size()) != n) {
    *why = "params: " + CameraModelName(model) + " needs " + std::to_string(n) + " values, got " +
           std::to_string(params.size());
    return false;
  }
  for (double p : params) {
    if (!std::isfinite(p)) {
      *why = "params: values must be finite";
      return false;
    }
  }
  const Eigen::Vector2d f = Focal();
  if (!(f.x() > 0) || !(f.y() > 0)) {
    *why = "params: focal lengths must be positive";
    return false;
  }
  return true;
}

Eigen::Vector2d Camera::Focal() const {
  switch (model) {
    case CameraModel::kPinhole:
    case CameraModel::kOpenCV:
      return {params[0], params[1]};
    default:
      return {params[0], params[0]};
  }
}

Eigen::Vector2d Camera::Principal() const {
  switch (model) {
    case CameraModel::kPinhole:
    case CameraModel::kOpenCV:
      return {params[2], params[3]};
    default:
      return {params[1], params[2]};
  }
}

Eigen::Vector2d Camera::ImageFromCam(const Eigen::Vector3d& p_in_cam) const {
  const Eigen::Vector2d uv(p_in_cam.x() / p_in_cam.z(), p_in_cam.y() / p_in_cam.z());
  const Eigen::Vector2d distorted = uv + Distortion(*this, uv);
  return Focal().cwiseProduct(distorted) + Principal();
}

Eigen::Matrix<double, 2, 3> Camera::ImageFromCamJacobian(const Eigen::Vector3d& p_in_cam) const {
  const double inv_z = 1.0 / p_in_cam.z();
  const Eigen::Vector2d uv(p_in_cam.x() * inv_z, p_in_cam.y() * inv_z);
  Eigen::Matrix<double, 2, 3> d_uv;
  d_uv << inv_z, 0.0, -uv.x() * inv_z, 0.0, inv_z, -uv.y() * inv_z;
  const Eigen::Matrix2d d_distorted = Eigen::Matrix2d::Identity() + DistortionJacobian(*this, uv);
  return Focal().asDiagonal() * d_distorted * d_uv;
}

Eigen::Vector3d Camera::CamFromImage(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d distorted = (pixel - Principal()).cwiseQuotient(Focal());
  Eigen::Vector2d uv = distorted;
  if (model != CameraModel::kPinhole && model != CameraModel::kSimplePinhole) {
    // Newton's method on g(uv) = uv + D(uv) - distorted with a central-difference Jacobian,
    // as COLMAP's IterativeUndistortion; converges in a few steps for realistic distortion.
    for (int iter = 0; iter < 100; ++iter) {
      const Eigen::Vector2d residual = uv + Distortion(*this, uv) - distorted;
      if (residual.squaredNorm() < 1e-28) break;
      Eigen::Matrix2d jacobian;
      for (int d = 0; d < 2; ++d) {
        const double step = 1e-7 * std::max(1.0, std::abs(uv[d]));
        Eigen::Vector2d a = uv, b = uv;
        a[d] += step;
        b[d] -= step;
        jacobian.col(d) = (a + Distortion(*this, a) - b - Distortion(*this, b)) / (2.0 * step);
      }
      const Eigen::Vector2d delta = jacobian.partialPivLu().solve(residual);
      if (!delta.allFinite()) break;
      uv -= delta;
    }
  }
  return {uv.x(), uv.y(), 1.0};
}

}  // namespace sft
