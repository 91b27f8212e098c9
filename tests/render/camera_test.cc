#include "src/render/camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "src/geometry/material.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {
namespace {

Camera MakeCamera(CameraModel model) {
  Camera camera;
  camera.model = model;
  camera.width = 640;
  camera.height = 480;
  switch (model) {
    case CameraModel::kSimplePinhole:
      camera.params = {500, 320, 240};
      break;
    case CameraModel::kPinhole:
      camera.params = {500, 520, 321, 239};
      break;
    case CameraModel::kSimpleRadial:
      camera.params = {500, 320, 240, -0.1};
      break;
    case CameraModel::kRadial:
      camera.params = {500, 320, 240, -0.1, 0.02};
      break;
    case CameraModel::kOpenCV:
      camera.params = {500, 510, 320, 240, -0.1, 0.02, 0.001, -0.002};
      break;
  }
  return camera;
}

TEST(CameraTest, ProjectUnprojectRoundTripAllModels) {
  for (CameraModel model :
       {CameraModel::kSimplePinhole, CameraModel::kPinhole, CameraModel::kSimpleRadial,
        CameraModel::kRadial, CameraModel::kOpenCV}) {
    const Camera camera = MakeCamera(model);
    std::string why;
    ASSERT_TRUE(camera.Check(&why)) << why;
    for (double x : {0.5, 100.0, 320.0, 639.5}) {
      for (double y : {0.5, 240.0, 479.5}) {
        const Eigen::Vector3d ray = camera.CamFromImage(Eigen::Vector2d(x, y));
        const Eigen::Vector2d back = camera.ImageFromCam(2.5 * ray);
        EXPECT_NEAR(back.x(), x, 1e-6) << CameraModelName(model);
        EXPECT_NEAR(back.y(), y, 1e-6) << CameraModelName(model);
      }
    }
  }
}

// A RADIAL camera with k1 = −0.5 (k2 = 0): r·(1 − 0.5 r²) increases up to r = sqrt(2/3) = 0.816
// and reaches its maximum 0.544 there; image points farther from the centre than 0.544 focal
// lengths have no ray. 64×64 pixels, f = 32: the fold is 17.4 px from the centre (the corners
// are 45 px away).
Camera FoldedCamera(CameraModel model) {
  Camera camera;
  camera.model = model;
  camera.width = camera.height = 64;
  camera.params = model == CameraModel::kOpenCV
                      ? std::vector<double>{32, 32, 32, 32, -0.5, 0, 1e-3, -1e-3}
                      : std::vector<double>{32, 32, 32, -0.5, 0};
  return camera;
}

TEST(CameraTest, PixelsPastTheFoldHaveNoRay) {
  for (CameraModel model : {CameraModel::kRadial, CameraModel::kOpenCV}) {
    SCOPED_TRACE(CameraModelName(model));
    const Camera camera = FoldedCamera(model);
    EXPECT_NEAR(camera.MaxUndistortedRadius(), std::sqrt(2.0 / 3.0), 1e-15);
    Eigen::Vector3d ray;
    // Inside the fold, up to just before it: a ray on the increasing branch that projects back.
    for (double rd : {0.0, 0.2, 0.5, 0.54}) {
      const Eigen::Vector2d pixel(32 + 32 * rd * 0.6, 32 + 32 * rd * 0.8);
      ASSERT_TRUE(camera.RayFromImage(pixel, &ray)) << rd;
      EXPECT_LE(ray.head<2>().norm(), camera.MaxUndistortedRadius()) << rd;
      const Eigen::Vector2d back = camera.ImageFromCam(ray);
      EXPECT_NEAR((back - pixel).norm(), 0.0, 1e-9) << rd;
      EXPECT_EQ(camera.CamFromImage(pixel), ray);
    }
    // Past it: no ray, and CamFromImage says so with a zero direction.
    for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(32 + 0.56 * 32, 32),
                                         Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d(63.5, 20)}) {
      EXPECT_FALSE(camera.RayFromImage(pixel, &ray)) << pixel.transpose();
      EXPECT_EQ(camera.CamFromImage(pixel), Eigen::Vector3d::Zero()) << pixel.transpose();
    }
  }
  // Distortions that increase everywhere keep a ray for every pixel.
  Camera pincushion = FoldedCamera(CameraModel::kRadial);
  pincushion.params[3] = 0.5;
  EXPECT_TRUE(std::isinf(pincushion.MaxUndistortedRadius()));
  Eigen::Vector3d ray;
  EXPECT_TRUE(pincushion.RayFromImage(Eigen::Vector2d(0.5, 0.5), &ray));
  EXPECT_NEAR((pincushion.ImageFromCam(ray) - Eigen::Vector2d(0.5, 0.5)).norm(), 0.0, 1e-9);
}

// Rendered, those pixels are empty (alpha 0, black) even though a wall fills the whole view;
// pixels well inside the fold see the wall (alpha 1).
TEST(CameraTest, PixelsPastTheFoldRenderEmpty) {
  // A 40 × 40 quad at z = 0 seen from z = −1 (normalized coordinates up to ±20 land on it).
  const std::vector<Eigen::Vector3d> positions = {
      {-20, -20, 0}, {20, -20, 0}, {20, 20, 0}, {-20, 20, 0}};
  const std::vector<Eigen::Vector3i> faces = {{0, 1, 2}, {0, 2, 3}};
  const RenderScene scene(positions, faces);
  const Material material = ConstantMaterial(2, Eigen::Vector3d::Constant(0.5), 0.5, 0.0);
  for (CameraModel model : {CameraModel::kRadial, CameraModel::kOpenCV}) {
    SCOPED_TRACE(CameraModelName(model));
    ViewSetup view;
    view.camera = FoldedCamera(model);
    view.cam_from_world.translation = Eigen::Vector3d(0, 0, 1);  // Camera centre at z = −1.
    view.point_lights.push_back({Eigen::Vector3d(0, 0, -1), Eigen::Vector3d::Constant(1.0), -1});
    RenderOptions options;
    options.spp = 4;
    options.bounces = 1;
    Image image;
    RenderView(scene, material, view, options, &image);
    int empty = 0, full = 0;
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        const double radius = std::hypot(x + 0.5 - 32, y + 0.5 - 32) / 32;  // Normalized.
        for (int c = 0; c < 4; ++c) ASSERT_TRUE(std::isfinite(image.at(x, y, c)));
        if (radius > 0.544 * 1.05 + 1.5 / 32) {  // Past the fold by more than a pixel.
          EXPECT_EQ(image.at(x, y, 3), 0.0f) << x << " " << y;
          EXPECT_EQ(image.at(x, y, 0), 0.0f) << x << " " << y;
          ++empty;
        } else if (radius < 0.5) {
          EXPECT_EQ(image.at(x, y, 3), 1.0f) << x << " " << y;
          ++full;
        }
      }
    }
    EXPECT_GT(empty, 2000);
    EXPECT_GT(full, 700);
  }
}

// COLMAP conventions: +z forward, +x right, +y down, principal point at the image centre means
// the optical axis hits pixel coordinate (cx, cy).
TEST(CameraTest, Conventions) {
  const Camera camera = MakeCamera(CameraModel::kPinhole);
  const Eigen::Vector2d centre = camera.ImageFromCam(Eigen::Vector3d(0, 0, 1));
  EXPECT_DOUBLE_EQ(centre.x(), 321);
  EXPECT_DOUBLE_EQ(centre.y(), 239);
  const Eigen::Vector2d right_down = camera.ImageFromCam(Eigen::Vector3d(0.1, 0.1, 1));
  EXPECT_GT(right_down.x(), centre.x());
  EXPECT_GT(right_down.y(), centre.y());
}

TEST(CameraTest, ModelNamesAndCheck) {
  CameraModel model;
  EXPECT_TRUE(CameraModelFromName("OPENCV", &model));
  EXPECT_EQ(model, CameraModel::kOpenCV);
  EXPECT_FALSE(CameraModelFromName("FISHEYE_42", &model));
  Camera camera = MakeCamera(CameraModel::kPinhole);
  camera.params.pop_back();
  std::string why;
  EXPECT_FALSE(camera.Check(&why));
  EXPECT_NE(why.find("params"), std::string::npos);
  camera = MakeCamera(CameraModel::kPinhole);
  camera.width = 0;
  EXPECT_FALSE(camera.Check(&why));
}

}  // namespace
}  // namespace sft
