#include "tests/testing/shadow_scenes.h"

#include <Eigen/Geometry>

#include "src/render/camera_rig.h"
#include "tests/testing/views.h"

namespace sft {
namespace testing {

CubeOverGround::CubeOverGround(int res)
    : view(LookAtView(Eigen::Vector3d(0.5, -2.0, 2.0), Eigen::Vector3d(0, 0.3, 0.2), res,
                      OrbitFocal(res, 40.0))) {
  Triangles ground;
  ground.positions = {{-6, -6, 0}, {6, -6, 0}, {6, 6, 0}, {-6, 6, 0}};
  ground.faces = {{0, 1, 2}, {0, 2, 3}};
  geometry.Append(ground);
  Triangles cube = ReadTestMesh("cube_2x2x2_12f.obj");
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.35, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (Eigen::Vector3d& p : cube.positions) p = 0.25 * (turn * p) + Eigen::Vector3d(0, 0, 0.5);
  geometry.Append(cube);
  scene = std::make_unique<RenderScene>(geometry.positions, geometry.faces);
}

Material CubeOverGround::GlossyMaterial() const {
  return ConstantMaterial(static_cast<int>(geometry.faces.size()), Eigen::Vector3d(0.7, 0.6, 0.5),
                          0.4, 0.3);
}

RenderOptions CubeOverGround::Options(int spp, int bounces, bool shadows,
                                      const Material* sampling) {
  RenderOptions options;
  options.spp = spp;
  options.bounces = bounces;
  options.effects.shadows = shadows;
  options.effects.environment = false;
  options.seed = 5;
  options.sampling_material = sampling;
  return options;
}

}  // namespace testing
}  // namespace sft
