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

// DESIGN.md §2.5: u = 0.5 − atan2(y, x)/(2π), v = acos(z)/π; the image centre looks along +x.
TEST(EnvironmentTest, DirectionMappingMatchesBlender) {
  Image image(8, 4, 3, 0.f);
  image.at(4, 1, 0) = 1.f;  // just right of centre, upper half: +x with z > 0 slightly, y < 0.
  image.at(0, 0, 1) = 1.f;  // u ≈ 0: direction −x (atan2 = π), top row: z ≈ 1.
  const EnvironmentMap env(image, Eigen::Matrix3d::Identity(), 2.0);
  const Eigen::Vector3d d1 = Eigen::Vector3d(1, -0.1, 0.3).normalized();
  EXPECT_DOUBLE_EQ(env.Radiance(d1).x(), 2.0);
  const Eigen::Vector3d d2 = Eigen::Vector3d(-1, 0.01, 3).normalized();
  EXPECT_DOUBLE_EQ(env.Radiance(d2).y(), 2.0);
  // world_from_env rotates lookups: a 90° turn about z moves +x to +y.
  Eigen::Matrix3d rz;
  rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const EnvironmentMap rotated(image, rz, 2.0);
  EXPECT_DOUBLE_EQ(rotated.Radiance(rz * d1).x(), 2.0);
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
