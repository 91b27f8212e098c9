// The bounding-sphere hierarchy that draws (A)'s secondary edge candidates
// (src/render/internal/edge_tree.h).
#include "src/render/internal/edge_tree.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace sft {
namespace render_internal {
namespace {

struct Segments {
  std::vector<Eigen::Vector3f> a, b;
  std::vector<float> lengths;
  void Add(const Eigen::Vector3f& p, const Eigen::Vector3f& q) {
    a.push_back(p);
    b.push_back(q);
    lengths.push_back((q - p).norm());
  }
};

// `count` random segments of length up to 0.2·scale in the cube [0, scale]³.
Segments RandomSegments(int count, float scale, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Segments s;
  for (int i = 0; i < count; ++i) {
    // Coefficients drawn in order (a constructor's arguments have no defined evaluation order).
    const Eigen::Vector3f p = Eigen::Vector3f::NullaryExpr([&](Eigen::Index) { return unit(rng); });
    const Eigen::Vector3f d =
        Eigen::Vector3f::NullaryExpr([&](Eigen::Index) { return unit(rng) - 0.5f; });
    s.Add(scale * p, scale * (p + 0.4f * d));
  }
  return s;
}

// Every draw reports Probability of what it drew, stratified draws land on each position in
// proportion to it, and the rest of the mass is the empty draw (−1): a subtree whose children
// are both wholly below x's plane.
void ExpectConsistent(const EdgeTree& tree, const Eigen::Vector3d& x, const Eigen::Vector3d& n) {
  const int size = static_cast<int>(tree.order().size());
  std::vector<double> p(size);
  double sum = 0.0;
  for (int j = 0; j < size; ++j) {
    p[j] = tree.Probability(x, n, j);
    ASSERT_TRUE(std::isfinite(p[j]));
    ASSERT_GE(p[j], 0.0);
    sum += p[j];
  }
  EXPECT_LE(sum, 1.0 + 1e-9);
  EXPECT_GT(sum, 0.5);
  const int draws = 1 << 18;
  std::vector<int> counts(size, 0);
  int empty = 0;
  for (int i = 0; i < draws; ++i) {
    double probability = -1.0;
    const int j = tree.Sample(x, n, (i + 0.5) / draws, &probability);
    if (j < 0) {
      EXPECT_EQ(probability, 0.0);
      ++empty;
      continue;
    }
    ASSERT_EQ(probability, p[j]) << j;  // the same arithmetic along the same path.
    ++counts[j];
  }
  for (int j = 0; j < size; ++j) {
    const double expected = draws * p[j];
    EXPECT_NEAR(counts[j], expected, 5.0 * std::sqrt(expected) + 3.0) << j;
  }
  const double expected_empty = draws * std::max(0.0, 1.0 - sum);
  EXPECT_NEAR(empty, expected_empty, 5.0 * std::sqrt(expected_empty) + 3.0);
}

TEST(EdgeTreeTest, ProbabilitiesSumToOneAndMatchTheDraws) {
  const Segments s = RandomSegments(500, 1.0f, 1);
  const EdgeTree tree(s.a, s.b, s.lengths);
  ASSERT_FALSE(tree.empty());
  ExpectConsistent(tree, {0.5, 0.5, 0.5}, Eigen::Vector3d(1, 2, 3).normalized());      // inside
  ExpectConsistent(tree, {3.0, -2.0, 0.5}, Eigen::Vector3d(-1, 0.5, 0).normalized());  // outside
}

// The order is a permutation, and every position's segment is the input segment it names.
TEST(EdgeTreeTest, OrderIsAPermutation) {
  const Segments s = RandomSegments(123, 1.0f, 2);
  const EdgeTree tree(s.a, s.b, s.lengths);
  std::vector<int> seen(s.a.size(), 0);
  for (int i : tree.order()) ++seen[i];
  for (int count : seen) EXPECT_EQ(count, 1);
}

// Segments wholly below x's plane are never drawn (their integrand is zero there); a segment
// with any point above it always can be.
TEST(EdgeTreeTest, SegmentsBelowThePlaneAreNeverDrawn) {
  Segments s;
  for (int i = 0; i < 40; ++i) {
    const float t = static_cast<float>(i);
    s.Add({t, 0.0f, -1.0f - 0.1f * t}, {t + 0.5f, 0.0f, -1.0f});  // below z = 0
  }
  s.Add({0.0f, 1.0f, -1.0f}, {0.0f, 1.0f, 0.01f});  // crosses z = 0
  s.Add({5.0f, 5.0f, 2.0f}, {5.0f, 6.0f, 2.0f});    // above
  const EdgeTree tree(s.a, s.b, s.lengths);
  const Eigen::Vector3d x(0, 0, 0), n(0, 0, 1);
  for (int j = 0; j < static_cast<int>(tree.order().size()); ++j) {
    const int input = tree.order()[j];
    const double p = tree.Probability(x, n, j);
    if (input < 40) {
      // A below-plane segment may share a bounding sphere with the others; then it keeps a
      // probability, but a lone cluster of them does not.
      EXPECT_GE(p, 0.0);
    } else {
      EXPECT_GT(p, 0.0) << input;
    }
  }
  // Looking down (n = −z) from high above the above-plane segment.
  const Eigen::Vector3d high(5.0, 5.5, 10.0), down(0, 0, -1);
  ExpectConsistent(tree, high, down);
  // Everything below a plane high above: nothing to draw.
  double probability = 1.0;
  EXPECT_EQ(tree.Sample({0, 0, 100}, {0, 0, 1}, 0.5, &probability), -1);
  EXPECT_EQ(probability, 0.0);
}

// Two equal clusters, one at distance ~1 and one at ~100: the near one gets nearly all the
// probability (∝ 1/r², so about 10⁴ : 1).
TEST(EdgeTreeTest, NearClustersAreFavoured) {
  Segments s = RandomSegments(64, 0.2f, 3);
  const Segments far = RandomSegments(64, 0.2f, 4);
  for (size_t i = 0; i < far.a.size(); ++i) {
    s.Add(far.a[i] + Eigen::Vector3f(100, 0, 0), far.b[i] + Eigen::Vector3f(100, 0, 0));
  }
  const EdgeTree tree(s.a, s.b, s.lengths);
  const Eigen::Vector3d x(-1.0, 0.1, 0.1), n(1, 0, 0);
  double near = 0.0, far_sum = 0.0;
  for (int j = 0; j < static_cast<int>(tree.order().size()); ++j) {
    (tree.order()[j] < 64 ? near : far_sum) += tree.Probability(x, n, j);
  }
  EXPECT_GT(near / far_sum, 1e3);
  EXPECT_GT(far_sum, 0.0);
}

// Scenes far from unit scale: the probabilities stay finite and normalized.
TEST(EdgeTreeTest, FiniteAtTinyAndHugeScales) {
  for (const float scale : {1e-9f, 1e9f}) {
    const Segments s = RandomSegments(200, scale, 5);
    const EdgeTree tree(s.a, s.b, s.lengths);
    ExpectConsistent(tree, Eigen::Vector3d(0.5, 0.5, 0.5) * scale, Eigen::Vector3d(0, 0, 1));
  }
}

// A cut prepared once serves every draw at its point: the draws and probabilities equal those of
// single draws at (x, n), on a tree deep enough to descend below the cut.
TEST(EdgeTreeTest, OneCutServesEveryDrawAtItsPoint) {
  const Segments s = RandomSegments(5000, 1.0f, 6);
  const EdgeTree tree(s.a, s.b, s.lengths);
  const Eigen::Vector3d x(0.3, 0.6, 0.4), n = Eigen::Vector3d(0.2, -1, 0.4).normalized();
  EdgeTree::Cut cut;
  tree.PrepareCut(x, n, &cut);
  ASSERT_GT(cut.count, 4);
  ASSERT_LE(cut.count, EdgeTree::Cut::kMaxEntries);
  for (int i = 0; i < 1000; ++i) {
    const double u = (i + 0.25) / 1000.0;
    double p_cut = -1.0, p_single = -1.0;
    const int j = tree.Sample(cut, u, &p_cut);
    EXPECT_EQ(j, tree.Sample(x, n, u, &p_single));
    EXPECT_EQ(p_cut, p_single);
    if (j >= 0) {
      EXPECT_EQ(tree.Probability(cut, j), p_cut);
    }
  }
  ExpectConsistent(tree, x, n);
}

}  // namespace
}  // namespace render_internal
}  // namespace sft
