// Probe alignment (src/capture/probe_alignment.h) on the stored COLMAP fixture (data/colmap/spot):
// synth rendered spot in front of the studio probe with world_from_env = identity, and the
// fixture's script mapped synth's world into a "COLMAP frame" rotated by a known R
// (scripts/make_colmap_fixture.py). After `sft import colmap` (which only scales and translates),
// the probe's true world_from_env is therefore R. A probe of unrelated content must fail.
#include "src/capture/probe_alignment.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "src/capture/colmap_import.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

std::string Fixture() { return testing::DataDir() + "/colmap/spot"; }
std::string StudioProbe() {
  return testing::DataDir() + "/cycles/sphere_env_studio/probes/studio.exr";
}

// The fixture's rotation: quaternion (cos 0.4, sin 0.4 · (0.48, 0.6, 0.64)).
Eigen::Matrix3d TrueWorldFromEnv() {
  const double s = std::sin(0.4);
  return Eigen::Quaterniond(std::cos(0.4), s * 0.48, s * 0.6, s * 0.64).toRotationMatrix();
}

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(Eigen::Matrix3d(a.transpose() * b)).angle() * 180.0 / M_PI;
}

// Imports the fixture with `probe` left unaligned (identity) and reads it back.
void ImportUnaligned(const std::string& probe, const std::string& out, Dataset* dataset) {
  ColmapImportOptions opts;
  opts.model = Fixture() + "/sparse_bin";
  opts.images = Fixture() + "/images";
  opts.masks = Fixture() + "/masks";
  opts.probe = probe;
  opts.out = out;
  opts.align_probe = false;
  opts.quiet = true;
  ColmapImportReport report;
  ASSERT_TRUE(ImportColmap(opts, &report).ok());
  ASSERT_TRUE(ReadDataset(out, dataset).ok());
  ASSERT_EQ(dataset->lights.size(), 1u);
  EXPECT_TRUE(dataset->lights[0].world_from_env.isIdentity());
}

TEST(ProbeAlignmentTest, RecoversTheFixturesRotation) {
  testing::TempDir tmp;
  Dataset dataset;
  ImportUnaligned(StudioProbe(), tmp.Join("ds"), &dataset);
  ProbeAlignmentOptions opts;
  opts.quiet = true;
  opts.max_views = 8;  // a third of the views keeps the test fast; the CLI tests use 24.
  ProbeAlignmentResult result;
  const Status status = AlignProbe(dataset, 0, opts, &result);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_LT(AngleDeg(result.world_from_env, TrueWorldFromEnv()), 2.0);
  EXPECT_GE(result.inliers, 30);
  std::printf(
      "probe alignment: error %.3f deg, %d inliers of %d matches, median residual %.3f deg\n",
      AngleDeg(result.world_from_env, TrueWorldFromEnv()), result.inliers, result.matches,
      result.median_residual_deg);
  EXPECT_LT(result.median_residual_deg, 0.5);
  EXPECT_NEAR(result.rotation_angle_deg, 0.8 * 180.0 / M_PI, 2.0);
  EXPECT_THAT(AlignedProbeLighting(result), HasSubstr("probe aligned"));
}

TEST(ProbeAlignmentTest, UnrelatedProbeIsAnErrorNotARotation) {
  testing::TempDir tmp;
  // A probe with plenty of features, none of them the studio's: blurred random blobs.
  Image noise(512, 256, 3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int y = 0; y < 256; y += 8) {
    for (int x = 0; x < 512; x += 8) {
      const float v = u(rng);
      for (int dy = 0; dy < 8; ++dy) {
        for (int dx = 0; dx < 8; ++dx) {
          for (int c = 0; c < 3; ++c) noise.at(x + dx, y + dy, c) = v * (0.5f + 0.5f * c);
        }
      }
    }
  }
  ASSERT_TRUE(WriteExr(tmp.Join("noise.exr"), noise).ok());
  Dataset dataset;
  ImportUnaligned(tmp.Join("noise.exr"), tmp.Join("ds"), &dataset);
  ProbeAlignmentOptions opts;
  opts.quiet = true;
  ProbeAlignmentResult result;
  const Status status = AlignProbe(dataset, 0, opts, &result);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("the probe does not match the frames' background"));
  EXPECT_LT(result.inliers, opts.min_inliers);
}

TEST(ProbeAlignmentTest, BadOptionsAndLightsAreErrors) {
  Dataset dataset;
  ProbeAlignmentResult result;
  ProbeAlignmentOptions opts;
  opts.ratio = 1.5;
  EXPECT_THAT(AlignProbe(dataset, 0, opts, &result).message(), HasSubstr("ratio"));
  opts = ProbeAlignmentOptions();
  EXPECT_THAT(AlignProbe(dataset, 0, opts, &result).message(),
              HasSubstr("is not an environment light"));
}

}  // namespace
}  // namespace sft
