// Hard cases checked against known answers, not only for finiteness: huge and tiny scene scales,
// and roughness near zero.
#include <gtest/gtest.h>

#include <cmath>

#include "src/geometry/material.h"
#include "src/render/environment.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

using testing::TopDownView;

RenderScene Quad(double half) {
  return RenderScene(testing::QuadPositions(half), testing::QuadFaces());
}

// Per pixel and channel, Σ of the row entries of one parameter kind.
std::vector<double> KindSums(const DerivativeOutput& output, ParameterKind kind, int pixels) {
  std::vector<double> sums(3 * pixels, 0.0);
  const JacobianRows& rows = output.rows;
  for (int p = 0; p < pixels; ++p) {
    for (uint64_t e = rows.offsets[p]; e < rows.offsets[p + 1]; ++e) {
      if (output.layout.KindOf(rows.entries[e].param) != kind) continue;
      for (int c = 0; c < 3; ++c) sums[3 * p + c] += rows.entries[e].d[c];
    }
  }
  return sums;
}

// A Lambert plane under a point light, the whole scene scaled by s (lengths × s, intensity × s²):
// radiance ρ·I·cos θ/(π d²) does not change, so the image at s = 1e-4 and 1e4 equals the one at
// s = 1 (same seed, same samples; float rounding of positions only, tolerance 1e-4 relative).
// The image is linear in the albedo and in the light scale with one path segment, so their rows
// summed per pixel are exactly I/ρ and I (the light derivative is taken at the rendered
// intensity, s·∂I/∂s); tolerance 1e-5 relative, float accumulation.
TEST(HardCasesTest, HugeAndTinyScalesGiveTheSameImageAndExactLinearRows) {
  const Eigen::Vector3d albedo(0.8, 0.5, 0.2);
  const int res = 24;
  Image reference;
  for (double s : {1.0, 1e-4, 1e4}) {
    const RenderScene scene = Quad(1.0 * s);
    const Material material = ConstantMaterial(2, albedo, 0.5, 0.0);
    ViewSetup view = TopDownView(2.0 * s, res, 26.0);  // sees the middle 92% of the quad.
    view.point_lights.push_back(
        {Eigen::Vector3d(0.3, -0.2, 0.4) * s, Eigen::Vector3d(2.0, 3.0, 4.0) * (s * s)});
    view.point_lights[0].light_index = 0;
    RenderOptions options;
    options.spp = 4;
    options.bounces = 1;
    DerivativeRequest request;
    request.jacobian_rows = true;
    Image image;
    DerivativeOutput output;
    RenderViewWithDerivatives(scene, material, view, options, request, 1, &image, &output);
    if (s == 1.0) reference = image;
    const std::vector<double> d_albedo = KindSums(output, ParameterKind::kAlbedo, res * res);
    const std::vector<double> d_light = KindSums(output, ParameterKind::kLight, res * res);
    for (int p = 0; p < res * res; ++p) {
      for (int c = 0; c < 3; ++c) {
        const double value = image.data[4 * p + c];
        ASSERT_GT(value, 0.0) << "scale " << s;
        EXPECT_NEAR(value, reference.data[4 * p + c], 1e-4 * value) << "scale " << s;
        EXPECT_NEAR(d_albedo[3 * p + c], value / albedo[c], 1e-5 * value / albedo[c])
            << "scale " << s << " pixel " << p;
        EXPECT_NEAR(d_light[3 * p + c], value, 1e-5 * value) << "scale " << s << " pixel " << p;
      }
    }
  }
}

// Roughness near zero is a mirror: a black-albedo plane with specular weight 1 under a uniform
// environment L reflects L·G1(wo)·G1(wi)·∫D… → L as α = roughness² → 0 (the lobe integrates to one
// and Smith masking is 1 away from grazing; here view angles stay under 30°). Checked at roughness
// 0 (the renderer's clamp), 0.001 and 0.01, mean over the image within 1%, every pixel within 5%.
TEST(HardCasesTest, RoughnessNearZeroIsAMirrorOfAUniformEnvironment) {
  const EnvironmentMap env(Image(16, 8, 3, 1.0f), Eigen::Matrix3d::Identity(), 0.75);
  const RenderScene scene = Quad(4.0);
  const int res = 16;
  for (double roughness : {0.0, 0.001, 0.01}) {
    const Material material = ConstantMaterial(2, Eigen::Vector3d::Zero(), roughness, 1.0);
    ViewSetup view = TopDownView(2.0, res, 16.0);
    view.environment = &env;
    RenderOptions options;
    options.spp = 16;
    options.bounces = 1;
    Image image;
    RenderView(scene, material, view, options, &image);
    double mean = 0.0;
    for (int p = 0; p < res * res; ++p) {
      for (int c = 0; c < 3; ++c) {
        const double value = image.data[4 * p + c];
        ASSERT_TRUE(std::isfinite(value));
        EXPECT_NEAR(value, 0.75, 0.05 * 0.75) << "roughness " << roughness << " pixel " << p;
        mean += value / (3.0 * res * res);
      }
    }
    EXPECT_NEAR(mean, 0.75, 0.01 * 0.75) << "roughness " << roughness;
  }
}

}  // namespace
}  // namespace sft
