// The sampling utilities of the edge terms (src/render/internal/sampling.h).
#include "src/render/internal/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "src/core/rng.h"

namespace sft {
namespace render_internal {
namespace {

TEST(SamplingTest, DiscreteDistributionDrawsInProportionToWeights) {
  const std::vector<double> weights = {1.0, 0.0, 3.0, 0.5, 5.5};
  const DiscreteDistribution d(weights);
  ASSERT_FALSE(d.empty());
  EXPECT_EQ(d.size(), 5);
  EXPECT_DOUBLE_EQ(d.total(), 10.0);
  EXPECT_DOUBLE_EQ(d.CumulativeBefore(3), 4.0);
  const int n = 100000;
  std::vector<int> inverse(5, 0), alias(5, 0);
  for (int i = 0; i < n; ++i) {
    const double u = (i + 0.5) / n;  // stratified.
    ++inverse[d.SampleInverse(u)];
    ++alias[d.Sample(u)];
  }
  for (int k = 0; k < 5; ++k) {
    // Stratified u: the inverse CDF hits each cell's share to within one sample.
    EXPECT_NEAR(inverse[k], n * weights[k] / 10.0, 1.0) << k;
    // The alias table's cells are exact fractions of [0, 1) too.
    EXPECT_NEAR(alias[k], n * weights[k] / 10.0, 2.0) << k;
  }
  EXPECT_EQ(inverse[1], 0);
  EXPECT_EQ(alias[1], 0);
  // The inverse CDF is monotone in u (what keeps stratified edge samples stratified).
  int last = 0;
  for (int i = 0; i < 1000; ++i) {
    const int k = d.SampleInverse(i / 1000.0);
    EXPECT_GE(k, last);
    last = k;
  }
  EXPECT_EQ(d.SampleInverse(1.0), 4);
}

TEST(SamplingTest, DiscreteDistributionWithoutPositiveWeightIsEmpty) {
  EXPECT_TRUE(DiscreteDistribution().empty());
  EXPECT_TRUE(DiscreteDistribution({0.0, 0.0}).empty());
  EXPECT_TRUE(DiscreteDistribution({1.0, std::numeric_limits<double>::infinity()}).empty());
}

TEST(SamplingTest, ClipSegmentKeepsThePartInTheFrustum) {
  Camera camera;
  camera.model = CameraModel::kPinhole;
  camera.width = camera.height = 100;
  camera.params = {100.0, 100.0, 50.0, 50.0};  // image spans x/z, y/z ∈ [−0.5, 0.5].
  const FrustumBounds f = ViewFrustum(camera, 1.0);
  EXPECT_NEAR(f.u_min, -0.55, 1e-12);  // 5% margin.
  EXPECT_NEAR(f.v_max, 0.55, 1e-12);
  double s0, s1;
  // Inside: unchanged.
  ASSERT_TRUE(ClipSegment({-0.1, 0, 1}, {0.1, 0, 1}, f, &s0, &s1));
  EXPECT_DOUBLE_EQ(s0, 0.0);
  EXPECT_DOUBLE_EQ(s1, 1.0);
  // From x/z = −1.55 to 0.45 at z = 1: enters at x = −0.55, s = 0.5.
  ASSERT_TRUE(ClipSegment({-1.55, 0, 1}, {0.45, 0, 1}, f, &s0, &s1));
  EXPECT_NEAR(s0, 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(s1, 1.0);
  // Crossing the camera plane: the part behind (z < z_min) goes.
  ASSERT_TRUE(ClipSegment({0, 0, -1}, {0, 0, 1}, f, &s0, &s1));
  EXPECT_NEAR(s0, 0.5 + 0.5e-7, 1e-12);
  // Entirely beside the view.
  EXPECT_FALSE(ClipSegment({2, 0, 1}, {3, 0, 1}, f, &s0, &s1));
}

TEST(SamplingTest, AngleUniformEdgePointSplitsTheSubtendedAngle) {
  const Eigen::Vector3d x(0, 0, 0), a(1, -1, 0), b(1, 1, 0);
  double s, subtended;
  ASSERT_TRUE(AngleUniformEdgePoint(a, b, x, 0.5, &s, &subtended));
  EXPECT_NEAR(subtended, M_PI / 2, 1e-12);
  EXPECT_NEAR(s, 0.5, 1e-12);
  // ξ = 1/4: the direction at 22.5° from a − x, i.e. at angle −22.5° to the x axis.
  ASSERT_TRUE(AngleUniformEdgePoint(a, b, x, 0.25, &s, &subtended));
  EXPECT_NEAR(-1.0 + 2.0 * s, std::tan(-M_PI / 8), 1e-12);
  // x on the segment's line: degenerate.
  EXPECT_FALSE(AngleUniformEdgePoint(a, b, Eigen::Vector3d(1, 5, 0), 0.5, &s, &subtended));
}

// Σ_segments ∫ f(ω) dθ over the angle each segment subtends at x (midpoint rule).
template <typename F>
double AngleIntegral(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments,
                     const Eigen::Vector3d& x, const F& f) {
  double integral = 0.0;
  for (const auto& [a, b] : segments) {
    const int steps = 20000;
    double s, subtended;
    for (int i = 0; i < steps; ++i) {
      EXPECT_TRUE(AngleUniformEdgePoint(a, b, x, (i + 0.5) / steps, &s, &subtended));
      integral += f((a + s * (b - a) - x).normalized()) * subtended / steps;
    }
  }
  return integral;
}

// E[target(ω_kept)·inv_pdf] = Σ_segments ∫ target dθ (angle at x), the resampling estimator's
// defining property (its weight makes it unbiased for any integrand that is zero where the target
// is, here the target itself).
TEST(SamplingTest, ResampledPointIsUnbiased) {
  const Eigen::Vector3d x(0, 0, 0);
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments = {
      {{1, -1, 0}, {1, 1, 0}}, {{-1, 2, 0}, {-3, 0.5, 0}}, {{0, -2, 0.5}, {0.5, -2, -0.5}}};
  const DiscreteDistribution table({2.0, 1.0, 0.5});
  auto ends = [&](int c, Eigen::Vector3d* a, Eigen::Vector3d* b) {
    *a = segments[c].first;
    *b = segments[c].second;
    return true;
  };
  auto target = [](const Eigen::Vector3d& omega) { return 1.5 + omega.x() + 0.5 * omega.y(); };
  const double reference = AngleIntegral(segments, x, target);
  double sum = 0.0;
  const int n = 40000;
  for (int i = 0; i < n; ++i) {
    Sampler sampler(7, 0, static_cast<uint64_t>(i), 0);
    const double u_index = sampler.Next1D(), u_point = sampler.Next1D();
    const ResampledPoint kept =
        ResampleSegmentPoint(table, 4, x, u_index, u_point, &sampler, ends, target);
    ASSERT_GE(kept.index, 0);
    const Eigen::Vector3d& a = segments[kept.index].first;
    const Eigen::Vector3d& b = segments[kept.index].second;
    sum += target((a + kept.s * (b - a) - x).normalized()) * kept.inv_pdf;
  }
  EXPECT_NEAR(sum / n, reference, 0.01 * reference);
}

// Systematic picks from one candidate draw (what secondary edges (A) keep several of): the mean
// of the M picks' estimates is unbiased too, and equal picks are adjacent.
TEST(SamplingTest, SystematicPicksAreUnbiased) {
  const Eigen::Vector3d x(0, 0, 0);
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments = {
      {{1, -1, 0}, {1, 1, 0}}, {{-1, 2, 0}, {-3, 0.5, 0}}, {{0, -2, 0.5}, {0.5, -2, -0.5}}};
  const DiscreteDistribution table({2.0, 1.0, 0.5});
  auto ends = [&](int c, Eigen::Vector3d* a, Eigen::Vector3d* b) {
    *a = segments[c].first;
    *b = segments[c].second;
    return c != 1 || a->x() < 0;  // all weighted
  };
  auto target = [](const Eigen::Vector3d& omega) { return 1.5 + omega.x() + 0.5 * omega.y(); };
  // The integrand: the target times a factor the target does not know.
  auto integrand = [&](const Eigen::Vector3d& omega) { return target(omega) * (1.0 + omega.y()); };
  const double reference = AngleIntegral(segments, x, integrand);
  const int kPicks = 3;
  double sum = 0.0;
  const int n = 40000;
  for (int i = 0; i < n; ++i) {
    Sampler sampler(11, 0, static_cast<uint64_t>(i), 0);
    const double u_index = sampler.Next1D(), u_point = sampler.Next1D();
    const SegmentCandidates candidates =
        DrawSegmentCandidates(table, 4, x, u_index, u_point, &sampler, ends, target);
    ASSERT_GT(candidates.num_weighted, 0);
    const double u = sampler.Next1D();
    int previous = -1;
    for (int j = 0; j < kPicks; ++j) {
      const int entry = candidates.PickEntry((j + u) / kPicks);
      ASSERT_GE(entry, previous);  // equal picks are adjacent
      previous = entry;
      const ResampledPoint kept = candidates.Point(entry);
      const Eigen::Vector3d& a = segments[kept.index].first;
      const Eigen::Vector3d& b = segments[kept.index].second;
      sum += integrand((a + kept.s * (b - a) - x).normalized()) * kept.inv_pdf / kPicks;
    }
  }
  EXPECT_NEAR(sum / n, reference, 0.01 * reference);
}

}  // namespace
}  // namespace render_internal
}  // namespace sft
