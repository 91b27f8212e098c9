// Memory estimates and the memory budget check (issue 9: a 100000² camera used to end in
// std::bad_alloc).
#include "src/core/memory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

namespace sft {
namespace {

using ::testing::HasSubstr;

TEST(MemoryTest, EstimateImageBytes) {
  EXPECT_EQ(EstimateImageBytes(128, 64, 4), 128u * 64 * 4 * 4);
  EXPECT_EQ(EstimateImageBytes(100000, 100000, 4), 160000000000ull);  // No 32-bit overflow.
  EXPECT_EQ(EstimateImageBytes(10, 10, 3, 8), 2400u);
  EXPECT_EQ(EstimateImageBytes(-1, 10, 3), 0u);
  const int64_t huge = std::numeric_limits<int64_t>::max();
  EXPECT_EQ(EstimateImageBytes(huge, huge, 4), std::numeric_limits<uint64_t>::max());
}

TEST(MemoryTest, BudgetRefusesMoreThanAvailable) {
  const uint64_t available = AvailableMemoryBytes();
  ASSERT_GT(available, 0u) << "/proc/meminfo is readable on Linux";
  std::string why;
  EXPECT_TRUE(CheckMemoryBudget(1 << 20, "a small thing", &why));
  EXPECT_FALSE(CheckMemoryBudget(EstimateImageBytes(100000, 100000, 4), "rendering it", &why));
  EXPECT_THAT(why, HasSubstr("rendering it needs an estimated 149 GB, more than the "));
  EXPECT_THAT(why, HasSubstr("of memory available"));
}

TEST(MemoryTest, FormatBytes) {
  EXPECT_EQ(FormatBytes(512), "512 bytes");
  EXPECT_EQ(FormatBytes(1536), "1.5 kB");
  EXPECT_EQ(FormatBytes(uint64_t{3} << 30), "3 GB");
}

}  // namespace
}  // namespace sft
