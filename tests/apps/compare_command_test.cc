// sft compare end to end: two tiny sft reconstruct runs (different solvers, with --reference) and
// one without --reference become comparison.csv and report.html, each naming every run, with
// finite numbers; bad --runs are one error line and write nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using testing::CountLines;
using ::testing::HasSubstr;
using testing::RunSft;

// The fields of one CSV line (no quoting: sft compare writes none).
std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream ss(line);
  std::string field;
  while (std::getline(ss, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

// True when `text` is a whole finite number.
bool IsFiniteNumber(const std::string& text) {
  if (text.empty()) return false;
  size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (...) {
    return false;
  }
  return used == text.size() && std::isfinite(value);
}

class CompareCommandTest : public ::testing::Test {
 protected:
  // One dataset, a perturbed start and three 1-outer-iteration geometry runs: lm and adam with
  // --reference, lm without it.
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    ASSERT_EQ(testing::SynthIcosphere(dir_->Join("ds"),
                                      "--cameras 2 --zooms 1 --res 16 --spp 8 --bounces 1"),
              "");
    std::string out;
    ASSERT_EQ(RunSft("perturb --mesh " + dir_->Join("ds/gt/mesh.ply") + " --out " +
                         dir_->Join("init.ply") + " --amplitude 0.02 --seed 4",
                     &out),
              0)
        << out;
    const std::string common = "reconstruct --quiet --no-report --dataset " + dir_->Join("ds") +
                               " --init " + dir_->Join("init.ply") +
                               " --phases geometry --outer 2 --steps 1 --spp 4 --bounces 1";
    const std::string reference = " --reference " + dir_->Join("ds/gt/mesh.ply");
    for (const char* solver : {"lm", "adam"}) {
      ASSERT_EQ(RunSft(common + " --solver " + solver + reference + " --out " +
                           dir_->Join(std::string("run_") + solver),
                       &out),
                0)
          << out;
    }
    ASSERT_EQ(RunSft(common + " --out " + dir_->Join("run_plain"), &out), 0) << out;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  static testing::TempDir* dir_;
};

testing::TempDir* CompareCommandTest::dir_ = nullptr;

// Every run appears in the CSV (its accepted iterations and each outer iteration) and in the
// report's table; every number in the CSV is finite; the runs with --reference have a Chamfer
// distance and an F1 in every outer row, the run without has those fields empty.
TEST_F(CompareCommandTest, CsvAndReportNameEveryRunWithFiniteNumbers) {
  const std::string runs =
      dir_->Join("run_lm") + "," + dir_->Join("run_adam") + "," + dir_->Join("run_plain");
  const std::string out_dir = dir_->Join("cmp");
  std::string out;
  ASSERT_EQ(RunSft("compare --runs " + runs + " --labels lm,adam,plain --out " + out_dir, &out), 0)
      << out;
  ASSERT_TRUE(fs::exists(out_dir + "/comparison.csv"));
  ASSERT_TRUE(fs::exists(out_dir + "/report.html"));

  std::stringstream csv(testing::ReadTestFile(out_dir + "/comparison.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::vector<std::string> header = SplitCsv(line);
  ASSERT_EQ(header,
            (std::vector<std::string>{"run", "kind", "outer", "seconds", "cost", "chamfer", "f1"}));
  std::map<std::string, int> iteration_rows, outer_rows;
  while (std::getline(csv, line)) {
    SCOPED_TRACE(line);
    const std::vector<std::string> f = SplitCsv(line);
    ASSERT_EQ(f.size(), header.size());
    const std::string& run = f[0];
    ASSERT_TRUE(run == "lm" || run == "adam" || run == "plain");
    for (int i : {2, 3, 4}) EXPECT_TRUE(IsFiniteNumber(f[i])) << header[i];
    EXPECT_GE(std::stod(f[4]), 0.0) << "cost";
    if (f[1] == "iteration") {
      ++iteration_rows[run];
      EXPECT_EQ(f[5], "");
      EXPECT_EQ(f[6], "");
    } else {
      ASSERT_EQ(f[1], "outer");
      ++outer_rows[run];
      if (run == "plain") {
        // No --reference: no Chamfer or F1 to report.
        EXPECT_EQ(f[5], "");
        EXPECT_EQ(f[6], "");
      } else {
        ASSERT_TRUE(IsFiniteNumber(f[5]) && IsFiniteNumber(f[6]));
        EXPECT_GT(std::stod(f[5]), 0.0);
        EXPECT_LT(std::stod(f[5]), 0.05);
        EXPECT_GE(std::stod(f[6]), 0.0);
        EXPECT_LE(std::stod(f[6]), 1.0);
      }
    }
  }
  for (const char* run : {"lm", "adam", "plain"}) {
    EXPECT_GE(iteration_rows[run], 1) << run;
    EXPECT_EQ(outer_rows[run], 2) << run;
  }

  const std::string html = testing::ReadTestFile(out_dir + "/report.html");
  EXPECT_THAT(html, HasSubstr("sft compare: 3 runs"));
  for (const char* run : {"<td>lm</td>", "<td>adam</td>", "<td>plain</td>"}) {
    EXPECT_THAT(html, HasSubstr(run));
  }
  EXPECT_EQ(html.find("nan"), std::string::npos);
  EXPECT_EQ(html.find("inf<"), std::string::npos);
  // Three charts: cost, Chamfer and F1 against wall time.
  EXPECT_EQ(testing::CountOccurrences(html, "<svg"), 3);
}

// Bad inputs: a folder without metrics.json, a metrics.json of something else, labels that do not
// match the runs. Each is exit 1 with one line naming the fault, and no --out folder.
TEST_F(CompareCommandTest, BadRunsAreOneLineAndWriteNothing) {
  fs::create_directories(dir_->Join("empty_run"));
  fs::create_directories(dir_->Join("other_run"));
  testing::WriteTestFile(dir_->Join("other_run/metrics.json"), "{\"psnr\": 30}");
  const std::string good = dir_->Join("run_lm");
  const std::string out_dir = dir_->Join("bad_cmp");
  struct BadCase {
    std::string args;
    std::string mentions;
  };
  const std::vector<BadCase> cases = {
      {"--runs " + good + "," + dir_->Join("empty_run"), dir_->Join("empty_run/metrics.json")},
      {"--runs " + dir_->Join("other_run"), dir_->Join("other_run/metrics.json")},
      {"--runs " + good + "," + good + " --labels only_one", "--labels"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.args);
    std::string out;
    EXPECT_EQ(RunSft("compare " + c.args + " --out " + out_dir, &out), 1);
    EXPECT_THAT(out, HasSubstr(c.mentions));
    EXPECT_EQ(CountLines(out), 1) << out;
    EXPECT_FALSE(fs::exists(out_dir));
  }
}

}  // namespace
}  // namespace sft
