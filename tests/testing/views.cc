#include "tests/testing/views.h"

#include "src/render/camera_rig.h"

namespace sft {
namespace testing {

ViewSetup LookAtView(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, int res,
                     double focal, const Eigen::Vector3d& up) {
  ViewSetup view;
  view.camera.model = CameraModel::kPinhole;
  view.camera.width = view.camera.height = res;
  view.camera.params = {focal, focal, 0.5 * res, 0.5 * res};
  view.cam_from_world = LookAt(eye, target, up);
  return view;
}

void AddPointLight(const Eigen::Vector3d& position, double intensity, ViewSetup* view) {
  PointLight light;
  light.position = position;
  light.intensity = Eigen::Vector3d::Constant(intensity);
  view->point_lights.push_back(light);
}

ViewSetup TopDownView(double height, int res, double focal) {
  ViewSetup view;
  view.camera.model = CameraModel::kPinhole;
  view.camera.width = view.camera.height = res;
  view.camera.params = {focal, focal, 0.5 * res, 0.5 * res};
  // A rotation of π about x: x_cam = +x, y_cam = −y, z_cam = −z.
  view.cam_from_world.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  view.cam_from_world.translation = -(view.cam_from_world.rotation * Eigen::Vector3d(0, 0, height));
  return view;
}

std::vector<Eigen::Vector3d> QuadPositions(double half) {
  return {{-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
}

std::vector<Eigen::Vector3i> QuadFaces() { return {{0, 1, 2}, {0, 2, 3}}; }

}  // namespace testing
}  // namespace sft
