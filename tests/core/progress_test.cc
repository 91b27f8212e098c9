// The ETA of work in kinds: each kind's remaining units at its own measured rate.
#include "src/core/progress.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

namespace sft {
namespace {

// Nothing done: no rate to extrapolate.
TEST(RemainingSecondsTest, NothingDoneIsZero) {
  EXPECT_EQ(RemainingSeconds({}), 0.0);
  EXPECT_EQ(RemainingSeconds({{100, 0, 0.0}, {50, 0, 0.0}}), 0.0);
}

// One kind: remaining × seconds / done, the single-rate ETA every progress line had.
TEST(RemainingSecondsTest, OneKindExtrapolatesItsRate) {
  EXPECT_DOUBLE_EQ(RemainingSeconds({{100, 25, 50.0}}), 75 * 2.0);
  EXPECT_DOUBLE_EQ(RemainingSeconds({{100, 100, 50.0}}), 0.0);
  EXPECT_DOUBLE_EQ(RemainingSeconds({{100, 120, 50.0}}), 0.0);  // done past the total.
}

// An expensive kind first (4 s per unit) and a cheap one after it (0.5 s per unit): once both
// have run, each is priced at its own rate; a kind not started yet takes the rate over all the
// work done so far.
TEST(RemainingSecondsTest, EachKindAtItsOwnRate) {
  // Only the expensive kind has run: the cheap kind takes its rate (the old single-rate ETA).
  EXPECT_DOUBLE_EQ(RemainingSeconds({{10, 10, 40.0}, {200, 0, 0.0}}), 200 * 4.0);
  // Both have run: 180 cheap units left at 0.5 s, none of the expensive.
  EXPECT_DOUBLE_EQ(RemainingSeconds({{10, 10, 40.0}, {200, 20, 10.0}}), 180 * 0.5);
  // A third kind not started takes the overall rate: (40 + 10) s / 30 units.
  EXPECT_DOUBLE_EQ(RemainingSeconds({{10, 10, 40.0}, {200, 20, 10.0}, {30, 0, 0.0}}),
                   180 * 0.5 + 30 * (50.0 / 30.0));
}

// Progress with kinds: the wall time between two Advance calls goes to the advancing kind.
TEST(ProgressTest, TimeBetweenAdvancesGoesToTheAdvancingKind) {
  Progress progress("test", std::vector<int64_t>{10, 20, 30}, /*enabled=*/false);
  progress.Advance(5, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  progress.Advance(10, 2);
  const std::vector<WorkKind> kinds = progress.kinds();
  ASSERT_EQ(kinds.size(), 3u);
  EXPECT_EQ(kinds[0].total, 10);
  EXPECT_EQ(kinds[0].done, 5);
  EXPECT_EQ(kinds[1].done, 0);
  EXPECT_EQ(kinds[2].done, 10);
  // The first Advance counts from the construction, a moment before it (the bound leaves room
  // for a loaded machine; an unset start time reads far outside it).
  EXPECT_GE(kinds[0].seconds, 0.0);
  EXPECT_LT(kinds[0].seconds, 1.0);
  EXPECT_GE(kinds[2].seconds, 0.05);
  EXPECT_EQ(kinds[1].seconds, 0.0);
  // One kind: no per-kind record (the single-rate ETA).
  EXPECT_TRUE(Progress("one", int64_t{10}, false).kinds().empty());
}

}  // namespace
}  // namespace sft
