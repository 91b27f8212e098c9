#include "src/render/render.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

using testing::QuadFaces;
using testing::QuadPositions;
using testing::TopDownView;

// Lambert plane under a point light: radiance ρ·I·cos θ/(π·d²) at every point (docs/dataset.md).
// The pixel value is the box-filter average of that smooth function, computed here by a 16×16
// midpoint rule over the pixel (quadrature error < 1e-5 relative). The render's only noise is the
// pixel jitter: the function varies ≲ 2% across a pixel, so 64 samples leave ≲ 0.1% (2%/√(12·64)).
// Tolerance 0.2%.
TEST(RenderTest, LambertPlaneUnderPointLight) {
  const RenderScene scene(QuadPositions(1.0), QuadFaces());
  const Eigen::Vector3d albedo(0.8, 0.5, 0.2);
  const Material material = ConstantMaterial(2, albedo, 0.5, 0.0);
  const int res = 64;
  const double focal = 40.0, height = 2.0;
  ViewSetup view = TopDownView(height, res, focal);
  const Eigen::Vector3d light(0.3, -0.2, 0.9), intensity(2.0, 3.0, 4.0);
  view.point_lights.push_back({light, intensity});
  RenderOptions options;
  options.spp = 64;
  options.bounces = 1;
  Image image;
  RenderView(scene, material, view, options, &image);
  int checked = 0;
  for (int y = 0; y < res; y += 3) {
    for (int x = 0; x < res; x += 3) {
      // Pixel → world points on z = 0 (the camera looks straight down).
      const double cu = (x + 0.5 - 0.5 * res) / focal, cv = (y + 0.5 - 0.5 * res) / focal;
      if (std::abs(cu * height) > 0.9 || std::abs(cv * height) > 0.9) continue;
      double irradiance_factor = 0.0;  // mean of cos θ / d² over the pixel.
      const int q = 16;
      for (int a = 0; a < q; ++a) {
        for (int b = 0; b < q; ++b) {
          const double u = (x + (a + 0.5) / q - 0.5 * res) / focal;
          const double v = (y + (b + 0.5) / q - 0.5 * res) / focal;
          const Eigen::Vector3d to_light = light - Eigen::Vector3d(u * height, -v * height, 0.0);
          const double d2 = to_light.squaredNorm();
          irradiance_factor += to_light.z() / std::sqrt(d2) / d2;
        }
      }
      irradiance_factor /= q * q;
      for (int c = 0; c < 3; ++c) {
        const double expected = albedo[c] * intensity[c] * irradiance_factor / M_PI;
        EXPECT_NEAR(image.at(x, y, c), expected, 2e-3 * expected) << x << "," << y;
      }
      EXPECT_FLOAT_EQ(image.at(x, y, 3), 1.0f);
      ++checked;
    }
  }
  EXPECT_GT(checked, 120);
}

// Furnace test: a convex object under a constant environment of radiance L, Lambertian albedo ρ,
// reflects exactly ρ·L in every direction (irradiance π·L), with or without bounces (a convex
// object never sees itself). The mean over fully covered pixels is compared at 1%; the noise of
// the mean over ~1000 pixels × 64 samples is ~0.1%.
TEST(RenderTest, FurnaceConvexObject) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &mesh).ok());
  const RenderScene scene(mesh);
  const double rho = 0.6, radiance = 1.5;
  const Material material =
      ConstantMaterial(mesh.n_faces(), Eigen::Vector3d::Constant(rho), 0.5, 0.0);
  const EnvironmentMap env(Image(32, 16, 3, 1.0f), Eigen::Matrix3d::Identity(), radiance);
  ViewSetup view = TopDownView(4.0, 48, 40.0);
  view.environment = &env;
  for (int bounces : {1, 3}) {
    RenderOptions options;
    options.spp = 64;
    options.bounces = bounces;
    Image image;
    RenderView(scene, material, view, options, &image);
    double sum = 0.0;
    int count = 0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        if (image.at(x, y, 3) < 1.0f) continue;
        sum += image.at(x, y, 1);
        ++count;
      }
    }
    ASSERT_GT(count, 200);  // the sphere covers ~330 pixels fully.
    EXPECT_NEAR(sum / count, rho * radiance, 0.01 * rho * radiance) << "bounces " << bounces;
  }
}

// The same seed gives the same image bit for bit, for 1 and 2 threads.
TEST(RenderTest, DeterministicAcrossThreadCounts) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/bunny_watertight_5k.obj", &mesh).ok());
  const RenderScene scene(mesh);
  const Material material =
      ConstantMaterial(mesh.n_faces(), Eigen::Vector3d(0.6, 0.5, 0.4), 0.3, 0.4);
  ViewSetup view = TopDownView(4.0, 32, 30.0);
  view.point_lights.push_back({Eigen::Vector3d(0.5, 0.5, 3.0), Eigen::Vector3d::Constant(10.0)});
  RenderOptions options;
  options.spp = 8;
  options.bounces = 3;
  options.seed = 42;
  Image one, two, other_seed;
  options.threads = 1;
  RenderView(scene, material, view, options, &one);
  options.threads = 2;
  RenderView(scene, material, view, options, &two);
  EXPECT_EQ(one.data, two.data);
  options.seed = 43;
  RenderView(scene, material, view, options, &other_seed);
  EXPECT_NE(one.data, other_seed.data);
}

// Shadows: a small quad between a light and a ground plane darkens the plane beneath it only
// when the shadows effect is on.
TEST(RenderTest, ShadowsEffect) {
  std::vector<Eigen::Vector3d> positions = QuadPositions(1.0);
  for (const Eigen::Vector3d& p : QuadPositions(0.2))
    positions.push_back(p + Eigen::Vector3d(0, 0, 0.5));
  std::vector<Eigen::Vector3i> faces = QuadFaces();
  faces.push_back({4, 5, 6});
  faces.push_back({4, 6, 7});
  const RenderScene scene(positions, faces);
  const Material material = ConstantMaterial(4, Eigen::Vector3d::Constant(0.5), 0.5, 0.0);
  ViewSetup view = TopDownView(3.0, 32, 30.0);
  view.camera.params = {30.0, 30.0, 16.0, 16.0};
  // Look at the plane from the side so the occluder does not hide the shadowed spot.
  view.cam_from_world.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI * 0.8, Eigen::Vector3d::UnitX()));
  view.cam_from_world.translation = -(view.cam_from_world.rotation * Eigen::Vector3d(0, -1.5, 2.5));
  view.point_lights.push_back({Eigen::Vector3d(0, 0, 2.0), Eigen::Vector3d::Constant(5.0)});
  RenderOptions options;
  options.spp = 4;
  options.bounces = 1;
  Image with, without;
  RenderView(scene, material, view, options, &with);
  options.effects.shadows = false;
  RenderView(scene, material, view, options, &without);
  // The origin of the plane projects somewhere in the image; find it.
  const Eigen::Vector2d px =
      view.camera.ImageFromCam(view.cam_from_world * Eigen::Vector3d(0, 0, 0));
  const int x = static_cast<int>(px.x()), y = static_cast<int>(px.y());
  ASSERT_TRUE(x >= 0 && x < 32 && y >= 0 && y < 32);
  EXPECT_LT(with.at(x, y, 0), 1e-6);
  EXPECT_GT(without.at(x, y, 0), 0.05);
}

// Hard cases produce finite images: degenerate, sliver and flipped triangles, coincident
// vertices, a light on the surface, roughness 0.001 and 0, grazing views, huge and tiny scales,
// the camera inside the object.
TEST(RenderTest, HardCasesStayFinite) {
  for (double scale : {1e-4, 1.0, 1e4}) {
    std::vector<Eigen::Vector3d> positions = QuadPositions(scale);
    positions.push_back(Eigen::Vector3d(0, 0, 0.1) * scale);            // 4
    positions.push_back(Eigen::Vector3d(0, 0, 0.1) * scale);            // 5 coincident with 4
    positions.push_back(Eigen::Vector3d(0.5, 0, 0.1) * scale);          // 6
    positions.push_back(Eigen::Vector3d(0.5 + 1e-12, 0, 0.1) * scale);  // 7 sliver
    std::vector<Eigen::Vector3i> faces = QuadFaces();
    faces.push_back({4, 5, 6});  // zero area (coincident vertices)
    faces.push_back({4, 6, 7});  // collinear sliver
    faces.push_back({0, 2, 1});  // flipped duplicate of the first face
    const RenderScene scene(positions, faces);
    for (double roughness : {0.0, 0.001, 0.5}) {
      const Material material = ConstantMaterial(5, Eigen::Vector3d::Constant(0.9), roughness, 1.0);
      for (double height : {2.0, 1e-3, -0.5}) {  // -0.5: camera below, grazing through the plane
        ViewSetup view = TopDownView(height * scale, 16, 12.0);
        view.point_lights.push_back(
            {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d::Constant(1.0)});
        view.point_lights.push_back(
            {Eigen::Vector3d(0.1, 0.1, 1e-9) * scale, Eigen::Vector3d::Constant(1.0)});
        const EnvironmentMap env(Image(8, 4, 3, 1.0f), Eigen::Matrix3d::Identity(), 1.0);
        view.environment = &env;
        view.point_lights[0].light_index = 0;
        view.point_lights[1].light_index = 1;
        view.environment_light_index = 2;
        RenderOptions options;
        options.spp = 4;
        options.bounces = 3;
        Image image;
        DerivativeRequest request;
        request.jacobian_rows = true;
        DerivativeOutput derivatives;
        RenderViewWithDerivatives(scene, material, view, options, request, 3, &image, &derivatives);
        for (float v : image.data) ASSERT_TRUE(std::isfinite(v)) << "scale " << scale;
        for (const JacobianEntry& e : derivatives.rows.entries) {
          for (float d : e.d) ASSERT_TRUE(std::isfinite(d)) << "scale " << scale;
        }
      }
    }
  }
}

// A camera inside a closed mesh sees its inside (two-sided shading) lit by a light inside too.
TEST(RenderTest, CameraInsideClosedObject) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &mesh).ok());
  const RenderScene scene(mesh);
  const Material material =
      ConstantMaterial(mesh.n_faces(), Eigen::Vector3d::Constant(0.5), 0.3, 0.5);
  ViewSetup view = TopDownView(0.2, 16, 10.0);
  view.point_lights.push_back({Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d::Constant(1.0)});
  RenderOptions options;
  options.spp = 4;
  options.bounces = 3;
  Image image;
  RenderView(scene, material, view, options, &image);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      EXPECT_FLOAT_EQ(image.at(x, y, 3), 1.0f);  // every ray hits the inside.
      EXPECT_GT(image.at(x, y, 0), 0.0f);
      EXPECT_TRUE(std::isfinite(image.at(x, y, 0)));
    }
  }
}

TEST(RenderTest, OptionsCheckAndEffectsParse) {
  RenderOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.bounces = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("bounces"), std::string::npos);
  options.bounces = 2;
  options.spp = 0;
  EXPECT_FALSE(options.Check(&why));
  Effects effects;
  EXPECT_TRUE(Effects::Parse("direct,shadows", &effects, &why));
  EXPECT_TRUE(effects.direct && effects.shadows && !effects.bounces && !effects.environment);
  EXPECT_FALSE(Effects::Parse("direct,glitter", &effects, &why));
  EXPECT_NE(why.find("glitter"), std::string::npos);
}

// RenderOptions::on_tile_done is called once per 8×8 tile (partial tiles at the borders count),
// from any thread, and does not change the image.
TEST(RenderTest, TileCallbackCountsTilesWithoutChangingTheImage) {
  const RenderScene scene(QuadPositions(1.0), QuadFaces());
  const Material material = ConstantMaterial(2, Eigen::Vector3d(0.5, 0.5, 0.5), 0.5, 0.0);
  ViewSetup view = TopDownView(2.0, 20, 12.0);
  view.camera.height = 12;
  view.camera.params = {12.0, 12.0, 10.0, 6.0};
  view.point_lights.push_back({Eigen::Vector3d(0.2, 0.1, 1.0), Eigen::Vector3d(1, 1, 1)});
  RenderOptions options;
  options.spp = 4;
  options.threads = 2;
  Image plain, counted;
  RenderView(scene, material, view, options, &plain);
  std::atomic<int> tiles{0};
  options.on_tile_done = [&tiles] { ++tiles; };
  RenderView(scene, material, view, options, &counted);
  EXPECT_EQ(RenderTileCount(20, 12), 6);
  EXPECT_EQ(tiles.load(), 6);
  EXPECT_EQ(plain.data, counted.data);
}

}  // namespace
}  // namespace sft
