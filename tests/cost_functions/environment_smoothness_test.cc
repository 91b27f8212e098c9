// The fitted environment's neighbour pairs (cost_functions/environment_smoothness.h).
#include "cost_functions/environment_smoothness.h"

#include <gtest/gtest.h>

#include <set>
#include <utility>

namespace sft {
namespace {

std::set<std::pair<int, int>> AsSet(const std::vector<TexelPair>& pairs) {
  std::set<std::pair<int, int>> set;
  for (const TexelPair& p : pairs) set.insert({std::min(p.a, p.b), std::max(p.a, p.b)});
  return set;
}

// 4 × 3: 12 horizontal pairs (u wraps: texel 3 meets texel 0 in every row) and 8 vertical ones,
// none twice.
TEST(EnvironmentSmoothnessTest, PairsWrapAroundTheHorizon) {
  const std::vector<TexelPair> pairs = EnvironmentNeighbourPairs(4, 3);
  EXPECT_EQ(pairs.size(), 20u);
  const auto set = AsSet(pairs);
  EXPECT_EQ(set.size(), pairs.size());
  EXPECT_TRUE(set.count({0, 3}));   // row 0 wraps.
  EXPECT_TRUE(set.count({8, 11}));  // row 2 wraps.
  EXPECT_TRUE(set.count({1, 5}));   // vertical.
  EXPECT_FALSE(set.count({3, 4}));  // the end of row 0 is not the start of row 1.
  EXPECT_FALSE(set.count({0, 8}));  // no pair across a pole.
}

// Width 2 pairs its two texels once per row; width 1 has vertical pairs only.
TEST(EnvironmentSmoothnessTest, NarrowGridsHaveNoDuplicates) {
  EXPECT_EQ(EnvironmentNeighbourPairs(2, 2).size(), 2u + 2u);
  EXPECT_EQ(AsSet(EnvironmentNeighbourPairs(2, 2)).size(), 4u);
  EXPECT_EQ(EnvironmentNeighbourPairs(1, 3).size(), 2u);
}

}  // namespace
}  // namespace sft
