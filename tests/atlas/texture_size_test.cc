// The texture size from the dataset's pixel footprint and from a mesh-colors material's density
// (src/atlas/texture_size.h).
#include "src/atlas/texture_size.h"

#include <gtest/gtest.h>

#include "tests/testing/dataset_scenes.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

TEST(TextureSizeTest, FromFootprint) {
  testing::TempDir tmp;
  testing::WriteJson(tmp.path(), testing::MinimalScene());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.path(), &dataset).ok());
  // View 0's camera centre is (0, 0, −2), f = 20 px: 0.1 units per pixel at the origin (view 1's
  // is 2.06 away: coarser). Side = sqrt(area / 0.1² / 0.5), rounded up to a power of two.
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  EXPECT_EQ(TextureSizeFromFootprint(dataset, origin, 1e3), 512);   // side 447.
  EXPECT_EQ(TextureSizeFromFootprint(dataset, origin, 1e4), 2048);  // side 1414.
  EXPECT_EQ(TextureSizeFromFootprint(dataset, origin, 1.0), 256);   // clamped up.
  EXPECT_EQ(TextureSizeFromFootprint(dataset, origin, 1e7), 4096);  // clamped down.
  dataset.views.clear();
  EXPECT_EQ(TextureSizeFromFootprint(dataset, origin, 1e4), 1024);  // no views: the default.
}

TEST(TextureSizeTest, ForMeshColors) {
  // Side = sqrt(4 · faces · (r+1)(r+2)/2 / 0.35), rounded up to a power of two.
  EXPECT_EQ(TextureSizeForMeshColors(5856, 2), 1024);     // spot_textured_point: side 634.
  EXPECT_EQ(TextureSizeForMeshColors(5000, 1), 512);      // side 414.
  EXPECT_EQ(TextureSizeForMeshColors(50000, 1), 2048);    // side 1309.
  EXPECT_EQ(TextureSizeForMeshColors(20, 1), 256);        // clamped up.
  EXPECT_EQ(TextureSizeForMeshColors(2000000, 4), 4096);  // clamped down.
  EXPECT_EQ(TextureSizeForMeshColors(0, 1), 256);
}

}  // namespace
}  // namespace sft
