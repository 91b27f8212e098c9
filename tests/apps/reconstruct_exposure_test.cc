// sft reconstruct with fit_exposure end to end: exposure.json and state.json carry the fitted
// gains, --resume continues from them, and bad values of the keys are one error line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountLines;
using ::testing::HasSubstr;
using testing::RunSft;
namespace fs = std::filesystem;

TEST(ReconstructExposureTest, GainsAreWrittenAndResumed) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(
                tmp.Join("ds"),
                "--cameras 4 --zooms 1 --res 32 --spp 32 --bounces 1 --shading flat "
                "--material '{\"albedo\": [0.6, 0.5, 0.4], \"roughness\": 0.5, \"specular\": 0}'"),
            "");
  // View 1's photograph was taken with other exposure and white balance.
  const double kGain[3] = {1.2, 1.0, 0.8};
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  Image image;
  ASSERT_TRUE(LoadViewImage(dataset, 1, &image).ok());
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] *= static_cast<float>(kGain[i % 3]);
  ASSERT_TRUE(WriteImage(tmp.Join("ds/" + dataset.views[1].image), image).ok());
  testing::WriteTestFile(tmp.Join("cfg.json"),
                         R"({"fit_exposure": true, "albedo_smoothness": 0.1})");
  const std::string common = "reconstruct --quiet --dataset " + tmp.Join("ds") +
                             " --spp 8 --bounces 1 --steps 5 --phases texture";
  std::string out;
  ASSERT_EQ(RunSft(common + " --init " + tmp.Join("ds/gt/mesh.ply") + " --config " +
                       tmp.Join("cfg.json") + " --out " + tmp.Join("r") + " --outer 2",
                   &out),
            0)
      << out;
  const nlohmann::json exposure =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/exposure.json")));
  EXPECT_EQ(exposure["format"], "sft-exposure/1");
  EXPECT_EQ(exposure["gauge_view"], 0);
  ASSERT_EQ(exposure["views"].size(), 4u);
  EXPECT_EQ(exposure["views"][1]["image"], dataset.views[1].image);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(exposure["views"][0]["gains"][c].get<double>(), 1.0);
    // A short fit from a grey start at 8 spp (smoothness ties texels one view sees to the
    // others'): within 5% of the photograph's change.
    EXPECT_NEAR(exposure["views"][1]["gains"][c].get<double>(), kGain[c], 0.05 * kGain[c]) << c;
  }
  const nlohmann::json state =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/state.json")));
  ASSERT_EQ(state["exposure_gains"].size(), 4u);
  EXPECT_EQ(state["exposure_gains"][1], exposure["views"][1]["gains"]);

  // Resume for one more outer iteration of geometry (gains fixed, rendered with): the gains
  // continue from the checkpoint. A restart at 1 would leave view 1's render 20% off in red and
  // blue, far above the fitted cost and many dB below the fitted PSNR.
  const nlohmann::json before =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/metrics.json")));
  const double last_cost = before["iterations"].back()["cost"].get<double>();
  const double last_psnr = before["iterations"].back()["view_psnr"][1].get<double>();
  const size_t records = before["iterations"].size();
  ASSERT_EQ(RunSft("reconstruct --quiet --resume " + tmp.Join("r") + " --outer 3 --phases geometry",
                   &out),
            0)
      << out;
  const nlohmann::json after =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/metrics.json")));
  ASSERT_GT(after["iterations"].size(), records);
  const double resumed_cost = after["iterations"][records]["cost"].get<double>();
  EXPECT_EQ(after["iterations"][records]["phase"], "geometry");
  EXPECT_LT(resumed_cost, 1.5 * last_cost) << resumed_cost << " vs " << last_cost;
  const double resumed_psnr = after["iterations"][records]["view_psnr"][1].get<double>();
  EXPECT_GT(resumed_psnr, last_psnr - 3.0) << resumed_psnr << " vs " << last_psnr;
  const nlohmann::json resumed =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/exposure.json")));
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(resumed["views"][1]["gains"][c].get<double>(), kGain[c], 0.05 * kGain[c]) << c;
  }
}

TEST(ReconstructExposureTest, BadKeysAreOneLine) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 1 --zooms 1 --res 8 --spp 2"), "");
  const std::string base = "reconstruct --quiet --dataset " + tmp.Join("ds") + " --init " +
                           tmp.Join("ds/gt/mesh.ply") + " --out " + tmp.Join("o") + " --config " +
                           tmp.Join("cfg.json");
  for (const auto& [config, key] : std::vector<std::pair<std::string, std::string>>{
           {R"({"fit_exposure": 1})", "fit_exposure: expected true or false"},
           {R"({"exposure_prior": -2})", "exposure_prior: expected a number in [0"},
           {R"({"stages": [{"name": "a", "exposure_prior": "high"}]})", "exposure_prior"}}) {
    testing::WriteTestFile(tmp.Join("cfg.json"), config);
    std::string out;
    EXPECT_EQ(RunSft(base, &out), 1) << config;
    EXPECT_THAT(out, HasSubstr(key));
    EXPECT_EQ(CountLines(out), 1) << out;
    EXPECT_FALSE(fs::exists(tmp.Join("o/state.json")));
  }
}

}  // namespace
}  // namespace sft
