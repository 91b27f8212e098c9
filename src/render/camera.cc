#include "src/render/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

// The undistorted radius r (of normalized coordinates) up to which the radial distortion
// r·(1 + k1 r² + k2 r⁴) increases: the smallest r > 0 with 1 + 3 k1 r² + 5 k2 r⁴ = 0, or +inf
// when it increases everywhere. Beyond it the distortion folds back: image points past its image
// d(r_max) have no preimage, and closer ones have a second, spurious preimage beyond r_max.
double RadialMonotonicLimit(double k1, double k2) {
  // Roots s = r² of 5 k2 s² + 3 k1 s + 1.
  double s = std::numeric_limits<double>::infinity();
  if (k2 == 0.0) {
    if (k1 < 0.0) s = -1.0 / (3.0 * k1);
  } else {
    const double disc = 9.0 * k1 * k1 - 20.0 * k2;
    if (disc >= 0.0) {
      for (const double sign : {-1.0, 1.0}) {
        const double root = (-3.0 * k1 + sign * std::sqrt(disc)) / (10.0 * k2);
        if (root > 0.0) s = std::min(s, root);
      }
    }
  }
  return std::sqrt(s);
}

double RadialDistorted(double r, double k1, double k2) {
  const double r2 = r * r;
  return r * (1.0 + k1 * r2 + k2 * r2 * r2);
}

// Inverts the radial distortion on [0, r_max]: the r with RadialDistorted(r) = rd, by Newton's
// method kept inside a shrinking bracket (the function increases there, so the root is unique).
// False when rd lies past the fold (no preimage).
bool InvertRadial(double rd, double k1, double k2, double r_max, double* r) {
  double lo = 0.0, hi = r_max;
  if (std::isinf(r_max)) {  // Increasing everywhere: find an upper bracket.
    hi = std::max(1.0, rd);
    while (RadialDistorted(hi, k1, k2) < rd) hi *= 2.0;
  } else if (RadialDistorted(r_max, k1, k2) < rd) {
    return false;
  }
  double x = std::min(rd, hi);
  for (int iter = 0; iter < 200; ++iter) {
    const double f = RadialDistorted(x, k1, k2) - rd;
    if (std::abs(f) <= 1e-15 * std::max(1.0, rd)) break;
    (f < 0.0 ? lo : hi) = x;
    const double x2 = x * x;
    const double slope = 1.0 + 3.0 * k1 * x2 + 5.0 * k2 * x2 * x2;
    double next = slope > 0.0 ? x - f / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next == x) break;
    x = next;
  }
  *r = x;
  return true;
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

double Camera::MaxUndistortedRadius() const {
  double k1, k2, p1, p2;
  if (!DistortionCoefficients(*this, &k1, &k2, &p1, &p2)) {
    return std::numeric_limits<double>::infinity();
  }
  return RadialMonotonicLimit(k1, k2);
}

bool Camera::RayFromImage(const Eigen::Vector2d& pixel, Eigen::Vector3d* ray) const {
  const Eigen::Vector2d distorted = (pixel - Principal()).cwiseQuotient(Focal());
  double k1, k2, p1, p2;
  if (!DistortionCoefficients(*this, &k1, &k2, &p1, &p2)) {
    *ray = Eigen::Vector3d(distorted.x(), distorted.y(), 1.0);
    return true;
  }
  // The radial part alone, inverted on the increasing branch [0, r_max].
  const double r_max = RadialMonotonicLimit(k1, k2);
  const double rd = distorted.norm();
  double r = 0.0;
  if (!InvertRadial(rd, k1, k2, r_max, &r)) return false;
  Eigen::Vector2d uv = rd > 0.0 ? Eigen::Vector2d(distorted * (r / rd)) : distorted;
  if (p1 != 0.0 || p2 != 0.0) {
    // Tangential terms: Newton's method on g(uv) = uv + D(uv) − distorted with a central-
    // difference Jacobian, as COLMAP's IterativeUndistortion, from the radial solution.
    bool converged = false;
    for (int iter = 0; iter < 100; ++iter) {
      const Eigen::Vector2d residual = uv + Distortion(*this, uv) - distorted;
      if (residual.squaredNorm() < 1e-28) {
        converged = true;
        break;
      }
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
    // A solution past the radial fold belongs to the spurious branch; one that was not reached
    // (residual above 1e-7 of the normalized image) is no solution.
    const double error = (uv + Distortion(*this, uv) - distorted).norm();
    if (!converged && !(error < 1e-7)) return false;
    if (!(uv.norm() <= r_max) || !uv.allFinite()) return false;
  }
  *ray = Eigen::Vector3d(uv.x(), uv.y(), 1.0);
  return true;
}

Eigen::Vector3d Camera::CamFromImage(const Eigen::Vector2d& pixel) const {
  Eigen::Vector3d ray;
  if (!RayFromImage(pixel, &ray)) return Eigen::Vector3d::Zero();
  return ray;
}

Camera DownscaledCamera(const Camera& camera, int log2_factor) {
  Camera scaled = camera;
  if (log2_factor <= 0) return scaled;
  const int factor = 1 << log2_factor;
  scaled.width = (camera.width + factor - 1) / factor;
  scaled.height = (camera.height + factor - 1) / factor;
  // Focal lengths and principal point lead the parameter list: f, cx, cy for the simple models,
  // fx, fy, cx, cy for the others (CameraModelNumParams' order).
  const bool simple = camera.model == CameraModel::kSimplePinhole ||
                      camera.model == CameraModel::kSimpleRadial ||
                      camera.model == CameraModel::kRadial;
  const int pixel_params = simple ? 3 : 4;
  for (int i = 0; i < pixel_params && i < static_cast<int>(scaled.params.size()); ++i) {
    scaled.params[i] /= factor;
  }
  return scaled;
}

}  // namespace sft
