// EnvironmentMap::RotationJacobian against central finite differences of Radiance under small
// rotations of the map (world_from_env ← exp([θ]×)·world_from_env).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "src/core/rng.h"
#include "src/render/environment.h"

namespace sft {
namespace {

// A 16×8 map of random texels in [−0.2, 2] (some negative: clamped to 0 by the map).
Image RandomMap(uint64_t seed) {
  Image image(16, 8, 3, 0.f);
  Sampler sampler(seed, 0, 0, 0);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        image.at(x, y, c) = static_cast<float>(2.2 * sampler.Next1D() - 0.2);
      }
    }
  }
  return image;
}

Eigen::Matrix3d Exp(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, theta / angle).toRotationMatrix();
}

// (u, v) of env direction e (docs/dataset.md), and whether e is at least `margin` (in texels)
// away from every texel centre's row and column, where the bilinear lookup has kinks.
bool AwayFromKinks(const Eigen::Vector3d& e, int width, int height, double margin) {
  const double u = 0.5 - std::atan2(e.y(), e.x()) / (2.0 * M_PI);
  const double v = std::acos(std::clamp(e.z(), -1.0, 1.0)) / M_PI;
  const double x = u * width - 0.5, y = v * height - 0.5;
  const double dx = std::abs(x - std::round(x)), dy = std::abs(y - std::round(y));
  return dx > margin && dy > margin;
}

// Central differences of Radiance(dir) over θ_k = ±h, component k (columns like the Jacobian).
Eigen::Matrix3d FiniteDifference(const EnvironmentMap& env, const Eigen::Vector3d& dir, double h) {
  Eigen::Matrix3d fd;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(k);
    fd.col(k) =
        (env.Rotated(Exp(step)).Radiance(dir) - env.Rotated(Exp(-step)).Radiance(dir)) / (2.0 * h);
  }
  return fd;
}

// Random unit directions, a turned map, h = 1e-6 rad: a point 0.01 texel from a kink moves at most
// h/(2π sin θ)·W ≈ 3e-6 texel per step at sin θ = 0.1, so no difference straddles a kink. Within a
// cell the lookup is smooth, so the central difference's truncation error is O(h²) ≈ 1e-12 and its
// rounding ≈ 1e-16·|L|/h ≈ 1e-10: a tolerance of 1e-6·max(1, |J|) holds with a wide margin, while a
// wrong sign, axis or missing factor (W, 1/dv, 1/(2π)) is off by O(|J|).
TEST(EnvironmentRotationTest, JacobianMatchesFiniteDifferences) {
  const Eigen::Matrix3d world_from_env = Exp(Eigen::Vector3d(0.3, -0.7, 0.4));
  const EnvironmentMap env(RandomMap(7), world_from_env, 1.7);
  Sampler sampler(11, 0, 0, 0);
  int checked = 0, polar_band = 0, wrapped = 0;
  for (int n = 0; n < 2000; ++n) {
    const double z = 2.0 * sampler.Next1D() - 1.0, phi = 2.0 * M_PI * sampler.Next1D();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d e(r * std::cos(phi), r * std::sin(phi), z);
    if (r < 0.1 || !AwayFromKinks(e, 16, 8, 0.01)) continue;
    const Eigen::Vector3d dir = world_from_env * e;
    const Eigen::Matrix3d jacobian = env.RotationJacobian(dir);
    const Eigen::Matrix3d fd = FiniteDifference(env, dir, 1e-6);
    const double tolerance = 1e-6 * std::max(1.0, jacobian.cwiseAbs().maxCoeff());
    EXPECT_LT((jacobian - fd).cwiseAbs().maxCoeff(), tolerance)
        << "e = " << e.transpose() << "\nJ =\n"
        << jacobian << "\nFD =\n"
        << fd;
    ++checked;
    if (std::abs(z) > std::cos(M_PI / 16.0)) ++polar_band;  // above the first row's centres.
    const double u = 0.5 - std::atan2(e.y(), e.x()) / (2.0 * M_PI);
    if (u * 16.0 < 0.5 || u * 16.0 > 15.5) ++wrapped;  // between the last and first columns.
  }
  EXPECT_GT(checked, 1500);
  EXPECT_GT(polar_band, 10);
  EXPECT_GT(wrapped, 50);
}

// A rotation about the direction itself leaves the lookup unchanged (J·dir = 0), and a map whose
// rows are constant is invariant under rotations about the env's z axis (J·(M·ẑ) = 0): the gauge
// of a rotationally symmetric probe (docs/reconstruct.md, "Probe rotation").
TEST(EnvironmentRotationTest, RotationAboutTheDirectionAndAboutZOfARowMapIsInvisible) {
  Image rows(16, 8, 3, 0.f);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 16; ++x) rows.at(x, y, 0) = rows.at(x, y, 1) = rows.at(x, y, 2) = y;
  }
  const Eigen::Matrix3d world_from_env = Exp(Eigen::Vector3d(-0.5, 0.2, 0.9));
  const EnvironmentMap row_map(rows, world_from_env, 1.0);
  const EnvironmentMap random_map(RandomMap(3), world_from_env, 1.0);
  Sampler sampler(5, 0, 0, 0);
  for (int n = 0; n < 100; ++n) {
    const double z = 2.0 * sampler.Next1D() - 1.0, phi = 2.0 * M_PI * sampler.Next1D();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d dir =
        world_from_env * Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
    const Eigen::Matrix3d j = random_map.RotationJacobian(dir);
    EXPECT_LT((j * dir).cwiseAbs().maxCoeff(), 1e-9 * std::max(1.0, j.cwiseAbs().maxCoeff()));
    const Eigen::Vector3d about_z = row_map.RotationJacobian(dir) * world_from_env.col(2);
    EXPECT_LT(about_z.cwiseAbs().maxCoeff(), 1e-9);
  }
}

// Hard cases stay finite: the poles (u undefined: only the polar band's zero v term), a zero or
// non-finite direction (zero), a black map (zero).
TEST(EnvironmentRotationTest, PolesBlackMapsAndBadDirectionsAreFinite) {
  const EnvironmentMap env(RandomMap(9), Eigen::Matrix3d::Identity(), 1.0);
  for (const Eigen::Vector3d& dir : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1),
                                     Eigen::Vector3d(1e-13, 0, 1), Eigen::Vector3d(0, -1e-9, -1)}) {
    EXPECT_TRUE(env.RotationJacobian(dir).allFinite()) << dir.transpose();
  }
  EXPECT_TRUE(env.RotationJacobian(Eigen::Vector3d(0, 0, 1)).isZero());
  EXPECT_TRUE(env.RotationJacobian(Eigen::Vector3d::Zero()).isZero());
  EXPECT_TRUE(env.RotationJacobian(Eigen::Vector3d(NAN, 0, 1)).isZero());
  EXPECT_TRUE(env.RotationJacobian(Eigen::Vector3d(INFINITY, 0, 0)).isZero());
  const EnvironmentMap black(Image(16, 8, 3, 0.f), Eigen::Matrix3d::Identity(), 1.0);
  EXPECT_TRUE(black.RotationJacobian(Eigen::Vector3d(0.3, 0.4, 0.5).normalized()).isZero());
  // Negative texels are clamped: a map of −1 everywhere is black.
  const EnvironmentMap negative(Image(16, 8, 3, -1.f), Eigen::Matrix3d::Identity(), 1.0);
  EXPECT_TRUE(negative.RotationJacobian(Eigen::Vector3d(0.3, 0.4, 0.5).normalized()).isZero());
}

// Rotated() turns lookups: the rotated map seen along R·d is the original seen along d.
TEST(EnvironmentRotationTest, RotatedTurnsLookups) {
  const EnvironmentMap env(RandomMap(4), Exp(Eigen::Vector3d(0.1, 0.2, 0.3)), 1.0);
  const Eigen::Matrix3d rotation = Exp(Eigen::Vector3d(0.4, -0.1, 0.2));
  const EnvironmentMap turned = env.Rotated(rotation);
  const Eigen::Vector3d d = Eigen::Vector3d(0.2, -0.5, 0.7).normalized();
  EXPECT_LT((turned.Radiance(rotation * d) - env.Radiance(d)).norm(), 1e-12);
  EXPECT_NEAR(turned.Pdf(rotation * d), env.Pdf(d), 1e-9 * env.Pdf(d));
}

}  // namespace
}  // namespace sft
