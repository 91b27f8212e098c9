// Derivatives of rendered images with respect to directional-light directions (ParameterKind::
// kLightDirection; issue 22): three numbers v per light, the light travelling along v/|v| in the
// world or (camera_frame) along Rᵀ·v/|v|, against central finite differences through 1 and 2
// bounces, with and without shadows.
//
// The scene: the glossy cube over a ground quad of the point-light tests
// (tests/testing/shadow_scenes.h), lit by one directional light that throws the cube's shadow
// onto the ground in view. v has length 1.7, not 1, and δ has a component along v, so the
// normalization's Jacobian (I − d dᵀ)/|v| is checked too (the component along v changes
// nothing). The differences render the light at v ± h·δ with the same seeds and paths.
// - Without shadows every next-event term is smooth in the direction: the comparison is per
//   pixel, relative L2 error over the image, tolerance 2e-3 (O(h²) truncation at h = 1e-3, about
//   6e-4 rad, and float32 images), as for the light positions.
// - With shadows the cube's shadow edge sweeps over the ground as the light turns: the
//   difference quotient is quantised by the samples the boundary crosses, so the comparison is on
//   8×8 block sums and the image sum, tolerance 5% as for the light positions and the vertex
//   shadow tests; and without the shadow-edge term the block error must at least double, so that
//   the term is really checked. With two bounces the shadow is also seen through a bounce
//   (secondary edges (B)); the error without that term is printed (docs/design-notes.md,
//   "Directional lights").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "src/geometry/material.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"
#include "tests/testing/light_finite_differences.h"
#include "tests/testing/shadow_scenes.h"

namespace sft {
namespace {

constexpr int kRes = 64;

struct DirectionCase {
  const char* name;
  bool camera_frame;
  int bounces;
  bool shadows;
  int spp;
  double step;  // h, in units of v (|v| = 1.7).
  // Tolerances: per pixel (smooth cases), on 8×8 block sums and on the image sum; < 0: not
  // checked (the pixel error of shadowed cases, quantised by the samples that cross).
  double pixel_tolerance;
  double block_tolerance;
  double sum_tolerance;
};

// The light travels down and across, from (−1, 0.8, 2) towards the cube, so that the cube's
// shadow falls on the ground in view.
const Eigen::Vector3d kWorldTravel = Eigen::Vector3d(1.0, -0.8, -2.0).normalized();
constexpr double kNorm = 1.7;

// `base` with the light at parameters v.
ViewSetup WithLight(const ViewSetup& base, bool camera_frame, const Eigen::Vector3d& v) {
  ViewSetup view = base;
  DirectionalLight light;
  light.camera_frame = camera_frame;
  const Eigen::Vector3d unit = v.normalized();
  light.direction = camera_frame ? view.cam_from_world.rotation.conjugate() * unit : unit;
  light.irradiance = Eigen::Vector3d(3.0, 2.5, 2.0);
  light.light_index = 0;
  light.parameter_norm = v.norm();
  view.directional_lights = {light};
  return view;
}

// The parameters at the test's point: kWorldTravel in the light's frame, length kNorm.
Eigen::Vector3d BaseParameters(const ViewSetup& view, bool camera_frame) {
  const Eigen::Vector3d d =
      camera_frame ? view.cam_from_world.rotation * kWorldTravel : kWorldTravel;
  return kNorm * d;
}

class LightDirectionDerivativesTest : public ::testing::TestWithParam<DirectionCase> {};

TEST_P(LightDirectionDerivativesTest, MatchesCentralDifferences) {
  const DirectionCase& c = GetParam();
  static const testing::CubeOverGround* fixture = new testing::CubeOverGround(kRes);
  const testing::CubeOverGround& s = *fixture;
  const Material material = s.GlossyMaterial();
  const RenderOptions options = s.Options(c.spp, c.bounces, c.shadows, &material);

  const Eigen::Vector3d x0 = BaseParameters(s.view, c.camera_frame);
  // δ: mostly across the direction, a fifth along it.
  const Eigen::Vector3d across = x0.unitOrthogonal();
  const Eigen::Vector3d delta =
      (across + 0.5 * x0.normalized().cross(across) + 0.2 * x0.normalized()).normalized();
  const testing::LightDerivativeCheck check(
      *s.scene, material, options,
      [&](const Eigen::Vector3d& v) { return WithLight(s.view, c.camera_frame, v); }, x0, delta,
      c.step, ParameterKind::kLightDirection);
  check.ExpectMatches(c.name, c.pixel_tolerance, c.block_tolerance, c.sum_tolerance, c.shadows,
                      c.bounces);
}

// Smooth cases: h = 1e-3, 4 spp, per pixel. Shadowed cases: h = 0.02 (the direction turns by
// h/|v| ≈ 0.012 rad and the shadow edge of the cube, 0.25–0.75 above the ground, moves by
// ≈ 0.005), 256 spp, on block and image sums (pixel error unchecked).
INSTANTIATE_TEST_SUITE_P(
    Lights, LightDirectionDerivativesTest,
    ::testing::Values(
        DirectionCase{"world_1_bounce", false, 1, false, 4, 1e-3, 2e-3, 2e-3, 2e-3},
        DirectionCase{"world_2_bounces", false, 2, false, 4, 1e-3, 2e-3, 2e-3, 2e-3},
        DirectionCase{"camera_1_bounce", true, 1, false, 4, 1e-3, 2e-3, 2e-3, 2e-3},
        DirectionCase{"camera_2_bounces", true, 2, false, 4, 1e-3, 2e-3, 2e-3, 2e-3},
        DirectionCase{"world_shadows_1_bounce", false, 1, true, 256, 2e-2, -1, 0.05, 0.05},
        DirectionCase{"camera_shadows_1_bounce", true, 1, true, 256, 2e-2, -1, 0.05, 0.05},
        DirectionCase{"world_shadows_2_bounces", false, 2, true, 256, 2e-2, -1, 0.05, 0.05},
        DirectionCase{"camera_shadows_2_bounces", true, 2, true, 256, 2e-2, -1, 0.05, 0.05}),
    [](const ::testing::TestParamInfo<DirectionCase>& info) {
      return std::string(info.param.name);
    });

}  // namespace
}  // namespace sft
