// `sft synth --ground --path orbit`: the plane is in the images but not in the masks or gt/, the
// views follow the orbit in order, and a camera below the plane is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

TEST(SynthGroundTest, PlaneInImagesNotInMasksOrTruth) {
  testing::TempDir tmp;
  const std::string mesh = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
  std::string out;
  ASSERT_EQ(testing::RunSft("synth --quiet --mesh " + mesh + " --out " + tmp.Join("ds") +
                                " --ground --ground-cells 16 --path orbit --elevation 20,40 "
                                "--cameras 4 --zooms 1 --res 32 --fill 0.4 --spp 4 --bounces 1",
                            &out),
            0)
      << out;
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  ASSERT_EQ(dataset.views.size(), 4u);
  TriMesh gt;
  ASSERT_TRUE(ReadMesh(tmp.Join("ds/gt/mesh.ply"), &gt).ok());
  EXPECT_EQ(gt.n_faces(), 320u);
  // The support_plane is the ground's: +z, 0.001 diagonals under the object's lowest point.
  double lo = 1e9;
  for (auto vh : gt.vertices()) lo = std::min<double>(lo, gt.point(vh)[2]);
  ASSERT_TRUE(dataset.has_support_plane);
  EXPECT_EQ(dataset.support_normal, Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(dataset.support_point.z(), lo - 1e-3, 1e-6);
  // Orbit order: camera k at azimuth 2πk/4 (quarter turns), elevation within [20°, 40°].
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d c = dataset.views[k].cam_from_world.Inverse().translation;
    const double azimuth = std::atan2(c.y(), c.x());
    EXPECT_NEAR(std::remainder(azimuth - M_PI / 2 * k, 2 * M_PI), 0.0, 1e-6) << k;
    const double elevation = std::asin(c.z() / c.norm()) * 180 / M_PI;
    EXPECT_GE(elevation, 20 - 1e-6);
    EXPECT_LE(elevation, 40 + 1e-6);
  }
  // The bottom row sees the lit plane (not black) but is outside the object's mask.
  Image image, mask;
  ASSERT_TRUE(LoadViewImage(dataset, 0, &image).ok());
  ASSERT_TRUE(LoadViewMask(dataset, 0, &mask).ok());
  const int y = image.height - 1, x = image.width / 2;
  EXPECT_GT(image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2), 0.0f);
  EXPECT_EQ(mask.at(x, y), 0.0f);
  EXPECT_EQ(mask.at(image.width / 2, image.height / 2), 1.0f);
}

TEST(SynthGroundTest, CameraBelowThePlaneIsAnError) {
  testing::TempDir tmp;
  const std::string mesh = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
  std::string out;
  EXPECT_NE(testing::RunSft("synth --quiet --mesh " + mesh + " --out " + tmp.Join("ds") +
                                " --ground --cameras 8 --zooms 1 --res 8 --spp 1",
                            &out),
            0);
  EXPECT_NE(out.find("--ground: camera"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp.Join("ds")));
}

}  // namespace
}  // namespace sft
