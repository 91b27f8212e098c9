// sft reconstruct --holdout and sft eval --held-out end to end on a tiny synthesized dataset:
// held-out views stay out of every fit (also on resume), are recorded in state.json and are
// scored by eval and shown in the report; bad values are one line and write nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountLines;
using testing::RunSft;

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

nlohmann::json ReadJson(const std::string& path) {
  return nlohmann::json::parse(testing::ReadTestFile(path));
}

// The number of entries of view_psnr in every iteration record of metrics.json, when all agree
// (-1 otherwise).
int ViewPsnrCount(const nlohmann::json& metrics) {
  int count = -2;
  for (const nlohmann::json& it : metrics["iterations"]) {
    const int n = static_cast<int>(it["view_psnr"].size());
    if (count != -2 && n != count) return -1;
    count = n;
  }
  return count;
}

TEST(ReconstructHoldoutTest, HeldOutViewsAreKeptOutAndScored) {
  testing::TempDir tmp;
  ASSERT_EQ(
      testing::SynthIcosphere(tmp.Join("ds"),
                              "--cameras 4 --zooms 1 --res 24 --spp 32 --bounces 1 "
                              "--material '{\"albedo\": [0.6, 0.5, 0.4], \"roughness\": 0.5}'"),
      "");
  std::string out;
  const std::string run = tmp.Join("r");
  ASSERT_EQ(RunSft("reconstruct --quiet --dataset " + tmp.Join("ds") + " --init " +
                       tmp.Join("ds/gt/mesh.ply") +
                       " --spp 8 --bounces 1 --steps 2 --phases texture --outer 1 --holdout 2 "
                       "--out " +
                       run,
                   &out),
            0)
      << out;
  // The report shows the held-out views beside the fitted ones.
  const std::string page = testing::ReadTestFile(run + "/report.html");
  EXPECT_THAT(page, HasSubstr("view 0 (held out)"));
  EXPECT_THAT(page, HasSubstr("view 2 (held out)"));
  EXPECT_THAT(page, HasSubstr("PSNR after its own gain"));
  // ...and the held-out views relit by the studio lights (src/eval/studio_lights.h).
  EXPECT_THAT(page, HasSubstr("Relit (lights the fit never saw)"));
  for (const char* file : {"relit_0_capture.png", "relit_0_key.png", "relit_2_ambient.png"}) {
    EXPECT_TRUE(std::filesystem::exists(run + "/report_files/" + file)) << file;
  }
  const nlohmann::json state = ReadJson(run + "/state.json");
  EXPECT_EQ(state["held_out_views"], nlohmann::json({0, 2}));
  EXPECT_EQ(state["holdout"], 2);
  EXPECT_EQ(state["stages"][0]["views"], nlohmann::json({1, 3}));
  const nlohmann::json metrics = ReadJson(run + "/metrics.json");
  ASSERT_FALSE(metrics["iterations"].empty());
  EXPECT_EQ(ViewPsnrCount(metrics), 2);
  EXPECT_EQ(metrics["held_out_views"], nlohmann::json({0, 2}));

  // A resume keeps the held-out views out, even when --views names them; a different --holdout
  // is one line.
  EXPECT_EQ(RunSft("reconstruct --quiet --no-report --resume " + run + " --holdout 3", &out), 1);
  EXPECT_THAT(out, HasSubstr("--holdout 3"));
  EXPECT_EQ(CountLines(out), 1) << out;
  ASSERT_EQ(RunSft("reconstruct --quiet --no-report --resume " + run +
                       " --outer 2 --holdout 2 --views 0,1,2,3",
                   &out),
            0)
      << out;
  const nlohmann::json resumed = ReadJson(run + "/metrics.json");
  EXPECT_GT(resumed["iterations"].size(), metrics["iterations"].size());
  EXPECT_EQ(ViewPsnrCount(resumed), 2);
  EXPECT_EQ(ReadJson(run + "/state.json")["held_out_views"], nlohmann::json({0, 2}));

  // eval --held-out: views 0 and 2, their means, the gain fit no worse than the plain PSNR.
  const std::string json_path = tmp.Join("held_out.json");
  ASSERT_EQ(RunSft("eval --dataset " + tmp.Join("ds") + " --reconstruction " + run +
                       " --spp 16 --bounces 1 --held-out --json " + json_path,
                   &out),
            0)
      << out;
  const nlohmann::json report = ReadJson(json_path);
  EXPECT_EQ(report, nlohmann::json::parse(out));
  EXPECT_EQ(report["views"], nlohmann::json({0, 2}));
  const nlohmann::json& held = report["held_out"];
  EXPECT_EQ(held["views"], nlohmann::json({0, 2}));
  EXPECT_EQ(held["gain"], nlohmann::json({1.0, 1.0, 1.0}));  // no exposure was fitted.
  ASSERT_EQ(held["views"].size(), 2u);
  double psnr_sum = 0.0;
  for (size_t i = 0; i < 2; ++i) {
    const nlohmann::json& v = held["per_view"][i];
    EXPECT_EQ(v["view"], 2 * i);
    EXPECT_GT(v["psnr_linear"].get<double>(), 15.0);
    EXPECT_GT(v["ssim_linear"].get<double>(), 0.5);
    EXPECT_GE(v["psnr_linear_gain_fit"].get<double>(), v["psnr_linear"].get<double>());
    psnr_sum += v["psnr_linear"].get<double>();
  }
  EXPECT_NEAR(held["psnr_linear"].get<double>(), psnr_sum / 2, 1e-9);
  EXPECT_GE(held["psnr_linear_gain_fit"].get<double>(), held["psnr_linear"].get<double>());
  EXPECT_TRUE(held["ssim_linear"].is_number());
  EXPECT_NEAR(report["full"]["psnr_linear"].get<double>(), held["psnr_linear"].get<double>(), 1e-9);
  // --held-out with --views: one line.
  EXPECT_EQ(RunSft("eval --dataset " + tmp.Join("ds") + " --reconstruction " + run +
                       " --held-out --views 1",
                   &out),
            1);
  EXPECT_EQ(CountLines(out), 1) << out;
}

// --print-schedule names the views each stage fits and the held-out ones.
TEST(ReconstructHoldoutTest, PrintScheduleShowsTheFittedViews) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 4 --zooms 1 --res 8 --spp 2"), "");
  std::string out;
  const std::string base = "reconstruct --dataset " + tmp.Join("ds") + " --print-schedule";
  ASSERT_EQ(RunSft(base + " --holdout 2", &out), 0) << out;  // the hull list: a carved start.
  const int stages = CountLines(out) - 2;                    // the header, the held-out line.
  ASSERT_GE(stages, 4) << out;
  EXPECT_EQ(testing::CountOccurrences(out, "  2 of 4: 1,3\n"), stages) << out;
  EXPECT_THAT(out, HasSubstr("held out (--holdout 2): 2 of 4: 0,2\n"));
  // A stage's own views lose the held-out ones; without --holdout, every stage fits all views.
  testing::WriteTestFile(tmp.Join("cfg.json"),
                         R"({"stages": [{"name": "a"}, {"name": "b", "views": [0, 1, 3]}]})");
  ASSERT_EQ(RunSft(base + " --holdout 2 --config " + tmp.Join("cfg.json"), &out), 0) << out;
  EXPECT_EQ(testing::CountOccurrences(out, "  2 of 4: 1,3\n"), 2)
      << out;  // b's {0, 1, 3} loses view 0.
  ASSERT_EQ(RunSft(base + " --config " + tmp.Join("cfg.json"), &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("  all 4\n"));
  EXPECT_THAT(out, HasSubstr("  3 of 4: 0,1,3\n"));
  EXPECT_THAT(out, Not(HasSubstr("held out")));
}

// A carved start (no --init) never reads a held-out view's mask: with view 0's mask empty (which
// carving refuses) and view 3's cut through by a hole, --holdout 3 starts from the same hull as on
// the intact dataset.
TEST(ReconstructHoldoutTest, CarvedStartIgnoresHeldOutMasks) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 6 --zooms 1 --res 24 --spp 4"), "");
  fs::copy(tmp.Join("ds"), tmp.Join("bad"), fs::copy_options::recursive);
  ASSERT_EQ(testing::CorruptMask(tmp.Join("bad"), 0, /*hole=*/false), "");
  ASSERT_EQ(testing::CorruptMask(tmp.Join("bad"), 3, /*hole=*/true), "");
  testing::WriteTestFile(tmp.Join("cfg.json"), R"({"stages": [{"name": "m", "phases": "texture",
      "outer_iterations": 1, "steps": 1, "spp": 1, "bounces": 1}]})");
  const std::string flags = " --quiet --no-report --config " + tmp.Join("cfg.json");
  std::string out;
  ASSERT_EQ(RunSft("reconstruct --dataset " + tmp.Join("ds") + " --out " + tmp.Join("r_ds") +
                       " --holdout 3" + flags,
                   &out),
            0)
      << out;
  ASSERT_EQ(RunSft("reconstruct --dataset " + tmp.Join("bad") + " --out " + tmp.Join("r_bad") +
                       " --holdout 3" + flags,
                   &out),
            0)
      << out;
  EXPECT_EQ(ReadJson(tmp.Join("r_bad/state.json"))["run"]["start"], "carved hull");
  EXPECT_EQ(ReadJson(tmp.Join("r_bad/state.json"))["held_out_views"], nlohmann::json({0, 3}));
  const std::string start = testing::ReadTestFile(tmp.Join("r_ds/initial_mesh.ply"));
  EXPECT_GT(start.size(), 1000u);
  EXPECT_TRUE(start == testing::ReadTestFile(tmp.Join("r_bad/initial_mesh.ply")))
      << "the held-out masks changed the carved start";
  // Not held out, the empty mask is refused (the corruption is real).
  EXPECT_EQ(
      RunSft("reconstruct --dataset " + tmp.Join("bad") + " --out " + tmp.Join("r_all") + flags,
             &out),
      1);
  EXPECT_THAT(out, HasSubstr("views[0]"));
}

TEST(ReconstructHoldoutTest, BadHoldoutIsOneLineAndWritesNothing) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 2 --zooms 1 --res 8 --spp 2"), "");
  const std::string base = "reconstruct --quiet --no-report --dataset " + tmp.Join("ds") +
                           " --init " + tmp.Join("ds/gt/mesh.ply") + " --out " + tmp.Join("o");
  std::string out;
  for (const std::string& flags :
       {std::string("--holdout 1"), std::string("--holdout -2"), std::string("--holdout x"),
        std::string("--views 1 --holdout 2")}) {
    EXPECT_NE(RunSft(base + " " + flags, &out), 0) << flags;  // 2: CLI11's parse error.
    EXPECT_THAT(out, HasSubstr("--holdout")) << flags;
    EXPECT_EQ(CountLines(out), 1) << flags << ": " << out;
    EXPECT_FALSE(fs::exists(tmp.Join("o"))) << flags;
  }
  // A stage whose views are all held out; the config key has the flag's checks.
  testing::WriteTestFile(
      tmp.Join("stages.json"),
      R"({"holdout": 2, "stages": [{"name": "a"}, {"name": "b", "views": [0]}]})");
  EXPECT_EQ(RunSft(base + " --config " + tmp.Join("stages.json"), &out), 1);
  EXPECT_THAT(out, HasSubstr("stage b"));
  EXPECT_EQ(CountLines(out), 1) << out;
  testing::WriteTestFile(tmp.Join("one.json"), R"({"holdout": 1})");
  EXPECT_EQ(RunSft(base + " --config " + tmp.Join("one.json"), &out), 1);
  EXPECT_THAT(out, HasSubstr("holdout"));
  EXPECT_EQ(CountLines(out), 1) << out;
  EXPECT_FALSE(fs::exists(tmp.Join("o")));

  // --held-out on a run that held out nothing.
  ASSERT_EQ(RunSft(base + " --outer 1 --steps 1 --phases texture --spp 2", &out), 0) << out;
  EXPECT_EQ(RunSft("eval --dataset " + tmp.Join("ds") + " --reconstruction " + tmp.Join("o") +
                       " --held-out --spp 2",
                   &out),
            1);
  EXPECT_THAT(out, HasSubstr("held out no views"));
  EXPECT_EQ(CountLines(out), 1) << out;
}

}  // namespace
}  // namespace sft
