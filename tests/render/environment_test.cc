#include "src/render/environment.h"

#include <gtest/gtest.h>

#include "src/core/rng.h"

namespace sft {
namespace {

// A 64×32 map with a bright patch, for sampling tests.
Image PatchMap() {
  Image image(64, 32, 3, 0.1f);
  for (int y = 8; y < 12; ++y) {
    for (int x = 40; x < 44; ++x) {
      image.at(x, y, 0) = 20.f;
      image.at(x, y, 1) = 10.f;
      image.at(x, y, 2) = 5.f;
    }
  }
  image.at(3, 3, 1) = -5.f;  // negative texels are clamped to 0.
  return image;
}

// The env-frame direction at polar angle θ and azimuth φ (degrees).
Eigen::Vector3d Direction(double theta_deg, double phi_deg) {
  const double t = theta_deg * M_PI / 180.0, p = phi_deg * M_PI / 180.0;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// The env-frame direction of the point (u, v) of the map (docs/dataset.md inverted by hand: φ =
// (0.5 − u)·360°, θ = v·180°).
Eigen::Vector3d DirectionOfUv(double u, double v) {
  return Direction(v * 180.0, (0.5 - u) * 360.0);
}

// docs/dataset.md: u = 0.5 − atan2(y, x)/(2π), v = acos(z)/π; the image centre looks along +x. At a
// texel's centre the interpolated lookup is the texel itself.
TEST(EnvironmentTest, DirectionMappingMatchesBlender) {
  Image image(8, 4, 3, 0.f);
  image.at(4, 1, 0) = 1.f;  // centre (u, v) = (0.5625, 0.375): θ = 67.5°, φ = −22.5° (y < 0).
  image.at(0, 0, 1) = 1.f;  // centre (0.0625, 0.125): θ = 22.5°, φ = 157.5° (towards −x).
  const EnvironmentMap env(image, Eigen::Matrix3d::Identity(), 2.0);
  const Eigen::Vector3d d1 = Direction(67.5, -22.5);
  EXPECT_NEAR(env.Radiance(d1).x(), 2.0, 1e-12);
  EXPECT_NEAR(env.Radiance(Direction(22.5, 157.5)).y(), 2.0, 1e-12);
  // world_from_env rotates lookups: a 90° turn about z moves +x to +y.
  Eigen::Matrix3d rz;
  rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const EnvironmentMap rotated(image, rz, 2.0);
  EXPECT_NEAR(rotated.Radiance(rz * d1).x(), 2.0, 1e-12);
}

// Between texel centres the lookup interpolates bilinearly (Cycles' Linear interpolation), wraps
// around in u, and holds the first row's values above its centres up to the pole.
TEST(EnvironmentTest, LookupIsBilinearBetweenTexelCentres) {
  Image image(8, 4, 3, 0.f);
  image.at(4, 1, 0) = 1.f;
  image.at(5, 1, 0) = 3.f;
  image.at(4, 2, 0) = 5.f;
  image.at(7, 0, 1) = 2.f;
  image.at(0, 0, 1) = 4.f;
  const EnvironmentMap env(image, Eigen::Matrix3d::Identity(), 1.0);
  // Halfway between the centres of (4, 1) and (5, 1): u = 5/8, v = 3/8.
  EXPECT_NEAR(env.Radiance(DirectionOfUv(5.0 / 8, 3.0 / 8)).x(), 2.0, 1e-9);
  // A quarter of the way from (4, 1) down to (4, 2): v = 3/8 + 1/16.
  EXPECT_NEAR(env.Radiance(DirectionOfUv(4.5 / 8, 3.0 / 8 + 1.0 / 16)).x(), 2.0, 1e-9);
  // Across the seam: halfway between the centres of (7, 0) and (0, 0) is u = 0 (= 1).
  EXPECT_NEAR(env.Radiance(DirectionOfUv(1e-9, 1.0 / 8)).y(), 3.0, 1e-6);
  // Above row 0's centres (v < 1/8) only u interpolates.
  EXPECT_NEAR(env.Radiance(DirectionOfUv(7.5 / 8, 0.03)).y(), 2.0, 1e-9);
  // u = 0.25/8 is a quarter texel left of column 0's centre: ¼·2 + ¾·4.
  EXPECT_NEAR(env.Radiance(DirectionOfUv(0.25 / 8, 0.03)).y(), 3.5, 1e-9);
}

// The importance sampler's density follows the interpolated lookup: its ratio to the
// interpolated value varies only with the cell's mean sin θ, so along a row of cells it is
// constant, and where the lookup is zero the pdf is zero.
TEST(EnvironmentTest, PdfFollowsTheInterpolatedLookup) {
  Image image(16, 8, 3, 0.f);
  image.at(5, 4, 0) = 6.f;
  image.at(6, 4, 0) = 2.f;
  const EnvironmentMap env(image, Eigen::Matrix3d::Identity(), 1.0);
  const double v = 4.5 / 8;  // row 4's centres: only u interpolates.
  double ratio = 0.0;
  for (double u : {5.2 / 16, 5.5 / 16, 5.9 / 16, 6.3 / 16}) {
    const Eigen::Vector3d d = DirectionOfUv(u, v);
    const double value = env.Radiance(d).x() / 3.0;  // mean of RGB.
    ASSERT_GT(value, 0.0);
    if (ratio == 0.0) ratio = env.Pdf(d) / value;
    EXPECT_NEAR(env.Pdf(d) / value, ratio, 1e-9 * ratio) << u;
  }
  EXPECT_EQ(env.Pdf(DirectionOfUv(2.5 / 16, v)), 0.0);
  EXPECT_EQ(env.Radiance(DirectionOfUv(2.5 / 16, v)).x(), 0.0);
}

TEST(EnvironmentTest, SamplePdfMatchesPdfAndIntegratesToOne) {
  const EnvironmentMap env(PatchMap(), Eigen::Matrix3d::Identity(), 1.0);
  for (int s = 0; s < 2000; ++s) {
    Sampler sampler(3, 0, 0, s);
    Eigen::Vector3d dir, radiance;
    double pdf;
    ASSERT_TRUE(env.Sample(sampler.Next1D(), sampler.Next1D(), &dir, &radiance, &pdf));
    EXPECT_NEAR(dir.norm(), 1.0, 1e-12);
    EXPECT_NEAR(pdf, env.Pdf(dir), 1e-6 * pdf);
    EXPECT_TRUE(radiance.isApprox(env.Radiance(dir)));
  }
  // ∫ pdf dω = 1 by quadrature over (θ, φ).
  const int nt = 400, np = 800;
  double integral = 0.0;
  for (int i = 0; i < nt; ++i) {
    const double theta = M_PI * (i + 0.5) / nt;
    for (int j = 0; j < np; ++j) {
      const double phi = 2 * M_PI * (j + 0.5) / np;
      const Eigen::Vector3d d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
      integral += env.Pdf(d) * std::sin(theta);
    }
  }
  integral *= (M_PI / nt) * (2 * M_PI / np);
  EXPECT_NEAR(integral, 1.0, 5e-3);
}

// Monte Carlo estimate of the mean radiance with importance sampling equals the exact mean.
TEST(EnvironmentTest, ImportanceSampledMeanIsUnbiased) {
  const EnvironmentMap env(PatchMap(), Eigen::Matrix3d::Identity(), 1.0);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const int n = 200000;
  for (int s = 0; s < n; ++s) {
    Sampler sampler(5, 0, 0, s);
    Eigen::Vector3d dir, radiance;
    double pdf;
    if (env.Sample(sampler.Next1D(), sampler.Next1D(), &dir, &radiance, &pdf)) {
      sum += radiance / pdf;
    }
  }
  const Eigen::Vector3d estimate = sum / n / (4 * M_PI);
  const Eigen::Vector3d exact = env.MeanRadiance();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(estimate[c], exact[c], 0.01 * exact[c]);
}

TEST(EnvironmentTest, BlackMapSamplesNothing) {
  const EnvironmentMap env(Image(16, 8, 3, 0.f), Eigen::Matrix3d::Identity(), 1.0);
  Eigen::Vector3d dir, radiance;
  double pdf;
  EXPECT_FALSE(env.Sample(0.3, 0.6, &dir, &radiance, &pdf));
  EXPECT_EQ(env.Pdf(Eigen::Vector3d(0, 0, 1)), 0.0);
}

}  // namespace
}  // namespace sft
