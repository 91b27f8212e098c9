// Derivatives of rendered images with respect to an environment's rotation (ParameterKind::
// kEnvironmentRotation; issue 22): a rotation vector θ turning the map as world_from_env ←
// exp([θ]×)·world_from_env (camera-fixed: cam_from_env ← exp([θ]×)·cam_from_env), against central
// finite differences through 1 and 2 bounces, glossy and diffuse, with and without shadows.
//
// The scene: the cube over the ground of the light tests (tests/testing/shadow_scenes.h) seen
// from lower down, so that the sky above the horizon is in view (the camera-ray escapes), lit by a
// random 32×16 probe with a bright patch (light-sampled and, with shadows, BSDF-sampled escapes
// under MIS). Some cases sit at θ0 ≠ 0 (≈ 4°), which checks the left Jacobian of SO(3)
// (ViewSetup::environment_rotation_jacobian) as well.
//
// The renders at θ0 ± h·δ sample light directions and MIS weights from the map at θ0
// (RenderOptions::sampling_environment) and paths with the material (detached sampling), so all
// three follow the same paths and the only change is the radiance looked up: the estimator is
// then smooth in θ except where a lookup crosses the row or column of a texel centre (kinks of the
// bilinear interpolation). A lookup moves by ≈ h·W/(2π sin ϑ) texels, so at h = 1e-4 rad about
// 1e-3 of the lookups straddle a kink and perturb the difference quotient by a part of the slope
// change there (large at the bright patch's edges); float32 images add ≈ 6e-8·|I|/(2h) ≈ 2e-4
// relative. These errors are per sample and average out over pixels: measured relative L2 errors
// 3.4e-3–7.7e-3 per pixel, ≤ 1.6e-3 on 8×8 blocks, ≤ 9e-4 on the image sum (docs/design-notes.md,
// "Probe rotation"). Tolerances 2e-2 per pixel, 5e-3 on blocks and the sum. Turning the environment
// moves no visibility boundary (it is at infinity), so there are no edge terms to check.
#include <gtest/gtest.h>

#include <deque>
#include <string>

#include "src/core/rng.h"
#include "src/geometry/material.h"
#include "src/render/derivatives.h"
#include "src/render/environment.h"
#include "src/render/render.h"
#include "tests/testing/light_finite_differences.h"
#include "tests/testing/shadow_scenes.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

constexpr int kRes = 48;

struct RotationCase {
  const char* name;
  bool camera_frame;
  int bounces;
  bool shadows;
  bool glossy;
  bool at_zero;  // θ0 = 0, else a turn of ≈ 4°.
};

// A 32×16 probe: random texels in [0.2, 1.2] and a bright 3×2 patch (a soft sun) above the
// horizon.
Image ProbeImage() {
  Image image(32, 16, 3, 0.f);
  Sampler sampler(21, 0, 0, 0);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<float>(0.2 + sampler.Next1D());
    }
  }
  for (int y = 4; y < 6; ++y) {
    for (int x = 12; x < 15; ++x) {
      image.at(x, y, 0) = 12.f, image.at(x, y, 1) = 10.f, image.at(x, y, 2) = 8.f;
    }
  }
  return image;
}

// The probe's views: the map turned by θ in the light's frame, kept alive for the renders.
class TurnedProbe {
 public:
  TurnedProbe(const ViewSetup& view, bool camera_frame)
      : view_(view),
        camera_frame_(camera_frame),
        world_from_cam_(view.cam_from_world.rotation.conjugate().toRotationMatrix()),
        // Camera-fixed: env → camera by a fixed turn, then camera → world by the view's pose.
        base_(ProbeImage(),
              camera_frame ? world_from_cam_ * RotationFromVector(Eigen::Vector3d(0.2, 1.1, -0.4))
                           : RotationFromVector(Eigen::Vector3d(-0.3, 0.1, 0.5)),
              0.8) {}

  // The world-frame turn of the map at parameters θ.
  Eigen::Matrix3d WorldTurn(const Eigen::Vector3d& theta) const {
    const Eigen::Matrix3d turn = RotationFromVector(theta);
    return camera_frame_ ? world_from_cam_ * turn * world_from_cam_.transpose() : turn;
  }

  ViewSetup At(const Eigen::Vector3d& theta) {
    maps_.push_back(base_.Rotated(WorldTurn(theta)));
    ViewSetup view = view_;
    view.environment = &maps_.back();
    view.environment_light_index = 0;
    view.environment_background = true;
    view.environment_rotation_jacobian =
        (camera_frame_ ? world_from_cam_ : Eigen::Matrix3d::Identity()) *
        RotationLeftJacobian(theta);
    return view;
  }

  EnvironmentMap SamplingMap(const Eigen::Vector3d& theta) const {
    return base_.Rotated(WorldTurn(theta));
  }

 private:
  ViewSetup view_;
  bool camera_frame_;
  Eigen::Matrix3d world_from_cam_;
  EnvironmentMap base_;
  std::deque<EnvironmentMap> maps_;  // deque: views keep pointing at their maps.
};

class EnvironmentRotationDerivativesTest : public ::testing::TestWithParam<RotationCase> {};

TEST_P(EnvironmentRotationDerivativesTest, MatchesCentralDifferences) {
  const RotationCase& c = GetParam();
  static const testing::CubeOverGround* fixture = new testing::CubeOverGround(kRes);
  const testing::CubeOverGround& s = *fixture;
  // Lower than the light tests' camera: the horizon crosses the upper third of the image.
  const ViewSetup view = testing::LookAtView(Eigen::Vector3d(0.6, -2.4, 0.9),
                                             Eigen::Vector3d(0, 0, 0.45), kRes, 0.9 * kRes);
  const Material material = c.glossy ? s.GlossyMaterial()
                                     : ConstantMaterial(static_cast<int>(s.geometry.faces.size()),
                                                        Eigen::Vector3d(0.7, 0.6, 0.5), 0.5, 0.0);
  RenderOptions options = s.Options(16, c.bounces, c.shadows, &material);
  options.effects.environment = true;

  const Eigen::Vector3d x0 =
      c.at_zero ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.03, -0.05, 0.04);
  TurnedProbe probe(view, c.camera_frame);
  const EnvironmentMap sampling = probe.SamplingMap(x0);
  options.sampling_environment = &sampling;
  const Eigen::Vector3d delta = Eigen::Vector3d(0.4, -0.7, 0.6).normalized();
  const testing::LightDerivativeCheck check(
      *s.scene, material, options, [&](const Eigen::Vector3d& theta) { return probe.At(theta); },
      x0, delta, 1e-4, ParameterKind::kEnvironmentRotation);
  // No edge terms: shadows = false skips the edge-term comparisons.
  check.ExpectMatches(c.name, 2e-2, 5e-3, 5e-3, /*shadows=*/false, c.bounces);
}

INSTANTIATE_TEST_SUITE_P(
    Probes, EnvironmentRotationDerivativesTest,
    ::testing::Values(RotationCase{"world_glossy_1_bounce", false, 1, true, true, true},
                      RotationCase{"world_glossy_2_bounces", false, 2, true, true, false},
                      RotationCase{"world_diffuse_2_bounces", false, 2, true, false, true},
                      RotationCase{"world_glossy_no_shadows", false, 2, false, true, false},
                      RotationCase{"camera_glossy_1_bounce", true, 1, true, true, false},
                      RotationCase{"camera_diffuse_2_bounces", true, 2, true, false, false}),
    [](const ::testing::TestParamInfo<RotationCase>& info) {
      return std::string(info.param.name);
    });

}  // namespace
}  // namespace sft
