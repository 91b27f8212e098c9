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
#include <random>
#include <string>
#include <vector>

#include "src/geometry/material.h"
#include "src/render/camera_rig.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/finite_differences.h"
#include "tests/testing/meshes.h"
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

// The cube (half-size 0.25, centred at (0, 0, 0.5)) above a 12 × 12 ground, the camera at
// (0.5, −2, 2) looking at (0, 0.3, 0.2).
struct CubeScene {
  testing::Triangles geometry;
  ViewSetup view = testing::LookAtView(Eigen::Vector3d(0.5, -2.0, 2.0),
                                       Eigen::Vector3d(0, 0.3, 0.2), kRes, OrbitFocal(kRes, 40.0));
  std::unique_ptr<RenderScene> scene;

  CubeScene() {
    testing::Triangles ground;
    ground.positions = {{-6, -6, 0}, {6, -6, 0}, {6, 6, 0}, {-6, 6, 0}};
    ground.faces = {{0, 1, 2}, {0, 2, 3}};
    geometry.Append(ground);
    testing::Triangles cube = testing::ReadTestMesh("cube_2x2x2_12f.obj");
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(0.35, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    for (Eigen::Vector3d& p : cube.positions) p = 0.25 * (turn * p) + Eigen::Vector3d(0, 0, 0.5);
    geometry.Append(cube);
    scene = std::make_unique<RenderScene>(geometry.positions, geometry.faces);
  }
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

// The directional derivative image Σ_θ J_θ·δ_θ (RGB per pixel) from the rows.
std::vector<double> RowsTimes(const DerivativeOutput& out, const std::vector<double>& delta) {
  std::vector<double> image(3 * static_cast<size_t>(out.rows.width) * out.rows.height, 0.0);
  for (size_t p = 0; p + 1 < out.rows.offsets.size(); ++p) {
    for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
      const JacobianEntry& entry = out.rows.entries[e];
      for (int k = 0; k < 3; ++k) image[3 * p + k] += entry.d[k] * delta[entry.param];
    }
  }
  return image;
}

class LightPositionDerivativesTest : public ::testing::TestWithParam<LightCase> {};

TEST_P(LightPositionDerivativesTest, MatchesCentralDifferences) {
  const LightCase& c = GetParam();
  static const CubeScene* fixture = new CubeScene();
  const CubeScene& s = *fixture;
  Material material = ConstantMaterial(static_cast<int>(s.geometry.faces.size()),
                                       Eigen::Vector3d(0.7, 0.6, 0.5), 0.4, 0.3);
  RenderOptions options;
  options.spp = c.spp;
  options.bounces = c.bounces;
  options.effects.shadows = c.shadows;
  options.effects.environment = false;
  options.seed = 5;
  options.sampling_material = &material;

  const Eigen::Vector3d x0 = BaseParameters(c.camera_frame);
  const Eigen::Vector3d delta = Eigen::Vector3d(0.6, -0.3, 0.74).normalized();
  Image plus, minus;
  RenderView(*s.scene, material, WithLight(s.view, c.camera_frame, x0 + c.step * delta), options,
             &plus);
  RenderView(*s.scene, material, WithLight(s.view, c.camera_frame, x0 - c.step * delta), options,
             &minus);

  ParameterLayout layout = MakeParameterLayout(*s.scene, material, 1);
  layout.light_positions = true;
  std::vector<double> direction(layout.size(), 0.0);
  for (int k = 0; k < 3; ++k) direction[layout.LightPositionOffset() + k] = delta[k];
  Image weights(kRes, kRes, 3);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (float& w : weights.data) w = static_cast<float>(u(rng));
  DerivativeRequest request;
  request.params = ParameterSelection::Only(ParameterKind::kLightPosition);
  request.jacobian_rows = true;
  request.adjoint_weights = &weights;
  Image image, reference;
  DerivativeOutput out;
  const ViewSetup view = WithLight(s.view, c.camera_frame, x0);
  RenderViewWithDerivatives(*s.scene, material, view, options, request, layout, &image, &out);
  RenderView(*s.scene, material, view, options, &reference);
  EXPECT_EQ(image.data, reference.data) << "derivative pass changed the image";
  for (const JacobianEntry& entry : out.rows.entries) {
    ASSERT_EQ(layout.KindOf(entry.param), ParameterKind::kLightPosition);
  }

  const std::vector<double> analytic = RowsTimes(out, direction);
  std::vector<double> fd(analytic.size());
  for (size_t p = 0; p < fd.size() / 3; ++p) {
    for (int k = 0; k < 3; ++k) {
      fd[3 * p + k] =
          (static_cast<double>(plus.data[4 * p + k]) - minus.data[4 * p + k]) / (2.0 * c.step);
    }
  }
  double adjoint = 0.0, weighted = 0.0, weighted_abs = 0.0;
  for (int i = 0; i < layout.size(); ++i) adjoint += out.gradient[i] * direction[i];
  for (size_t i = 0; i < analytic.size(); ++i) {
    weighted += weights.data[i] * analytic[i];
    weighted_abs += std::abs(weights.data[i] * analytic[i]);
  }
  const double pixel_error = testing::RelativeError(analytic, fd);
  const double block_error = testing::RelativeError(testing::BlockSums(analytic, kRes, 8),
                                                    testing::BlockSums(fd, kRes, 8));
  const double fd_sum = testing::Sum(fd);
  const double sum_error = std::abs(testing::Sum(analytic) - fd_sum) / std::abs(fd_sum);
  std::printf("%s: pixel error %.2e, block error %.4f, sum error %.4f (fd sum %.5g)\n", c.name,
              pixel_error, block_error, sum_error, fd_sum);
  ASSERT_GT(std::abs(fd_sum), 0.0) << "the perturbation does not change the image";
  EXPECT_LT(pixel_error, c.pixel_tolerance) << c.name;
  EXPECT_LT(block_error, c.block_tolerance) << c.name;
  EXPECT_LT(sum_error, c.sum_tolerance) << c.name;
  EXPECT_NEAR(adjoint, weighted, 1e-5 * weighted_abs + 1e-12) << c.name;

  if (!c.shadows) return;
  // What the boundary terms add: the same comparison without the shadow edges seen directly and
  // without those seen through a bounce (secondary edges (B)). Without either the comparison must
  // be worse, so that the tolerance above tests the terms (measured: docs/design-notes.md, "Fitted
  // point lights").
  for (const bool direct : {false, true}) {
    if (direct && c.bounces == 1) continue;
    DerivativeRequest without = request;
    (direct ? without.secondary_edge_samples : without.shadow_edge_ratio) = 0.0;
    DerivativeOutput out_without;
    RenderViewWithDerivatives(*s.scene, material, view, options, without, layout, &image,
                              &out_without);
    const std::vector<double> partial = RowsTimes(out_without, direction);
    const double block_without = testing::RelativeError(testing::BlockSums(partial, kRes, 8),
                                                        testing::BlockSums(fd, kRes, 8));
    const double sum_without = std::abs(testing::Sum(partial) - fd_sum) / std::abs(fd_sum);
    std::printf("%s without %s: block error %.4f, sum error %.4f\n", c.name,
                direct ? "secondary edges" : "shadow edges", block_without, sum_without);
    if (!direct) EXPECT_GT(block_without, 2.0 * block_error) << c.name;
  }
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
