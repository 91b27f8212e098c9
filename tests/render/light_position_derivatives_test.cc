// Derivatives of rendered images with respect to point-light positions (ParameterKind::
// kLightPosition; issue 22): a world-frame light's world position and a camera-frame light's
// (a flash's) offset in the camera frame, against central finite differences, through 1 and 2
// bounces, with and without shadows.
//
// The scene: a glossy cube (turned to a generic orientation) above a ground quad, seen obliquely,
// lit by one point light that throws the cube's shadow onto the ground in view. The finite
// differences render the light at θ ± h·δ (δ a fixed direction of the three parameters) with the
// same seeds and the same paths: directions, lobe choices and pdfs do not depend on the light.
// - Without shadows the estimator is a smooth function of the light's position (every
//   next-event term is smooth in it), so the comparison is per pixel: relative L2 error over the
//   image, tolerance 2e-3 as in derivatives_test.cc (the O(h²) truncation of the central
//   difference at h = 1e-3, about 4e-4 of the light's distance, and float32 images).
// - With shadows the shadow boundary moves with the light: a shadow ray that crosses it switches
//   discontinuously, so a pixel's difference quotient is quantised by the samples that cross,
//   while the analytic side puts the boundary term at random points along the boundary. Both are
//   unbiased for the derivative of the expected image and agree on sums over 8×8 pixel blocks
//   and over the image, compared at 5% as the vertex derivatives' shadow tests are
//   (vertex_derivatives_test.cc).
// - Two bounces with shadows: the shadow boundary is also seen through a bounce (secondary edges
//   (B)); the same comparison without that term is measured in docs/design-notes.md, "Fitted
//   point lights".
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "src/geometry/material.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/light_finite_differences.h"
#include "tests/testing/meshes.h"
#include "tests/testing/shadow_scenes.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

constexpr int kRes = 64;

struct LightCase {
  const char* name;
  bool camera_frame;
  int bounces;
  bool shadows;
  int spp;
  double step;  // h, scene units.
  // Tolerances: the per-pixel relative L2 error (smooth cases) or the 8×8 block-sum and
  // image-sum errors (shadowed cases).
  double pixel_tolerance;
  double block_tolerance;
  double sum_tolerance;
};

// The shared cube over a ground quad (tests/testing/shadow_scenes.h).
struct CubeScene : testing::CubeOverGround {
  CubeScene() : CubeOverGround(kRes) {}
};

// The light's parameters: the world position, or the flash's camera-frame offset (to the right
// of and above the camera, so that the cube's shadow shows).
Eigen::Vector3d BaseParameters(bool camera_frame) {
  return camera_frame ? Eigen::Vector3d(0.6, -0.5, 0.0) : Eigen::Vector3d(-1.0, 0.8, 2.5);
}

// `view` with the light at parameters `x`.
ViewSetup WithLight(const ViewSetup& base, bool camera_frame, const Eigen::Vector3d& x) {
  ViewSetup view = base;
  PointLight light;
  light.camera_frame = camera_frame;
  light.position = camera_frame ? view.cam_from_world.Inverse() * x : x;
  light.intensity = Eigen::Vector3d(6.0, 5.0, 4.0);
  light.light_index = 0;
  view.point_lights = {light};
  return view;
}

class LightPositionDerivativesTest : public ::testing::TestWithParam<LightCase> {};

TEST_P(LightPositionDerivativesTest, MatchesCentralDifferences) {
  const LightCase& c = GetParam();
  static const CubeScene* fixture = new CubeScene();
  const CubeScene& s = *fixture;
  const Material material = s.GlossyMaterial();
  const RenderOptions options = s.Options(c.spp, c.bounces, c.shadows, &material);

  const Eigen::Vector3d delta = Eigen::Vector3d(0.6, -0.3, 0.74).normalized();
  const testing::LightDerivativeCheck check(
      *s.scene, material, options,
      [&](const Eigen::Vector3d& x) { return WithLight(s.view, c.camera_frame, x); },
      BaseParameters(c.camera_frame), delta, c.step, ParameterKind::kLightPosition);
  check.ExpectMatches(c.name, c.pixel_tolerance, c.block_tolerance, c.sum_tolerance, c.shadows,
                      c.bounces);
}

// Smooth cases: h = 1e-3, 4 spp, per pixel. Shadowed cases: h = 0.02 (the shadow boundary moves
// by (τ − 1)·h ≈ 0.3·h on the ground), 256 spp, on block and image sums (pixel error unchecked).
INSTANTIATE_TEST_SUITE_P(
    Lights, LightPositionDerivativesTest,
    ::testing::Values(
        LightCase{"world_1_bounce", false, 1, false, 4, 1e-3, 2e-3, 2e-3, 2e-3},
        LightCase{"world_2_bounces", false, 2, false, 4, 1e-3, 2e-3, 2e-3, 2e-3},
        LightCase{"flash_1_bounce", true, 1, false, 4, 1e-3, 2e-3, 2e-3, 2e-3},
        LightCase{"flash_2_bounces", true, 2, false, 4, 1e-3, 2e-3, 2e-3, 2e-3},
        LightCase{"world_shadows_1_bounce", false, 1, true, 256, 2e-2, 1e9, 0.05, 0.05},
        LightCase{"flash_shadows_1_bounce", true, 1, true, 256, 2e-2, 1e9, 0.05, 0.05},
        LightCase{"world_shadows_2_bounces", false, 2, true, 256, 2e-2, 1e9, 0.05, 0.05},
        LightCase{"flash_shadows_2_bounces", true, 2, true, 256, 2e-2, 1e9, 0.05, 0.05}),
    [](const ::testing::TestParamInfo<LightCase>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace sft
