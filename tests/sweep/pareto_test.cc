// The Pareto front of accuracy against time (src/sweep/pareto.h) against hand-computed answers.
#include "src/sweep/pareto.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sft {
namespace {

// Points (seconds, value), by hand:
//   0 (10, 20)  first in time                       -> on both fronts
//   1 (12, 19)  worse than 0 if higher is better    -> on the lower-is-better front only
//   2 (15, 25)  better than all cheaper points      -> higher-is-better front
//   3 (15, 24)  same time as 2, worse               -> dominated by 2
//   4 (20, 25)  as good as 2, slower                -> dominated by 2
//   5 (30, 31)  best                                -> front
//   6 (5, NaN)  no value                            -> left out
//   7 (25, 30)  better than everything cheaper      -> front
//   8 (30, 31)  equal to 5                          -> front, beside 5
//   9 (inf, 99) no time                             -> left out
TEST(ParetoTest, HandComputedFronts) {
  const double nan = std::nan("");
  const std::vector<double> seconds = {10, 12, 15, 15, 20, 30, 5, 25, 30, HUGE_VAL};
  const std::vector<double> value = {20, 19, 25, 24, 25, 31, nan, 30, 31, 99};
  EXPECT_EQ(ParetoFront(seconds, value, /*higher_is_better=*/true),
            (std::vector<int>{0, 2, 7, 5, 8}));
  // Lower is better (Chamfer): only 0 and then 1 improve on everything cheaper.
  EXPECT_EQ(ParetoFront(seconds, value, /*higher_is_better=*/false), (std::vector<int>{0, 1}));
}

TEST(ParetoTest, EdgeCases) {
  EXPECT_TRUE(ParetoFront({}, {}, true).empty());
  EXPECT_EQ(ParetoFront({3}, {1}, true), (std::vector<int>{0}));
  // A faster and better point dominates everything: the front is that point.
  EXPECT_EQ(ParetoFront({5, 1, 3}, {1, 9, 2}, true), (std::vector<int>{1}));
  // Strictly increasing time and value: all on the front, in time order.
  EXPECT_EQ(ParetoFront({3, 1, 2}, {30, 10, 20}, true), (std::vector<int>{1, 2, 0}));
}

}  // namespace
}  // namespace sft
