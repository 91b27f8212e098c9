// Pinhole calibrations given as matrices, as the Middlebury (K, R, t) and IDR/NeuS (P = K[R|t])
// formats store them: splitting a projection matrix, checking a rotation, and turning K into an
// sft camera (src/render/camera.h). Eigen only, so the format parsers that use it can be fuzzed
// alone.
//
// Conventions: P maps a world point X (homogeneous) to λ·(u, v, 1) = P·X; K[R|t] has R a rotation
// and t such that p_cam = R·X + t (world to camera, the camera looking along +z with +y down, as
// in sft and OpenCV). Pixel coordinates: calibrations from OpenCV and Matlab-style tools put the
// centre of pixel (0, 0) at (0, 0), sft (and COLMAP) at (0.5, 0.5); CameraFromIntrinsics adds
// `pixel_centre_offset` to the principal point to convert.
#ifndef SFT_IO_PINHOLE_MATRICES_H_
#define SFT_IO_PINHOLE_MATRICES_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "src/render/camera.h"

namespace sft {

// A skew entry K(0,1) is accepted (and dropped: sft's cameras have none) while dropping it moves
// no pixel of the image by more than this many pixels.
constexpr double kMaxSkewShiftPixels = 0.1;
// A rotation matrix is accepted when every entry of R·Rᵀ − I is within this tolerance.
constexpr double kRotationTolerance = 1e-3;

struct PinholeCalibration {
  Eigen::Matrix3d intrinsics = Eigen::Matrix3d::Identity();  // K, upper triangular, K(2,2) = 1.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();    // R, det +1.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();     // t.
};

// Splits P = λ·K[R|t] (any λ ≠ 0, either sign) by an RQ decomposition of its left 3×3 block: K
// upper triangular with a positive diagonal, scaled to K(2,2) = 1, and R a rotation. False with
// the reason in *why when P has a non-finite entry or a singular left block.
bool DecomposeProjectionMatrix(const Eigen::Matrix<double, 3, 4>& projection,
                               PinholeCalibration* calibration, std::string* why);

// The rotation nearest to `matrix` (SVD), after checking that `matrix` is one: finite, R·Rᵀ
// within kRotationTolerance of I and det R > 0. False with the reason otherwise.
bool RotationFromMatrix(const Eigen::Matrix3d& matrix, Eigen::Quaterniond* rotation,
                        std::string* why);

// A PINHOLE camera of `width` × `height` from K: K(1,0) = K(2,0) = K(2,1) = 0, K(2,2) ≠ 0 (K is
// divided by it), positive focal lengths, a skew that moves no pixel by more than
// kMaxSkewShiftPixels (it is dropped). `pixel_centre_offset` is added to cx and cy (0.5 for
// calibrations whose pixel centres sit at integer coordinates). False with the reason otherwise.
bool CameraFromIntrinsics(const Eigen::Matrix3d& intrinsics, int width, int height,
                          double pixel_centre_offset, Camera* camera, std::string* why);

}  // namespace sft

#endif  // SFT_IO_PINHOLE_MATRICES_H_
