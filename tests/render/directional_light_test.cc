// Directional lights against known answers (pbrt-v4 style): a Lambertian plane lit at angle θ has
// radiance ρ/π·E·cos θ, a light from behind gives nothing, a square occluder casts a shadow of its
// own size shifted by h·tan θ, and the light is the limit of a far point light (glossy too).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "src/geometry/material.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

using testing::QuadFaces;
using testing::QuadPositions;
using testing::TopDownView;

// A light travelling down and towards +x, at θ from the vertical: direction (sin θ, 0, −cos θ),
// wi = (−sin θ, 0, cos θ) at the plane z = 0.
DirectionalLight Sun(double theta, const Eigen::Vector3d& irradiance) {
  DirectionalLight light;
  light.direction = Eigen::Vector3d(std::sin(theta), 0.0, -std::cos(theta));
  light.irradiance = irradiance;
  return light;
}

Image Render(const RenderScene& scene, const Material& material, const ViewSetup& view, int spp) {
  RenderOptions options;
  options.spp = spp;
  options.bounces = 1;
  Image image;
  RenderView(scene, material, view, options, &image);
  return image;
}

// Every sample of a uniformly lit plane has the same value, so the pixels are exact up to float
// rounding (tolerance 1e-6 relative).
TEST(DirectionalLightTest, LambertianPlaneIsAlbedoOverPiTimesIrradianceTimesCosine) {
  const RenderScene scene(QuadPositions(1.0), QuadFaces());
  const Eigen::Vector3d albedo(0.8, 0.5, 0.2);
  const Eigen::Vector3d irradiance(3.0, 2.0, 1.0);
  const Material material = ConstantMaterial(2, albedo, 0.5, 0.0);
  const int res = 16;
  for (double degrees : {0.0, 30.0, 60.0, 85.0}) {
    const double theta = degrees * M_PI / 180.0;
    ViewSetup view = TopDownView(2.0, res, 20.0);  // sees the middle 80% of the quad.
    view.directional_lights.push_back(Sun(theta, irradiance));
    const Image image = Render(scene, material, view, 4);
    for (int p = 0; p < res * res; ++p) {
      for (int c = 0; c < 3; ++c) {
        const double expected = albedo[c] / M_PI * irradiance[c] * std::cos(theta);
        EXPECT_NEAR(image.data[4 * p + c], expected, 1e-6 * expected)
            << degrees << "° pixel " << p << " channel " << c;
      }
    }
  }
}

TEST(DirectionalLightTest, LightFromBehindTheSurfaceGivesNothing) {
  const RenderScene scene(QuadPositions(1.0), QuadFaces());
  const Material material = ConstantMaterial(2, Eigen::Vector3d(0.8, 0.8, 0.8), 0.3, 0.5);
  ViewSetup view = TopDownView(2.0, 16, 20.0);
  // Travelling up (+z) and grazing-up: the camera side of the plane faces away from the light.
  view.directional_lights.push_back(Sun(M_PI, Eigen::Vector3d::Constant(5.0)));
  view.directional_lights.push_back(Sun(0.6 * M_PI, Eigen::Vector3d::Constant(5.0)));
  const Image image = Render(scene, material, view, 4);
  for (int p = 0; p < 16 * 16; ++p) {
    EXPECT_EQ(image.data[4 * p + 0], 0.0f) << p;
    EXPECT_EQ(image.data[4 * p + 3], 1.0f) << p;  // the plane is seen.
  }
}

// A 0.4 × 0.4 square at height h = 0.5 above a ground plane, the light at tan θ = 1.2: parallel
// rays cast a shadow of the square's own size, 0.16, centred at (h·tan θ, 0) = (0.6, 0) (a point
// light's would be larger). Measured as Σ (1 − value/lit) × pixel area over the ground right of
// x = 0.3 (the square itself is seen left of x = 0.27): 64 spp leave an area noise of ~0.3%, the
// tolerance is 2% (area) and 0.01 (centre).
TEST(DirectionalLightTest, OccluderCastsAShadowOfItsOwnSizeShiftedByHeightTimesTangent) {
  std::vector<Eigen::Vector3d> positions = QuadPositions(2.0);
  std::vector<Eigen::Vector3i> faces = QuadFaces();
  for (const Eigen::Vector3d& p : QuadPositions(0.2))
    positions.push_back(p + 0.5 * Eigen::Vector3d::UnitZ());
  for (const Eigen::Vector3i& f : QuadFaces()) faces.push_back(f + Eigen::Vector3i::Constant(4));
  const RenderScene scene(positions, faces);
  const double albedo = 0.6, irradiance = 2.0;
  const Material material = ConstantMaterial(4, Eigen::Vector3d::Constant(albedo), 0.5, 0.0);
  const int res = 128;
  const double focal = 64.0, height = 2.0;
  ViewSetup view = TopDownView(height, res, focal);  // ground x, y ∈ [−2, 2].
  const double theta = std::atan(1.2);
  view.directional_lights.push_back(Sun(theta, Eigen::Vector3d::Constant(irradiance)));
  const Image image = Render(scene, material, view, 64);
  const double lit = albedo / M_PI * irradiance * std::cos(theta);
  const double pixel = height / focal;  // a pixel's side on the ground.
  double area = 0.0, sum_x = 0.0, sum_y = 0.0;
  for (int j = 0; j < res; ++j) {
    for (int i = 0; i < res; ++i) {
      const double x = pixel * (i + 0.5 - 0.5 * res), y = -pixel * (j + 0.5 - 0.5 * res);
      const double value = image.at(i, j, 0);
      if (x < -1.0) {  // far from both.
        EXPECT_NEAR(value, lit, 1e-6 * lit) << i << ", " << j;
      }
      if (x < 0.3) continue;
      const double shadow = (1.0 - value / lit) * pixel * pixel;
      area += shadow;
      sum_x += shadow * x;
      sum_y += shadow * y;
    }
  }
  std::printf("shadow area %.5f (0.16), centre (%.4f, %.4f) ((0.6, 0))\n", area, sum_x / area,
              sum_y / area);
  EXPECT_NEAR(area, 0.16, 0.02 * 0.16);
  EXPECT_NEAR(sum_x / area, 0.5 * 1.2, 0.01);
  EXPECT_NEAR(sum_y / area, 0.0, 0.01);
}

// A directional light is the limit of a point light of intensity E·D² at distance D against its
// travel direction: on a glossy plane of half-size 1 at D = 1e3 the two differ by O(1/D) in the
// direction and the falloff (tolerance 1% relative per pixel), with the same samples.
TEST(DirectionalLightTest, IsTheLimitOfAFarPointLight) {
  const RenderScene scene(QuadPositions(1.0), QuadFaces());
  const Material material = ConstantMaterial(2, Eigen::Vector3d(0.5, 0.4, 0.3), 0.4, 0.6);
  const DirectionalLight sun = Sun(0.5, Eigen::Vector3d(1.0, 2.0, 3.0));
  const double distance = 1e3;
  ViewSetup directional = TopDownView(2.0, 16, 20.0);
  directional.directional_lights.push_back(sun);
  ViewSetup point = TopDownView(2.0, 16, 20.0);
  point.point_lights.push_back({-distance * sun.direction, sun.irradiance * distance * distance});
  const Image a = Render(scene, material, directional, 4);
  const Image b = Render(scene, material, point, 4);
  for (int p = 0; p < 16 * 16; ++p) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_GT(b.data[4 * p + c], 0.0f);
      EXPECT_NEAR(a.data[4 * p + c], b.data[4 * p + c], 0.01 * b.data[4 * p + c]) << p;
    }
  }
}

}  // namespace
}  // namespace sft
