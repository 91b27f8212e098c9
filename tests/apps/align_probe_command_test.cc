// `sft align-probe` end to end: a dataset imported with --no-align-probe gets its probe rotation
// back in a copy (the input is untouched); a dataset without an environment light and an output
// inside the input fail with one line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;
using testing::RunSft;

std::string Fixture() { return testing::DataDir() + "/colmap/spot"; }

TEST(AlignProbeCommandTest, AlignsACopyOfAnUnalignedImport) {
  testing::TempDir tmp;
  std::string output;
  ASSERT_EQ(RunSft("import colmap --quiet --no-align-probe --model " + Fixture() +
                       "/sparse_txt --images " + Fixture() + "/images --masks " + Fixture() +
                       "/masks --probe " + testing::DataDir() +
                       "/cycles/sphere_env_studio/probes/studio.exr --out " + tmp.Join("ds"),
                   &output),
            0)
      << output;
  ASSERT_EQ(
      RunSft("align-probe --dataset " + tmp.Join("ds") + " --out " + tmp.Join("aligned"), &output),
      0)
      << output;
  EXPECT_THAT(output, HasSubstr("median residual"));
  Dataset before, after;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &before).ok());
  ASSERT_TRUE(ReadDataset(tmp.Join("aligned"), &after).ok());
  ASSERT_TRUE(CheckDatasetFiles(after).ok());
  EXPECT_TRUE(before.lights[0].world_from_env.isIdentity());
  EXPECT_THAT(before.lighting, HasSubstr("not yet aligned"));
  EXPECT_THAT(after.lighting, HasSubstr("probe aligned"));
  const double s = std::sin(0.4);
  const Eigen::Matrix3d truth =
      Eigen::Quaterniond(std::cos(0.4), s * 0.48, s * 0.6, s * 0.64).toRotationMatrix();
  const Eigen::Matrix3d error = truth.transpose() * after.lights[0].world_from_env;
  EXPECT_LT(Eigen::AngleAxisd(error).angle() * 180.0 / M_PI, 2.0);
}

TEST(AlignProbeCommandTest, ErrorsAreOneLine) {
  testing::TempDir tmp;
  std::string output;
  ASSERT_EQ(RunSft("import colmap --quiet --model " + Fixture() + "/sparse_txt --images " +
                       Fixture() + "/images --out " + tmp.Join("ds"),
                   &output),
            0)
      << output;
  EXPECT_EQ(RunSft("align-probe --dataset " + tmp.Join("ds") + " --out " + tmp.Join("o"), &output),
            1);
  EXPECT_THAT(output, HasSubstr("no environment light"));
  EXPECT_EQ(testing::CountLines(output), 1);
  EXPECT_EQ(
      RunSft("align-probe --dataset " + tmp.Join("ds") + " --out " + tmp.Join("ds/x"), &output), 1);
  EXPECT_EQ(testing::CountLines(output), 1);
  EXPECT_EQ(
      RunSft("align-probe --dataset " + tmp.Join("missing") + " --out " + tmp.Join("o"), &output),
      1);
  EXPECT_EQ(testing::CountLines(output), 1);
}

}  // namespace
}  // namespace sft
