// Automatic masks (src/capture/auto_masks.h) through `sft import colmap --masks auto` on the stored
// COLMAP fixture (data/colmap/spot), against synth's true coverage masks stored beside it. The
// fixture's sparse points come from the true mesh (every 4th camera-facing vertex, with 0.3 px
// noise), so this measures GrabCut given good seeds, not COLMAP's point density.
#include "src/capture/auto_masks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "src/capture/colmap_import.h"
#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/point_cloud_ply.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

std::string Fixture() { return testing::DataDir() + "/colmap/spot"; }

// A little below the measured IoU (docs/import.md "Automatic masks").
constexpr double kMeanThreshold = 0.9;
constexpr double kMinThreshold = 0.83;
constexpr double kConsistentMeanThreshold = 0.9;

// The fixture names masks as COLMAP does: IMAGE_NAME.png (000.jpg.png, ..., 023.png.png).
Image TrueMask(const Dataset& dataset, int view) {
  const std::string stem = std::filesystem::path(dataset.views[view].image).stem().string();
  Image truth;
  EXPECT_TRUE(
      ReadMask(Fixture() + "/masks/" + stem + (stem == "023" ? ".png" : ".jpg") + ".png", &truth)
          .ok());
  return truth;
}

// The fixture imported without masks, and its sparse points.
void ImportFixture(const testing::TempDir& tmp, Dataset* dataset, PointCloud* sparse) {
  ColmapImportOptions opts;
  opts.model = Fixture() + "/sparse_bin";
  opts.images = Fixture() + "/images";
  opts.out = tmp.Join("ds");
  opts.quiet = true;
  ColmapImportReport report;
  ASSERT_TRUE(ImportColmap(opts, &report).ok());
  ASSERT_TRUE(ReadDataset(opts.out, dataset).ok());
  ASSERT_TRUE(ReadPointCloudPly(JoinPath(opts.out, dataset->sparse_points), sparse).ok());
}

// Fast: three views segmented through the library.
TEST(AutoMasksTest, ThreeViewsMatchTheTrueMasks) {
  testing::TempDir tmp;
  Dataset dataset;
  PointCloud sparse;
  ImportFixture(tmp, &dataset, &sparse);
  if (HasFatalFailure()) return;
  for (int view : {0, 8, 16}) {
    Image mask;
    const Status status =
        AutoMask(dataset, view, sparse.positions, AutoMaskOptions(), nullptr, &mask);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_GT(MaskIoU(mask, TrueMask(dataset, view)), kMinThreshold) << view;
  }
}

// Background consistency (src/capture/background_consistency.h) on the same views: the spot stands
// in front of the probe, which the distant hypothesis explains, so the masks come closer to the
// truth than GrabCut's from the seeds alone.
TEST(AutoMasksTest, BackgroundConsistencyBringsTheMasksCloser) {
  testing::TempDir tmp;
  Dataset dataset;
  PointCloud sparse;
  ImportFixture(tmp, &dataset, &sparse);
  if (HasFatalFailure()) return;
  BackgroundConsistencyOptions consistency;
  consistency.quiet = true;
  std::vector<Image> distances;
  ASSERT_TRUE(BackgroundDistances(dataset, nullptr, consistency, &distances).ok());
  double with_sum = 0, without_sum = 0;
  for (int view : {0, 8, 16}) {
    Image with, without;
    ASSERT_TRUE(
        AutoMask(dataset, view, sparse.positions, AutoMaskOptions(), &distances[view], &with).ok());
    ASSERT_TRUE(
        AutoMask(dataset, view, sparse.positions, AutoMaskOptions(), nullptr, &without).ok());
    const double iou_with = MaskIoU(with, TrueMask(dataset, view));
    const double iou_without = MaskIoU(without, TrueMask(dataset, view));
    std::printf("view %d: IoU %.4f with background consistency, %.4f without\n", view, iou_with,
                iou_without);
    with_sum += iou_with;
    without_sum += iou_without;
  }
  EXPECT_GT(with_sum / 3, kConsistentMeanThreshold);
  EXPECT_GT(with_sum, without_sum);
}

// All 24 views through `sft import colmap --masks auto` (~10 s of GrabCut): the figures of
// docs/import.md.
TEST(AutoMasksLongTest, ImportWithAutoMasksMatchesTheTrueMasks) {
  testing::TempDir tmp;
  const std::string out = tmp.Join("ds");
  std::string output;
  ASSERT_EQ(testing::RunSft("import colmap --quiet --masks auto --model " + Fixture() +
                                "/sparse_bin --images " + Fixture() + "/images --out " + out,
                            &output),
            0)
      << output;
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(out, &dataset).ok());
  ASSERT_TRUE(CheckDatasetFiles(dataset).ok());
  double sum = 0, worst = 1;
  for (size_t i = 0; i < dataset.views.size(); ++i) {
    ASSERT_FALSE(dataset.views[i].mask.empty());
    Image automatic;
    ASSERT_TRUE(LoadViewMask(dataset, static_cast<int>(i), &automatic).ok());
    const double iou = MaskIoU(automatic, TrueMask(dataset, static_cast<int>(i)));
    sum += iou;
    worst = std::min(worst, iou);
  }
  const double mean = sum / dataset.views.size();
  std::printf("auto masks: IoU mean %.4f, min %.4f over %zu views\n", mean, worst,
              dataset.views.size());
  EXPECT_GT(mean, kMeanThreshold);
  EXPECT_GT(worst, kMinThreshold);
}

TEST(AutoMasksTest, TooFewSeedsIsAnError) {
  testing::TempDir tmp;
  ColmapImportOptions opts;
  opts.model = Fixture() + "/sparse_txt";
  opts.images = Fixture() + "/images";
  opts.masks = "auto";
  opts.out = tmp.Join("ds");
  opts.quiet = true;
  opts.auto_masks.min_seeds = 100000;
  ColmapImportReport report;
  const Status status = ImportColmap(opts, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("automatic mask: only"));
  EXPECT_FALSE(std::filesystem::exists(opts.out));
  EXPECT_FALSE(std::filesystem::exists(opts.out + ".partial"));
}

TEST(AutoMasksTest, IoU) {
  Image a(4, 1, 1), b(4, 1, 1);
  a.data = {1, 1, 0, 0};
  b.data = {0, 1, 1, 0};
  EXPECT_DOUBLE_EQ(MaskIoU(a, b), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(MaskIoU(Image(2, 2, 1), Image(2, 2, 1)), 1.0);
}

}  // namespace
}  // namespace sft
