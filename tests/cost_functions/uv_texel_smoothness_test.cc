// The UV texel smoothness prior (cost_functions/uv_texel_smoothness.h): its Jacobian against
// central differences, and its pairs: 4-neighbours, used texels of one chart only.
#include "cost_functions/uv_texel_smoothness.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "src/core/rng.h"

namespace sft {
namespace {

// Central differences of a linear residual are exact up to rounding: relative error 1e-7.
constexpr double kGradientTolerance = 1e-7;

double Uniform(uint64_t key) { return static_cast<double>(Mix64(key) >> 11) * 0x1.0p-53; }

// Two charts of a 16² texture (see tests/geometry/uv_texel_charts_test.cc).
UvTexelCharts TwoCharts() {
  const std::vector<Eigen::Vector3i> faces = {{0, 1, 2}, {0, 2, 3}, {0, 2, 4}};
  const std::vector<Eigen::Vector2d> uvs = {{0.1, 0.1}, {0.4, 0.1}, {0.4, 0.4},
                                            {0.1, 0.1}, {0.4, 0.4}, {0.1, 0.4},
                                            {0.6, 0.6}, {0.9, 0.9}, {0.6, 0.9}};
  return ComputeUvTexelCharts(faces, uvs, 16, 16);
}

template <int kChannels>
void CheckPairJacobians() {
  const std::vector<TexelPair> pairs = UvTexelNeighbourPairs(TwoCharts());
  ASSERT_FALSE(pairs.empty());
  std::vector<double> texels(kChannels * 16 * 16);
  for (size_t k = 0; k < texels.size(); ++k) texels[k] = Uniform(k);
  for (size_t p = 0; p < pairs.size(); p += 7) {
    SCOPED_TRACE(p);
    const double w = 0.5 + 0.1 * p;
    const TexelDifferenceCost<kChannels> cost(w);
    const double* parameters[] = {&texels[kChannels * pairs[p].a], &texels[kChannels * pairs[p].b]};
    const ceres::GradientChecker checker(
        &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr),
        ceres::NumericDiffOptions());
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(parameters, kGradientTolerance, &results)) << results.error_log;
    for (int c = 0; c < kChannels; ++c) {
      EXPECT_NEAR(results.residuals[c], w * (parameters[0][c] - parameters[1][c]), 1e-12);
    }
  }
}

TEST(UvTexelSmoothnessTest, JacobianMatchesFiniteDifferencesAlbedo) { CheckPairJacobians<3>(); }
TEST(UvTexelSmoothnessTest, JacobianMatchesFiniteDifferencesRoughness) { CheckPairJacobians<1>(); }

TEST(UvTexelSmoothnessTest, PairsAreNeighboursOfOneChart) {
  const UvTexelCharts charts = TwoCharts();
  const std::vector<TexelPair> pairs = UvTexelNeighbourPairs(charts);
  int horizontal = 0, vertical = 0;
  for (const TexelPair& p : pairs) {
    ASSERT_TRUE(charts.used(p.a) && charts.used(p.b));
    EXPECT_EQ(charts.chart_of_texel[p.a], charts.chart_of_texel[p.b]);
    if (p.b == p.a + 1) {
      ++horizontal;
      EXPECT_EQ(p.a / 16, p.b / 16);  // no wrap to the next row.
    } else {
      EXPECT_EQ(p.b, p.a + 16);
      ++vertical;
    }
  }
  // Every pair of horizontally or vertically adjacent used texels of one chart is there.
  int expected = 0;
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      const int k = y * 16 + x;
      if (!charts.used(k)) continue;
      if (x + 1 < 16 && charts.chart_of_texel[k + 1] == charts.chart_of_texel[k]) ++expected;
      if (y + 1 < 16 && charts.chart_of_texel[k + 16] == charts.chart_of_texel[k]) ++expected;
    }
  }
  EXPECT_EQ(horizontal + vertical, expected);
  EXPECT_GT(horizontal, 0);
  EXPECT_GT(vertical, 0);
}

}  // namespace
}  // namespace sft
