#include "src/render/bsdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "src/core/rng.h"

namespace sft {
namespace {

Eigen::Vector3d Direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// ∫ pdf dω over the upper hemisphere by a midpoint rule in (cos θ, φ). The visible-normal lobe
// reflects part of its mass below the horizon (much of it for rough, grazing cases), which
// SampleBsdf rejects; so the integral is ≤ 1 and must equal SampleBsdf's acceptance rate.
TEST(BsdfTest, PdfIntegratesToAcceptanceRate) {
  const Eigen::Vector3d n(0, 0, 1);
  // Roughness ≥ 0.15: sharper lobes are below what the grid resolves (their D normalization is
  // checked by GgxDistributionIsNormalized with a 1D quadrature instead).
  for (double roughness : {0.15, 0.3, 0.6, 1.0}) {
    for (double theta_o : {0.1, 0.8, 1.4}) {
      BsdfParams params;
      params.albedo = Eigen::Vector3d(0.5, 0.5, 0.5);
      params.roughness = roughness;
      params.specular = 0.5;
      const Eigen::Vector3d wo = Direction(theta_o, 0.3);
      const int nc = 800, np = 800;
      double integral = 0.0;
      for (int i = 0; i < nc; ++i) {
        const double cos_t = (i + 0.5) / nc;
        for (int j = 0; j < np; ++j) {
          const double phi = 2 * M_PI * (j + 0.5) / np;
          integral += BsdfPdf(params, n, wo, Direction(std::acos(cos_t), phi));
        }
      }
      integral *= (1.0 / nc) * (2 * M_PI / np);
      const int samples = 40000;
      int accepted = 0;
      for (int s = 0; s < samples; ++s) {
        Sampler sampler(11, 0, 0, s);
        BsdfSample sample;
        const Eigen::Vector3d u(sampler.Next1D(), sampler.Next1D(), sampler.Next1D());
        accepted += SampleBsdf(params, n, wo, u, &sample) ? 1 : 0;
      }
      // Tolerance 0.02: the acceptance rate's binomial standard deviation is ≤ 0.0025, and the
      // 800×800 grid resolves the sharpest lobe here (α = 0.0225) to well under 1%.
      EXPECT_LE(integral, 1.01) << "roughness " << roughness << " theta_o " << theta_o;
      EXPECT_NEAR(integral, static_cast<double>(accepted) / samples, 0.02)
          << "roughness " << roughness << " theta_o " << theta_o;
    }
  }
}

// Histogram of sampled directions in (cos θ, φ) cells against the pdf integrated over each cell:
// a χ² statistic over cells with enough expected counts. With 200k samples and ~100 cells the
// χ² of a correct sampler is ~100 ± 15; a wrong pdf gives thousands.
TEST(BsdfTest, SamplingMatchesPdfChiSquare) {
  const Eigen::Vector3d n(0, 0, 1);
  for (double roughness : {0.1, 0.4, 0.9}) {
    BsdfParams params;
    params.albedo = Eigen::Vector3d(0.4, 0.4, 0.4);
    params.roughness = roughness;
    params.specular = 0.6;
    const Eigen::Vector3d wo = Direction(0.7, 0.0);
    const int nc = 10, np = 20, samples = 200000;
    std::vector<double> observed(nc * np, 0.0), expected(nc * np, 0.0);
    int accepted = 0;
    for (int s = 0; s < samples; ++s) {
      Sampler sampler(7, 0, 0, s);
      BsdfSample sample;
      const Eigen::Vector3d u(sampler.Next1D(), sampler.Next1D(), sampler.Next1D());
      if (!SampleBsdf(params, n, wo, u, &sample)) continue;
      ++accepted;
      EXPECT_NEAR(sample.pdf, BsdfPdf(params, n, wo, sample.wi), 1e-9 * sample.pdf);
      const int i = std::min(nc - 1, static_cast<int>(sample.wi.z() * nc));
      double phi = std::atan2(sample.wi.y(), sample.wi.x());
      if (phi < 0) phi += 2 * M_PI;
      const int j = std::min(np - 1, static_cast<int>(phi / (2 * M_PI) * np));
      observed[i * np + j] += 1;
    }
    // Expected counts: pdf integrated over each cell with 20×20 sub-cells.
    for (int i = 0; i < nc; ++i) {
      for (int j = 0; j < np; ++j) {
        double cell = 0.0;
        for (int a = 0; a < 20; ++a) {
          for (int b = 0; b < 20; ++b) {
            const double cos_t = (i + (a + 0.5) / 20) / nc;
            const double phi = 2 * M_PI * (j + (b + 0.5) / 20) / np;
            cell += BsdfPdf(params, n, wo, Direction(std::acos(cos_t), phi));
          }
        }
        expected[i * np + j] = cell / 400.0 * (1.0 / nc) * (2 * M_PI / np) * samples;
      }
    }
    double chi2 = 0.0;
    int dof = 0;
    for (size_t c = 0; c < observed.size(); ++c) {
      if (expected[c] < 5) continue;
      chi2 += (observed[c] - expected[c]) * (observed[c] - expected[c]) / expected[c];
      ++dof;
    }
    EXPECT_GT(dof, 50);
    EXPECT_LT(chi2, dof + 6.0 * std::sqrt(2.0 * dof)) << "roughness " << roughness;
    EXPECT_GT(accepted, samples / 2);
  }
}

TEST(BsdfTest, LambertValueAndReciprocity) {
  BsdfParams params;
  params.albedo = Eigen::Vector3d(0.2, 0.5, 0.8);
  params.specular = 0.3;
  params.roughness = 0.4;
  const Eigen::Vector3d n(0, 0, 1);
  const Eigen::Vector3d a = Direction(0.3, 0.1), b = Direction(1.1, 2.0);
  EXPECT_TRUE(EvalBsdf(params, n, a, b).isApprox(EvalBsdf(params, n, b, a), 1e-12));
  params.specular = 0.0;
  EXPECT_TRUE(EvalBsdf(params, n, a, b).isApprox(params.albedo / M_PI, 1e-12));
  // Below the surface: zero.
  EXPECT_TRUE(EvalBsdf(params, n, a, -b).isZero());
}

// GGX D is normalized: ∫ D(h) (n·h) dω_h = 1 (checked by quadrature for α from 0.0025 to 1).
TEST(BsdfTest, GgxDistributionIsNormalized) {
  for (double alpha : {0.0025, 0.04, 0.25, 1.0}) {
    // Substitution t = tan²θ / α² makes the integrand smooth: ∫ D cos sin dθ dφ = 1.
    const int steps = 200000;
    double integral = 0.0;
    for (int i = 0; i < steps; ++i) {
      const double theta = 0.5 * M_PI * (i + 0.5) / steps;
      integral += GgxD(std::cos(theta), alpha) * std::cos(theta) * std::sin(theta);
    }
    integral *= 2 * M_PI * 0.5 * M_PI / steps;
    EXPECT_NEAR(integral, 1.0, 0.01) << "alpha " << alpha;
  }
}

// Hard cases stay finite: roughness 0.001 (clamped α), grazing directions, normal incidence.
TEST(BsdfTest, HardCasesStayFinite) {
  const Eigen::Vector3d n(0, 0, 1);
  for (double roughness : {0.0, 0.001, 1.0}) {
    BsdfParams params;
    params.albedo = Eigen::Vector3d(1, 1, 1);
    params.roughness = roughness;
    params.specular = 1.0;
    for (double theta : {0.0, 1e-8, 1.5707, M_PI / 2 - 1e-12}) {
      const Eigen::Vector3d wo = Direction(theta, 0.0);
      const Eigen::Vector3d wi = Direction(theta, M_PI);
      EXPECT_TRUE(EvalBsdf(params, n, wo, wi).allFinite());
      EXPECT_TRUE(std::isfinite(BsdfPdf(params, n, wo, wi)));
      for (int s = 0; s < 100; ++s) {
        Sampler sampler(1, 2, 3, s);
        BsdfSample sample;
        const Eigen::Vector3d u(sampler.Next1D(), sampler.Next1D(), sampler.Next1D());
        if (SampleBsdf(params, n, wo, u, &sample)) {
          EXPECT_TRUE(sample.f.allFinite());
          EXPECT_TRUE(std::isfinite(sample.pdf));
          EXPECT_GT(sample.pdf, 0.0);
        }
      }
    }
  }
}

}  // namespace
}  // namespace sft
