#include "src/io/pinhole_matrices.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>

namespace sft {
namespace {

std::string Number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", value);
  return buffer;
}

}  // namespace

bool DecomposeProjectionMatrix(const Eigen::Matrix<double, 3, 4>& projection,
                               PinholeCalibration* calibration, std::string* why) {
  if (!projection.allFinite()) {
    *why = "the projection matrix has a non-finite entry";
    return false;
  }
  Eigen::Matrix3d m = projection.leftCols<3>();
  Eigen::Vector3d p4 = projection.col(3);
  const double scale = m.cwiseAbs().maxCoeff();
  if (!(scale > 0) || !(std::abs(m.determinant()) > 1e-12 * scale * scale * scale)) {
    *why = "the left 3x3 block of the projection matrix is singular";
    return false;
  }
  // P is defined up to λ: with det M > 0 the rotation of M = K·R (det K > 0) has det +1.
  if (m.determinant() < 0) {
    m = -m;
    p4 = -p4;
  }
  // RQ from QR: with J the row-reversing permutation, (J·M)ᵀ = Q·U gives M = (J·Uᵀ·J)·(J·Qᵀ), where
  // J·Uᵀ·J is upper triangular and J·Qᵀ orthogonal.
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  j(0, 2) = j(1, 1) = j(2, 0) = 1;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((j * m).transpose());
  const Eigen::Matrix3d q = qr.householderQ();
  const Eigen::Matrix3d u = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d k = j * u.transpose() * j;
  Eigen::Matrix3d r = j * q.transpose();
  // K·R = (K·D)·(D·R) for D = diag(±1): make K's diagonal positive.
  for (int i = 0; i < 3; ++i) {
    if (k(i, i) < 0) {
      k.col(i) = -k.col(i);
      r.row(i) = -r.row(i);
    }
  }
  calibration->translation = k.triangularView<Eigen::Upper>().solve(p4);
  calibration->intrinsics = k / k(2, 2);
  calibration->rotation = r;
  if (!calibration->intrinsics.allFinite() || !calibration->translation.allFinite()) {
    *why = "the projection matrix does not decompose into finite K, R, t";
    return false;
  }
  return true;
}

bool RotationFromMatrix(const Eigen::Matrix3d& matrix, Eigen::Quaterniond* rotation,
                        std::string* why) {
  if (!matrix.allFinite()) {
    *why = "the rotation has a non-finite entry";
    return false;
  }
  const double error =
      (matrix * matrix.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(error <= kRotationTolerance)) {
    *why = "not a rotation: R*R^T differs from the identity by " + Number(error) + " (allowed " +
           Number(kRotationTolerance) + ")";
    return false;
  }
  if (!(matrix.determinant() > 0)) {
    *why = "not a rotation: determinant " + Number(matrix.determinant()) + " (a reflection)";
    return false;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
  *rotation = Eigen::Quaterniond(Eigen::Matrix3d(svd.matrixU() * svd.matrixV().transpose()));
  rotation->normalize();
  return true;
}

bool CameraFromIntrinsics(const Eigen::Matrix3d& intrinsics, int width, int height,
                          double pixel_centre_offset, Camera* camera, std::string* why) {
  if (!intrinsics.allFinite()) {
    *why = "K has a non-finite entry";
    return false;
  }
  if (!(intrinsics(2, 2) != 0)) {
    *why = "K(3,3) is 0";
    return false;
  }
  const Eigen::Matrix3d k = intrinsics / intrinsics(2, 2);
  const double tolerance = 1e-9 * k.cwiseAbs().maxCoeff();
  if (std::abs(k(1, 0)) > tolerance || std::abs(k(2, 0)) > tolerance ||
      std::abs(k(2, 1)) > tolerance) {
    *why = "K is not upper triangular (K(2,1), K(3,1), K(3,2) must be 0)";
    return false;
  }
  if (!(k(0, 0) > 0) || !(k(1, 1) > 0)) {
    *why = "K's focal lengths must be positive, got " + Number(k(0, 0)) + " and " + Number(k(1, 1));
    return false;
  }
  // Dropping the skew s moves pixel (u, v) by s·(v − cy)/fy along u.
  const double rows_from_centre = std::max(std::abs(k(1, 2)), std::abs(height - k(1, 2)));
  const double shift = std::abs(k(0, 1)) * rows_from_centre / k(1, 1);
  if (!(shift <= kMaxSkewShiftPixels)) {
    *why = "K's skew " + Number(k(0, 1)) + " moves pixels by up to " + Number(shift) +
           " px; sft's cameras have no skew (at most " + Number(kMaxSkewShiftPixels) +
           " px is dropped)";
    return false;
  }
  camera->model = CameraModel::kPinhole;
  camera->width = width;
  camera->height = height;
  camera->params = {k(0, 0), k(1, 1), k(0, 2) + pixel_centre_offset, k(1, 2) + pixel_centre_offset};
  return camera->Check(why);
}

}  // namespace sft
