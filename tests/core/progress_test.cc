// The ETA of work in kinds: each kind's remaining units at its own measured rate.
#include "src/core/progress.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

namespace sft {
namespace {

// Nothing timed: no rate to extrapolate.
TEST(RemainingSecondsTest, NothingTimedIsZero) {
  EXPECT_EQ(RemainingSeconds({}), 0.0);
  EXPECT_EQ(RemainingSeconds({{100, 0, 0, 0.0}, {50, 0, 0, 0.0}}), 0.0);
  EXPECT_EQ(RemainingSeconds({{100, 5, 0, 0.0}}), 0.0);  // one untimed first step.
}

// One kind: remaining × seconds / timed units.
TEST(RemainingSecondsTest, OneKindExtrapolatesItsRate) {
  EXPECT_DOUBLE_EQ(RemainingSeconds({{100, 25, 20, 40.0}}), 75 * 2.0);
  EXPECT_DOUBLE_EQ(RemainingSeconds({{100, 100, 95, 50.0}}), 0.0);
  EXPECT_DOUBLE_EQ(RemainingSeconds({{100, 120, 115, 50.0}}), 0.0);  // done past the total.
}

// An expensive kind first (4 s per unit) and a cheap one after it (0.5 s per unit): once both
// have been timed, each is priced at its own rate; a kind not timed yet takes the rate over all
// the timed work.
TEST(RemainingSecondsTest, EachKindAtItsOwnRate) {
  // Only the expensive kind has been timed: the cheap one, whose first step is done, takes its
  // rate.
  EXPECT_DOUBLE_EQ(RemainingSeconds({{10, 10, 9, 36.0}, {200, 1, 0, 0.0}}), 199 * 4.0);
  // Both timed: 180 cheap units left at 0.5 s, none of the expensive.
  EXPECT_DOUBLE_EQ(RemainingSeconds({{10, 10, 9, 36.0}, {200, 20, 19, 9.5}}), 180 * 0.5);
  // A third kind not started takes the overall rate: (36 + 9.5) s / 28 timed units.
  EXPECT_DOUBLE_EQ(RemainingSeconds({{10, 10, 9, 36.0}, {200, 20, 19, 9.5}, {30, 0, 0, 0.0}}),
                   180 * 0.5 + 30 * (45.5 / 28.0));
}

// Progress with kinds: the wall time between two Advance calls goes to the advancing kind, except
// for a kind's first step (its set-up), which is done but not timed.
TEST(ProgressTest, TimeBetweenAdvancesGoesToTheAdvancingKind) {
  Progress progress("test", std::vector<int64_t>{10, 20, 30}, /*enabled=*/false);
  progress.Advance(5, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  progress.Advance(10, 2);  // kind 2's first step: not timed.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  progress.Advance(4, 2);
  progress.Advance(1, 0);
  const std::vector<WorkKind> kinds = progress.kinds();
  ASSERT_EQ(kinds.size(), 3u);
  EXPECT_EQ(kinds[0].total, 10);
  EXPECT_EQ(kinds[0].done, 6);
  EXPECT_EQ(kinds[0].timed, 1);
  EXPECT_EQ(kinds[1].done, 0);
  EXPECT_EQ(kinds[2].done, 14);
  EXPECT_EQ(kinds[2].timed, 4);
  // Kind 2's timed step took the second sleep; kind 0's the moment after it (the bound leaves
  // room for a loaded machine).
  EXPECT_GE(kinds[2].seconds, 0.05);
  EXPECT_GE(kinds[0].seconds, 0.0);
  EXPECT_LT(kinds[0].seconds, 1.0);
  EXPECT_EQ(kinds[1].seconds, 0.0);
  // One kind: no per-kind record (the single-rate ETA).
  EXPECT_TRUE(Progress("one", int64_t{10}, false).kinds().empty());
}

}  // namespace
}  // namespace sft
