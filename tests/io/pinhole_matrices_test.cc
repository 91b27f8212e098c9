// Projection matrices split into K, R, t; rotations checked; K turned into sft cameras.
#include "src/io/pinhole_matrices.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace sft {
namespace {

using ::testing::HasSubstr;

Eigen::Matrix3d SomeRotation() {
  return Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
}

TEST(PinholeMatricesTest, DecomposeRecoversKRtForAnyScaleAndSign) {
  Eigen::Matrix3d k;
  k << 2892.3, 0.2, 823.2, 0, 2883.2, 619.1, 0, 0, 1;
  const Eigen::Matrix3d r = SomeRotation();
  const Eigen::Vector3d t(-0.3, 0.2, 1.7);
  for (double scale : {1.0, 0.003, -2.5}) {
    Eigen::Matrix<double, 3, 4> p;
    p << k * r, k * t;
    p *= scale;
    PinholeCalibration c;
    std::string why;
    ASSERT_TRUE(DecomposeProjectionMatrix(p, &c, &why)) << why;
    EXPECT_LT((c.intrinsics - k).cwiseAbs().maxCoeff(), 1e-9 * 3000) << scale;
    EXPECT_LT((c.rotation - r).cwiseAbs().maxCoeff(), 1e-12) << scale;
    EXPECT_LT((c.translation - t).cwiseAbs().maxCoeff(), 1e-12) << scale;
  }
}

TEST(PinholeMatricesTest, DecomposeRejectsSingularAndNonFinite) {
  Eigen::Matrix<double, 3, 4> p = Eigen::Matrix<double, 3, 4>::Zero();
  p(0, 0) = p(1, 1) = 1;
  PinholeCalibration c;
  std::string why;
  EXPECT_FALSE(DecomposeProjectionMatrix(p, &c, &why));
  EXPECT_THAT(why, HasSubstr("singular"));
  p(2, 2) = std::nan("");
  EXPECT_FALSE(DecomposeProjectionMatrix(p, &c, &why));
  EXPECT_THAT(why, HasSubstr("non-finite"));
}

TEST(PinholeMatricesTest, RotationCheck) {
  Eigen::Quaterniond q;
  std::string why;
  ASSERT_TRUE(RotationFromMatrix(SomeRotation(), &q, &why)) << why;
  EXPECT_TRUE(q.toRotationMatrix().isApprox(SomeRotation(), 1e-12));
  EXPECT_FALSE(RotationFromMatrix(1.01 * SomeRotation(), &q, &why));
  EXPECT_THAT(why, HasSubstr("not a rotation"));
  EXPECT_FALSE(RotationFromMatrix(-SomeRotation(), &q, &why));
  EXPECT_THAT(why, HasSubstr("reflection"));
}

TEST(PinholeMatricesTest, CameraFromIntrinsicsShiftsThePrincipalPointAndRejectsSkew) {
  Eigen::Matrix3d k;
  k << 3310.4, 0, 316.73, 0, 3325.5, 200.55, 0, 0, 1;
  Camera camera;
  std::string why;
  ASSERT_TRUE(CameraFromIntrinsics(2 * k, 640, 480, 0.5, &camera, &why)) << why;
  EXPECT_EQ(camera.model, CameraModel::kPinhole);
  EXPECT_EQ(camera.width, 640);
  EXPECT_THAT(camera.params, ::testing::ElementsAre(3310.4, 3325.5, 317.23, 201.05));
  k(0, 1) = 5;  // moves a pixel 280 rows from cy by 5 * 280 / 3325 = 0.42 px.
  EXPECT_FALSE(CameraFromIntrinsics(k, 640, 480, 0.5, &camera, &why));
  EXPECT_THAT(why, HasSubstr("skew"));
  k(0, 1) = 0;
  k(2, 0) = 0.1;
  EXPECT_FALSE(CameraFromIntrinsics(k, 640, 480, 0.5, &camera, &why));
  EXPECT_THAT(why, HasSubstr("upper triangular"));
}

}  // namespace
}  // namespace sft
