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

}  // namespace testing
}  // namespace sft
