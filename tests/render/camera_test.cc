#include "src/render/camera.h"

#include <gtest/gtest.h>

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
