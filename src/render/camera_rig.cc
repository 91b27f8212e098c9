#include "src/render/camera_rig.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace sft {

Rigid3d LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
               const Eigen::Vector3d& up) {
  const Eigen::Vector3d forward = (target - center).normalized();
  Eigen::Vector3d right = forward.cross(up);
  if (right.norm() < 1e-6) right = forward.cross(Eigen::Vector3d(0, 1, 0));
  right.normalize();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d rotation;
  rotation.row(0) = right;
  rotation.row(1) = down;
  rotation.row(2) = forward;
  Rigid3d cam_from_world;
  cam_from_world.rotation = Eigen::Quaterniond(rotation).normalized();
  if (cam_from_world.rotation.w() < 0) cam_from_world.rotation.coeffs() *= -1.0;
  cam_from_world.translation = -(rotation * center);
  return cam_from_world;
}

Eigen::Vector3d FibonacciSphereDirection(int k, int n) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - (2.0 * k + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = golden * k;
  return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
}

double OrbitDistance(double radius, double fov_deg, double fill) {
  return radius / (fill * std::tan(0.5 * fov_deg * M_PI / 180.0));
}

double OrbitFocal(int resolution, double fov_deg) {
  return 0.5 * resolution / std::tan(0.5 * fov_deg * M_PI / 180.0);
}

}  // namespace sft
