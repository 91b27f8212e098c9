// Cameras in COLMAP's conventions (docs/dataset.md): models and parameter order as COLMAP's
// cameras.txt; the camera looks along +z with +x right and +y down; pixel (x, y) covers [x, x+1] x
// [y, y+1] so the upper-left pixel's centre is (0.5, 0.5); `cam_from_world` maps world points into
// the camera frame.
#ifndef SFT_RENDER_CAMERA_H_
#define SFT_RENDER_CAMERA_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

enum class CameraModel { kSimplePinhole, kPinhole, kSimpleRadial, kRadial, kOpenCV };

// "SIMPLE_PINHOLE" -> kSimplePinhole etc.; false for unknown names.
bool CameraModelFromName(const std::string& name, CameraModel* model);
std::string CameraModelName(CameraModel model);
// Number of entries of `params` for the model (COLMAP order):
//   SIMPLE_PINHOLE f, cx, cy | PINHOLE fx, fy, cx, cy | SIMPLE_RADIAL f, cx, cy, k |
//   RADIAL f, cx, cy, k1, k2 | OPENCV fx, fy, cx, cy, k1, k2, p1, p2
int CameraModelNumParams(CameraModel model);

// A rigid transform y = rotation * x + translation (rotation a unit quaternion).
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  Rigid3d Inverse() const {
    Rigid3d inv;
    inv.rotation = rotation.conjugate();
    inv.translation = -(inv.rotation * translation);
    return inv;
  }
};

struct Camera {
  std::string id;
  CameraModel model = CameraModel::kPinhole;
  int width = 0;   // pixels
  int height = 0;  // pixels
  std::vector<double> params;

  // Empty string when valid; else what is wrong ("params: PINHOLE needs 4 values, got 3").
  bool Check(std::string* why) const;

  // Projects a point in the camera frame (z > 0) to image coordinates, with distortion.
  Eigen::Vector2d ImageFromCam(const Eigen::Vector3d& p_in_cam) const;
  // ∂ImageFromCam/∂p_in_cam (2×3), analytic, distortion included (z > 0).
  Eigen::Matrix<double, 2, 3> ImageFromCamJacobian(const Eigen::Vector3d& p_in_cam) const;
  // Inverse of ImageFromCam up to scale: a direction (x, y, 1) in the camera frame whose
  // projection is `pixel`. False when no ray projects there: past the fold of a distortion whose
  // radial part r·(1 + k1 r² + k2 r⁴) stops increasing at r = MaxUndistortedRadius() (e.g. a
  // strongly negative k1), or where the tangential terms' Newton iteration does not converge.
  // The radial part is inverted on its increasing branch only, so no pixel gets the spurious
  // preimage beyond the fold.
  bool RayFromImage(const Eigen::Vector2d& pixel, Eigen::Vector3d* ray) const;
  // RayFromImage's ray, or the zero vector for pixels without one. A zero direction is the
  // renderer's "no ray": Embree finds no hit along it (it asserts on NaN directions, so NaN is not
  // an option) and the environment gives it no radiance, so the sample is empty (black, alpha 0).
  Eigen::Vector3d CamFromImage(const Eigen::Vector2d& pixel) const;
  // The undistorted radius (normalized coordinates) up to which the radial distortion increases;
  // +inf for the pinhole models and distortions that increase everywhere.
  double MaxUndistortedRadius() const;

  // Focal lengths in pixels (fx, fy).
  Eigen::Vector2d Focal() const;
  Eigen::Vector2d Principal() const;
};

// The camera of the same view at 2^-log2_factor of its resolution: ⌈w/2^k⌉ × ⌈h/2^k⌉ pixels,
// focal lengths and principal point divided by 2^k (pixel (x, y) covers [x, x+1] × [y, y+1], so
// the continuous image coordinates scale exactly; a coarse pixel is the box mean of its 2^k × 2^k
// children, as the pyramid's levels are). Distortion coefficients act on normalized coordinates
// and stay as they are. log2_factor ≥ 0.
Camera DownscaledCamera(const Camera& camera, int log2_factor);

}  // namespace sft

#endif  // SFT_RENDER_CAMERA_H_
