// COLMAP's progress lines and a missing executable (src/capture/colmap_runner.h).
#include "src/capture/colmap_runner.h"

#include <gtest/gtest.h>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

TEST(ColmapRunnerTest, ParsesProgressLines) {
  int done = 0, total = 0;
  ASSERT_TRUE(ParseColmapProgress("feature_extractor", "Processed file [12/60]", &done, &total));
  EXPECT_EQ(done, 12);
  EXPECT_EQ(total, 60);
  ASSERT_TRUE(ParseColmapProgress("exhaustive_matcher", "Matching block [2/2, 1/2] in 3.1s", &done,
                                  &total));
  EXPECT_EQ(done, 3);
  EXPECT_EQ(total, 4);
  ASSERT_TRUE(
      ParseColmapProgress("sequential_matcher", "Matching image [7/200] in 0.2s", &done, &total));
  EXPECT_EQ(done, 7);
  ASSERT_TRUE(ParseColmapProgress("mapper", "Registering image #17 (9)", &done, &total));
  EXPECT_EQ(done, 9);
  EXPECT_FALSE(ParseColmapProgress("mapper", "Bundle adjustment report", &done, &total));
}

// A missing COLMAP executable is one clear error.
TEST(ColmapRunnerTest, MissingExecutable) {
  testing::TempDir tmp;
  double seconds = 0;
  const Status status =
      RunColmapStage("/nonexistent/colmap", "mapper", {}, tmp.Join("log.txt"), 1, false, &seconds);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("COLMAP not found"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace sft
