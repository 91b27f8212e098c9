// Which views --holdout K keeps out of the fit and how the stages' views follow
// (src/optim/holdout.h).
#include "src/optim/holdout.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace sft {
namespace {

using ::testing::HasSubstr;

TEST(HoldoutTest, EveryKthSelectedViewFromTheFirst) {
  std::vector<int> held;
  ASSERT_TRUE(ChooseHeldOutViews(8, {}, 20, &held).ok());
  EXPECT_EQ(held, std::vector<int>({0, 8, 16}));
  ASSERT_TRUE(ChooseHeldOutViews(2, {}, 4, &held).ok());
  EXPECT_EQ(held, std::vector<int>({0, 2}));
  // Within --views: positions 0, 2, 4 of the selection.
  ASSERT_TRUE(ChooseHeldOutViews(2, {9, 3, 5, 7, 1}, 10, &held).ok());
  EXPECT_EQ(held, std::vector<int>({1, 5, 9}));
  ASSERT_TRUE(ChooseHeldOutViews(0, {}, 4, &held).ok());
  EXPECT_TRUE(held.empty());
  // K larger than the selection holds out its first view only.
  ASSERT_TRUE(ChooseHeldOutViews(50, {}, 4, &held).ok());
  EXPECT_EQ(held, std::vector<int>({0}));
}

TEST(HoldoutTest, BadValuesAreErrors) {
  std::vector<int> held;
  EXPECT_THAT(ChooseHeldOutViews(1, {}, 4, &held).message(), HasSubstr("--holdout"));
  EXPECT_FALSE(ChooseHeldOutViews(-3, {}, 4, &held).ok());
  const Status none = ChooseHeldOutViews(2, {3}, 4, &held);
  EXPECT_FALSE(none.ok());
  EXPECT_THAT(none.message(), HasSubstr("none to fit"));
  EXPECT_FALSE(ChooseHeldOutViews(2, {}, 1, &held).ok());
}

TEST(HoldoutTest, StagesNeverFitAHeldOutView) {
  std::vector<StageOptions> stages(3);
  stages[0].name = "all";
  stages[1].name = "some";
  stages[1].fit.views = {0, 1, 2};
  stages[2].name = "other";
  stages[2].fit.views = {3};
  std::vector<int> held;
  ASSERT_TRUE(ApplyHoldout(2, {}, 4, &stages, &held).ok());
  EXPECT_EQ(held, std::vector<int>({0, 2}));
  EXPECT_EQ(stages[0].fit.views, std::vector<int>({1, 3}));
  EXPECT_EQ(stages[1].fit.views, std::vector<int>({1}));
  EXPECT_EQ(stages[2].fit.views, std::vector<int>({3}));
  // A stage that names held-out views only.
  stages[2].fit.views = {0, 2};
  const Status status = ExcludeHeldOutViews({0, 2}, 4, &stages);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("stage other"));
  EXPECT_THAT(status.message(), HasSubstr("held out"));
}

}  // namespace
}  // namespace sft
