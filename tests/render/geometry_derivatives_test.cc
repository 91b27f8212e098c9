// Finite-difference checks of the geometric building blocks of vertex derivatives: the face
// normal's chain rule, the hit point's implicit derivative, the glossy term's gradient in n and
// wi, and the camera projection's Jacobian. All are smooth functions evaluated in double; central
// differences with step h have truncation error O(h²·f''') ≈ 1e-10 and rounding error
// O(ε/h) ≈ 1e-10 at h = 1e-6, so a relative tolerance of 1e-6 leaves a wide margin while still
// catching any wrong term (a missing or mis-signed term is an O(1) error).
#include "src/render/geometry_derivatives.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <limits>
#include <random>

#include "src/render/bsdf.h"
#include "src/render/camera.h"

namespace sft {
namespace {

constexpr double kStep = 1e-6;
constexpr double kTolerance = 1e-6;

Eigen::Vector3d UnitNormal(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                           const Eigen::Vector3d& p2) {
  return (p1 - p0).cross(p2 - p0).normalized();
}

TEST(NormalChainTest, MatchesFiniteDifferences) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  // Coefficients drawn in order (a constructor's arguments have no defined evaluation order).
  auto random_vector = [&] {
    return Eigen::Vector3d::NullaryExpr([&](Eigen::Index) { return normal(rng); }).eval();
  };
  for (int trial = 0; trial < 20; ++trial) {
    std::array<Eigen::Vector3d, 3> p = {random_vector(), random_vector(), random_vector()};
    if (trial == 0) p[2] = p[0] + 1e-3 * (p[1] - p[0]) + 1e-4 * random_vector();  // a sliver.
    const double sign = trial % 2 == 0 ? 1.0 : -1.0;
    Eigen::Matrix3d g;  // three scalar functions of n: rows are their gradients.
    for (int r = 0; r < 3; ++r) g.row(r) = random_vector().transpose();
    const NormalChain chain(p[0], p[1], p[2], sign);
    const Eigen::Matrix<double, 3, 9> analytic = chain.Map(g);
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) {
        auto plus = p, minus = p;
        const double h = kStep * p[j].norm();
        plus[j][k] += h;
        minus[j][k] -= h;
        const Eigen::Vector3d fd = g *
                                   (sign * (UnitNormal(plus[0], plus[1], plus[2]) -
                                            UnitNormal(minus[0], minus[1], minus[2]))) /
                                   (2.0 * h);
        const double scale = std::max(1.0, fd.norm());
        EXPECT_NEAR((analytic.col(3 * j + k) - fd).norm() / scale, 0.0,
                    trial == 0 ? 1e-3 : kTolerance)
            << "trial " << trial << " corner " << j << " coordinate " << k;
      }
    }
  }
  // Degenerate face: zero maps, no NaN.
  const Eigen::Vector3d a(1, 2, 3);
  const NormalChain degenerate(a, a, a, 1.0);
  EXPECT_TRUE(degenerate.Map(Eigen::Matrix3d::Identity()).isZero());
}

// The hit point of ray o + t·d with the plane of (p0, p1, p2).
Eigen::Vector3d HitPoint(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                         const std::array<Eigen::Vector3d, 3>& p) {
  const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
  return o + d * (n.dot(p[0] - o) / n.dot(d));
}

TEST(HitPointDerivativesTest, MatchesFiniteDifferences) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  auto random_vector = [&] {
    return Eigen::Vector3d::NullaryExpr([&](Eigen::Index) { return uniform(rng); }).eval();
  };
  for (int trial = 0; trial < 20; ++trial) {
    const std::array<Eigen::Vector3d, 3> p = {Eigen::Vector3d(0, 0, 0) + 0.2 * random_vector(),
                                              Eigen::Vector3d(1, 0, 0) + 0.2 * random_vector(),
                                              Eigen::Vector3d(0, 1, 0) + 0.2 * random_vector()};
    const Eigen::Vector3d o = Eigen::Vector3d(0.3, 0.3, 3.0) + random_vector();
    const Eigen::Vector3d target = (p[0] + p[1] + p[2]) / 3.0 + 0.1 * random_vector();
    const Eigen::Vector3d d = (target - o).normalized();
    const Eigen::Vector3d x = HitPoint(o, d, p);
    // Barycentrics of x.
    Eigen::Matrix3d basis;
    basis << p[1] - p[0], p[2] - p[0], UnitNormal(p[0], p[1], p[2]);
    const Eigen::Vector3d local = basis.colPivHouseholderQr().solve(x - p[0]);
    const Eigen::Vector3d b(1.0 - local[0] - local[1], local[0], local[1]);
    std::array<Eigen::Matrix3d, 3> d_x_d_p;
    Eigen::Matrix3d d_x_d_o;
    ASSERT_TRUE(HitPointDerivatives(d, UnitNormal(p[0], p[1], p[2]), b, &d_x_d_p, &d_x_d_o));
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 3; ++j) {
        auto plus = p, minus = p;
        plus[j][k] += kStep;
        minus[j][k] -= kStep;
        const Eigen::Vector3d fd = (HitPoint(o, d, plus) - HitPoint(o, d, minus)) / (2 * kStep);
        EXPECT_LT((d_x_d_p[j].col(k) - fd).norm(), kTolerance * std::max(1.0, fd.norm()));
      }
      Eigen::Vector3d o_plus = o, o_minus = o;
      o_plus[k] += kStep;
      o_minus[k] -= kStep;
      const Eigen::Vector3d fd = (HitPoint(o_plus, d, p) - HitPoint(o_minus, d, p)) / (2 * kStep);
      EXPECT_LT((d_x_d_o.col(k) - fd).norm(), kTolerance * std::max(1.0, fd.norm()));
    }
  }
  // Grazing: no derivative, reported.
  std::array<Eigen::Matrix3d, 3> d_x_d_p;
  Eigen::Matrix3d d_x_d_o;
  EXPECT_FALSE(HitPointDerivatives(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1),
                                   Eigen::Vector3d(1, 0, 0) / 3.0, &d_x_d_p, &d_x_d_o));
}

TEST(PointJacobianTest, ChainsThroughTwoHits) {
  // x1 = hit of the camera ray on face A; x2 = hit of the ray from x1 along d2 on face B.
  const std::array<Eigen::Vector3d, 3> a = {Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(2, -1, 0.3),
                                            Eigen::Vector3d(-1, 2, -0.2)};
  const std::array<Eigen::Vector3d, 3> b = {Eigen::Vector3d(-1, -1, 2), Eigen::Vector3d(3, -1, 2.5),
                                            Eigen::Vector3d(-1, 3, 1.8)};
  const Eigen::Vector3d camera(0.1, 0.2, -3.0);
  const Eigen::Vector3d d1 = Eigen::Vector3d(0.05, 0.02, 1.0).normalized();
  const Eigen::Vector3d d2 = Eigen::Vector3d(0.3, 0.1, 1.0).normalized();
  auto barycentrics = [](const std::array<Eigen::Vector3d, 3>& p, const Eigen::Vector3d& x) {
    Eigen::Matrix3d basis;
    basis << p[1] - p[0], p[2] - p[0], UnitNormal(p[0], p[1], p[2]);
    const Eigen::Vector3d local = basis.colPivHouseholderQr().solve(x - p[0]);
    return Eigen::Vector3d(1.0 - local[0] - local[1], local[0], local[1]);
  };
  auto x2_of = [&](const std::array<Eigen::Vector3d, 3>& pa,
                   const std::array<Eigen::Vector3d, 3>& pb) {
    return HitPoint(HitPoint(camera, d1, pa), d2, pb);
  };
  const Eigen::Vector3d x1 = HitPoint(camera, d1, a);
  const Eigen::Vector3d x2 = x2_of(a, b);
  PointJacobian jacobian;
  jacobian.Advance(true, d1, UnitNormal(a[0], a[1], a[2]), barycentrics(a, x1),
                   Eigen::Vector3i(0, 1, 2));
  jacobian.Advance(false, d2, UnitNormal(b[0], b[1], b[2]), barycentrics(b, x2),
                   Eigen::Vector3i(3, 4, 5));
  ASSERT_TRUE(jacobian.valid);
  ASSERT_EQ(jacobian.count, 6);
  for (int e = 0; e < 6; ++e) {
    for (int k = 0; k < 3; ++k) {
      auto pa_plus = a, pa_minus = a, pb_plus = b, pb_minus = b;
      if (e < 3) {
        pa_plus[e][k] += kStep;
        pa_minus[e][k] -= kStep;
      } else {
        pb_plus[e - 3][k] += kStep;
        pb_minus[e - 3][k] -= kStep;
      }
      const Eigen::Vector3d fd =
          (x2_of(pa_plus, pb_plus) - x2_of(pa_minus, pb_minus)) / (2 * kStep);
      EXPECT_EQ(jacobian.vertex[e], e);
      EXPECT_LT((jacobian.m[e].col(k) - fd).norm(), kTolerance * std::max(1.0, fd.norm()))
          << "vertex " << e << " coordinate " << k;
    }
  }
}

TEST(GlossyGradientTest, MatchesFiniteDifferencesAndEvalBsdf) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const FresnelMode mode : {FresnelMode::kConstant, FresnelMode::kSchlick}) {
    for (const double roughness : {0.05, 0.3, 1.0}) {
      BsdfParams params;
      params.albedo = Eigen::Vector3d(0.2, 0.5, 0.7);
      params.roughness = roughness;
      params.specular = 0.4;
      params.fresnel = mode;
      for (int trial = 0; trial < 20; ++trial) {
        // One draw per statement: the order in which a constructor's arguments are evaluated is
        // unspecified (gcc and clang differ), and the test must see the same points under both.
        std::array<double, 8> u;
        for (double& value : u) value = uniform(rng);
        const Eigen::Vector3d n(0.2 * u[0], 0.2 * u[1], 1.0);
        const Eigen::Vector3d wo = Eigen::Vector3d(u[2], u[3], 1.0 + 0.5 * u[4]).normalized();
        // wi near the mirror direction so the lobe is not negligible at low roughness.
        const Eigen::Vector3d mirror = 2.0 * wo.dot(n.normalized()) * n.normalized() - wo;
        const Eigen::Vector3d wi =
            (mirror + 0.5 * roughness * roughness * Eigen::Vector3d(u[5], u[6], u[7])).normalized();
        Eigen::Vector3d d_n, d_wi;
        const double g = EvalGlossyWithGradient(params, n, wo, wi, &d_n, &d_wi);
        // EvalBsdf's n is unit; compare values at the unit normal.
        Eigen::Vector3d d_unit, d_unused;
        const double g_unit =
            EvalGlossyWithGradient(params, n.normalized(), wo, wi, &d_unit, &d_unused);
        if (EvalBsdf(params, n.normalized(), wo, wi).isZero()) continue;
        EXPECT_NEAR(g_unit, EvalBsdf(params, n.normalized(), wo, wi)[0] - params.albedo[0] / M_PI,
                    1e-9 * std::max(1.0, g_unit));
        // The test's n is not unit, so a cosine can pass 1, where GGX's 1 − cos² is clamped at
        // 0: a kink the steps must not straddle. A step h in n or wi moves n·wi and n·wo by at
        // most h·|n| and n·half by at most h·|n|/|wi + wo|; steps stay within a quarter of that.
        const double len = (wi + wo).norm();
        const double kink = std::min({std::abs(1.0 - n.dot(wi + wo) / len) * len,
                                      std::abs(1.0 - n.dot(wi)), std::abs(1.0 - n.dot(wo))}) /
                            n.norm();
        for (int k = 0; k < 3; ++k) {
          Eigen::Vector3d dn = Eigen::Vector3d::Zero(), unused;
          // Relative to α, the scale on which the lobe varies: truncation (h/α)² = 1e-8.
          const double h = std::min(1e-4 * roughness * roughness, 0.25 * kink);
          // Central differences' rounding error, ε·|g|/h, with a wide factor.
          const double rounding = 100.0 * std::numeric_limits<double>::epsilon() * std::abs(g) / h;
          dn[k] = h;
          const double fd_n = (EvalGlossyWithGradient(params, n + dn, wo, wi, &unused, &unused) -
                               EvalGlossyWithGradient(params, n - dn, wo, wi, &unused, &unused)) /
                              (2 * h);
          const double fd_wi = (EvalGlossyWithGradient(params, n, wo, wi + dn, &unused, &unused) -
                                EvalGlossyWithGradient(params, n, wo, wi - dn, &unused, &unused)) /
                               (2 * h);
          EXPECT_NEAR(d_n[k], fd_n, rounding + 1e-5 * std::max(1.0, std::abs(fd_n))) << g;
          EXPECT_NEAR(d_wi[k], fd_wi, rounding + 1e-5 * std::max(1.0, std::abs(fd_wi))) << g;
        }
      }
    }
  }
}

TEST(CameraJacobianTest, MatchesFiniteDifferences) {
  for (const auto& [model, params] : std::vector<std::pair<CameraModel, std::vector<double>>>{
           {CameraModel::kPinhole, {300, 310, 64, 60}},
           {CameraModel::kSimpleRadial, {300, 64, 60, 0.1}},
           {CameraModel::kRadial, {300, 64, 60, 0.1, -0.05}},
           {CameraModel::kOpenCV, {300, 310, 64, 60, 0.1, -0.05, 0.01, -0.02}}}) {
    Camera camera;
    camera.model = model;
    camera.width = 128;
    camera.height = 120;
    camera.params = params;
    const Eigen::Vector3d p(0.3, -0.2, 2.0);
    const Eigen::Matrix<double, 2, 3> analytic = camera.ImageFromCamJacobian(p);
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d dp = Eigen::Vector3d::Zero();
      dp[k] = kStep;
      const Eigen::Vector2d fd =
          (camera.ImageFromCam(p + dp) - camera.ImageFromCam(p - dp)) / (2 * kStep);
      EXPECT_LT((analytic.col(k) - fd).norm(), 1e-6 * fd.norm() + 1e-6)
          << CameraModelName(model) << " coordinate " << k;
    }
  }
}

}  // namespace
}  // namespace sft
