// report.html's 3D view in a real browser: a tiny reconstruction's report opened in headless
// Chromium (software WebGL) through scripts/check_report_viewer.sh, which reads what the page's
// script reports: both views loaded and drew pixels that differ from the background. Skips with
// one line when Chromium is absent (scripts/setup.sh --with-chromium installs it) or three.js is
// not installed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

TEST(ReportViewerTest, ChromiumDrawsBothViews) {
  if (testing::RunCommand("command -v chromium > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "chromium not installed (bash scripts/setup.sh --with-chromium)";
  }
  if (!std::filesystem::exists("/usr/share/javascript/three/three.min.js")) {
    GTEST_SKIP() << "three.js not installed (apt-get install libjs-three)";
  }
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"),
                                    "--cameras 4 --zooms 1 --res 24 --spp 8 --bounces 1 "
                                    "--material '{\"procedural\": \"wood\", \"scale\": 3}'"),
            "");
  std::string out;
  ASSERT_EQ(testing::RunSft("perturb --mesh " + tmp.Join("ds/gt/mesh.ply") + " --out " +
                                tmp.Join("init.ply") + " --amplitude 0.02 --seed 2",
                            &out),
            0)
      << out;
  ASSERT_EQ(testing::RunSft("reconstruct --quiet --dataset " + tmp.Join("ds") + " --init " +
                                tmp.Join("init.ply") +
                                " --spp 4 --bounces 1 --steps 1 --outer 1 --phases alternate"
                                " --out " +
                                tmp.Join("r"),
                            &out),
            0)
      << out;
  const std::string script = testing::DataDir() + "/../scripts/check_report_viewer.sh";
  // The object covers about a fifth of each 480×400 canvas; 500 drawn pixels excludes a blank or
  // failed view.
  const int code = testing::RunCommand(
      "bash " + script + " " + tmp.Join("r/report.html") + " " + tmp.Join("shot.png") + " 500",
      &out);
  std::printf("%s", out.c_str());
  EXPECT_EQ(code, 0) << out;
  EXPECT_THAT(out, HasSubstr("loaded; pixels drawn: result"));
  EXPECT_THAT(out, HasSubstr(", start"));
}

}  // namespace
}  // namespace sft
