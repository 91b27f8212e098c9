// The held-out views' gain choices (src/eval/held_out_eval.h) on cases with known answers: the
// per-view least-squares gain, the median of the fitted gains, and which gains a run's state.json
// contributes.
#include "src/eval/held_out_eval.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "src/optim/run_outputs.h"
#include "src/optim/schedule_config.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_images.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

TEST(HeldOutEvalTest, GainFitOfAHalfBrightTargetIsOneHalf) {
  const Image ours = testing::SmoothPattern(24, 20);
  const Image target = ScaleChannels(ours, Eigen::Vector3d::Constant(0.5));
  const Eigen::Vector3d gain = FitViewGain(ours, target, Image());
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(gain[c], 0.5, 1e-6) << c;
  HeldOutScores scores;
  ASSERT_TRUE(scores.Add(3, ours, target, Image(), Eigen::Vector3d::Ones()).ok());
  const nlohmann::json j = scores.ToJson();
  ASSERT_EQ(j["per_view"].size(), 1u);
  EXPECT_EQ(j["per_view"][0]["view"], 3);
  // Without the fit the error is half the image (about 6 dB for values near 0.5); after it the
  // images are equal up to float rounding.
  EXPECT_LT(j["per_view"][0]["psnr_linear"].get<double>(), 12.0);
  EXPECT_GT(j["per_view"][0]["psnr_linear_gain_fit"].get<double>(), 90.0);
  EXPECT_NEAR(j["per_view"][0]["gain_fit"][1].get<double>(), 0.5, 1e-6);
  // The view's own gain given as the median gain scores as well as the fit.
  HeldOutScores with_gain;
  ASSERT_TRUE(with_gain.Add(3, ours, target, Image(), Eigen::Vector3d::Constant(0.5)).ok());
  EXPECT_GT(with_gain.ToJson()["psnr_linear"].get<double>(), 90.0);
}

TEST(HeldOutEvalTest, GainFitIsPerChannelAndOverTheMask) {
  const Image ours = testing::SmoothPattern(16, 16);
  Image target = ScaleChannels(ours, Eigen::Vector3d(0.5, 2.0, 0.25));
  Image mask(16, 16, 1, 1.0f);
  for (int y = 0; y < 16; ++y) {
    mask.at(0, y) = 0.0f;  // outside the mask the target is unrelated.
    for (int c = 0; c < 3; ++c) target.at(0, y, c) = 7.0f;
  }
  const Eigen::Vector3d gain = FitViewGain(ours, target, mask);
  EXPECT_NEAR(gain[0], 0.5, 1e-6);
  EXPECT_NEAR(gain[1], 2.0, 1e-6);
  EXPECT_NEAR(gain[2], 0.25, 1e-6);
  // Without the mask the unrelated column pulls the gains up.
  EXPECT_GT(FitViewGain(ours, target, Image())[2], 0.3);
  // A channel black in ours keeps gain 1.
  Image black = ours;
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) black.at(x, y, 1) = 0.0f;
  }
  EXPECT_EQ(FitViewGain(black, target, mask)[1], 1.0);
}

TEST(HeldOutEvalTest, MedianGainPerChannel) {
  EXPECT_EQ(MedianGain({}), Eigen::Vector3d::Ones());
  const Eigen::Vector3d median = MedianGain(
      {Eigen::Vector3d(1, 10, 3), Eigen::Vector3d(2, 1, 3), Eigen::Vector3d(10, 2, 0.5)});
  EXPECT_EQ(median, Eigen::Vector3d(2, 2, 3));
  EXPECT_EQ(MedianGain({Eigen::Vector3d::Constant(1), Eigen::Vector3d::Constant(2),
                        Eigen::Vector3d::Constant(3), Eigen::Vector3d::Constant(10)}),
            Eigen::Vector3d::Constant(2.5));
}

// state.json of a run that held out view 0 and fitted exposure on views 1..3 (gains 1, 2, 10):
// the held-out gain is their median, 2; view 0's own recorded gain (100) does not count, nor do
// views only a stage without exposure fitted.
TEST(HeldOutEvalTest, SetupTakesTheMedianOfTheExposureFittedViews) {
  testing::TempDir tmp;
  StageOptions texture;
  texture.name = "texture";
  texture.fit.fit_exposure = true;
  texture.fit.views = {1, 2, 3};
  StageOptions shape;
  shape.name = "shape";
  shape.fit.views = {1, 2, 3, 4};
  RunState state;
  state.run_info = {{"dataset", "ds"}};
  state.stages = {StageJson(texture), StageJson(shape)};
  state.view_gains = {Eigen::Vector3d::Constant(100), Eigen::Vector3d::Constant(1),
                      Eigen::Vector3d::Constant(2), Eigen::Vector3d::Constant(10),
                      Eigen::Vector3d::Constant(50)};
  state.holdout = 4;
  state.held_out_views = {0};
  ASSERT_TRUE(WriteRunState(tmp.path(), state).ok());
  HeldOutSetup setup;
  ASSERT_TRUE(ReadHeldOutSetup(tmp.path(), 5, &setup).ok());
  EXPECT_EQ(setup.views, std::vector<int>({0}));
  EXPECT_EQ(setup.gain_views, std::vector<int>({1, 2, 3}));
  EXPECT_EQ(setup.gain, Eigen::Vector3d::Constant(2));
  // No stage fitted exposure: gain 1.
  texture.fit.fit_exposure = false;
  state.stages = {StageJson(texture)};
  ASSERT_TRUE(WriteRunState(tmp.path(), state).ok());
  ASSERT_TRUE(ReadHeldOutSetup(tmp.path(), 5, &setup).ok());
  EXPECT_EQ(setup.gain, Eigen::Vector3d::Ones());
  EXPECT_TRUE(setup.gain_views.empty());
  // A run without held-out views, or whose held-out view the dataset lacks: one line.
  state.held_out_views = {7};
  ASSERT_TRUE(WriteRunState(tmp.path(), state).ok());
  EXPECT_THAT(ReadHeldOutSetup(tmp.path(), 5, &setup).message(), HasSubstr("held_out_views"));
  state.held_out_views.clear();
  state.holdout = 0;
  ASSERT_TRUE(WriteRunState(tmp.path(), state).ok());
  const Status none = ReadHeldOutSetup(tmp.path(), 5, &setup);
  EXPECT_FALSE(none.ok());
  EXPECT_THAT(none.message(), HasSubstr("held out no views"));
}

}  // namespace
}  // namespace sft
