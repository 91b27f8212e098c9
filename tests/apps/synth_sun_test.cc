// `sft synth --sun`: a world-fixed directional light replaces the flash. Known answer: a
// Lambertian surface facing the sun has radiance albedo/π · E, so with the default E = 0.5·π and
// albedo 0.8 the sphere's top (its faces within a few degrees of +z, flat shading) is at most
// 0.4 and at least 0.4·cos 10°; the half turned away is black (one segment, no ambient light).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

TEST(SynthSunTest, DirectionalLightLightsTheSideFacingIt) {
  testing::TempDir tmp;
  const std::string mesh = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
  std::string out;
  ASSERT_EQ(testing::RunSft("synth --quiet --mesh " + mesh + " --out " + tmp.Join("ds") +
                                " --sun 0,0,-2 --cameras 8 --zooms 1 --res 48 --spp 4 --bounces 1"
                                " --material '{\"albedo\": [0.8, 0.8, 0.8], \"roughness\": 0.5,"
                                " \"specular\": 0}'",
                            &out),
            0)
      << out;
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  ASSERT_EQ(dataset.lights.size(), 1u);
  const LightSpec& sun = dataset.lights[0];
  EXPECT_EQ(sun.type, LightType::kDirectional);
  EXPECT_EQ(sun.frame, LightFrame::kWorld);
  EXPECT_NEAR((sun.direction - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(sun.irradiance.x(), 0.5 * M_PI, 1e-9);
  float brightest = 0.0f;
  double upper_mean = 0.0, lower_mean = 0.0;
  int upper = 0, lower = 0;
  for (int v = 0; v < static_cast<int>(dataset.views.size()); ++v) {
    Image image;
    ASSERT_TRUE(LoadViewImage(dataset, v, &image).ok());
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        brightest = std::max(brightest, image.at(x, y, 0));
        sum += image.at(x, y, 0);
      }
    }
    // Cameras above the equator see mostly the lit half, those below mostly the dark one.
    const double z = dataset.views[v].cam_from_world.Inverse().translation.z();
    if (z > 0.2) upper_mean += sum, ++upper;
    if (z < -0.2) lower_mean += sum, ++lower;
  }
  EXPECT_LE(brightest, 0.4f * 1.001f);
  EXPECT_GE(brightest, 0.4f * std::cos(10 * M_PI / 180));
  ASSERT_GT(upper, 0);
  ASSERT_GT(lower, 0);
  EXPECT_GT(upper_mean / upper, 3.0 * lower_mean / lower);
}

}  // namespace
}  // namespace sft
