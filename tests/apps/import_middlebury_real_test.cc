// `sft import middlebury` on the real dino ring (../shared/data/real/middlebury_dino_ring48: 48
// photographs, 640×480, K[R|t] per view, black background; read from the shared folder, never
// copied into the repository). Skipped when the shared data is absent.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

TEST(ImportMiddleburyRealTest, DinoRingBoxMatchesThePublishedBoundingBox) {
  const std::string shared = testing::SharedDataDir();
  if (shared.empty()) GTEST_SKIP() << "no ../shared/data";
  const std::string set = shared + "/real/middlebury_dino_ring48";
  testing::TempDir tmp;
  std::string output;
  // The README's recipe dilates by 10 and erodes by 7 after a threshold of 0.19; 0.1 keeps the
  // dino's shadowed spikes (0.19 cuts up to 7 mm of them in this ring's views; docs/import.md).
  ASSERT_EQ(testing::RunSft("import middlebury --par " + set +
                                "/dino_par.txt --masks threshold "
                                "--threshold 0.1 --out " +
                                tmp.Join("d"),
                            &output),
            0)
      << output;
  // dino_par.txt lists the full 363-view hemisphere; the ring holds the first 48 images.
  EXPECT_THAT(output, HasSubstr("warning: 315 of 363 entries have no image file"));
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("d"), &dataset).ok());
  ASSERT_EQ(dataset.views.size(), 48u);
  EXPECT_EQ(dataset.cameras.size(), 1u);
  // The set's README: the tight bounding box is (-0.041897 0.001126 -0.037845) to (0.030897
  // 0.088227 0.035495). The masks' hull (48 views, carved at 64 voxels, ~2 mm) must match it
  // within 3 mm on every face.
  const nlohmann::json& box = dataset.extra["import"]["normalization"]["object_box_in_source"];
  const double lo[3] = {-0.041897, 0.001126, -0.037845}, hi[3] = {0.030897, 0.088227, 0.035495};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(box[0][a].get<double>(), lo[a], 0.003) << "axis " << a;
    EXPECT_NEAR(box[1][a].get<double>(), hi[a], 0.003) << "axis " << a;
  }
}

}  // namespace
}  // namespace sft
