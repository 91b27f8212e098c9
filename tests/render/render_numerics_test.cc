// Numerics of the renderer: determinism of derivatives across thread counts, non-finite values
// counted and dropped (RenderStats), and the floating-point mode left as the caller set it.
#include <gtest/gtest.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "src/geometry/material.h"
#include "src/render/render.h"
#include "tests/testing/meshes.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

// A 2×2×2 cube (data/meshes) standing on a 12×12 ground quad, seen obliquely: silhouettes,
// creases, a cast shadow and light bounced between cube and ground.
testing::Triangles CubeOnGround() {
  testing::Triangles cube = testing::ReadTestMesh("cube_2x2x2_12f.obj");
  for (Eigen::Vector3d& p : cube.positions) p = 0.5 * p + Eigen::Vector3d(0, 0, 0.5);
  testing::Triangles scene;
  scene.positions = {{-6, -6, 0}, {6, -6, 0}, {6, 6, 0}, {-6, 6, 0}};
  scene.faces = {{0, 1, 2}, {0, 2, 3}};
  scene.Append(cube);
  return scene;
}

struct DerivativeRender {
  Image image;
  DerivativeOutput output;
  RenderStats stats;
};

DerivativeRender Render(const RenderScene& scene, const Material& material, const ViewSetup& view,
                        int threads, const Image* weights) {
  RenderOptions options;
  options.spp = 4;
  options.bounces = 2;
  options.threads = threads;
  DerivativeRequest request;
  request.params.vertices = true;
  request.jacobian_rows = weights == nullptr;
  request.adjoint_weights = weights;
  request.primary_edge_ratio = 1.0;
  request.shadow_edge_ratio = 1.0;
  request.secondary_edge_samples = 2.0;
  DerivativeRender out;
  RenderViewWithDerivatives(scene, material, view, options, request, 1, &out.image, &out.output,
                            &out.stats);
  return out;
}

ViewSetup CubeView() {
  ViewSetup view = testing::LookAtView({5, -4, 4}, {0, 0, 0.4}, 40, 45.0);
  testing::AddPointLight({-2, -3, 5}, 30.0, &view);
  return view;
}

TEST(RenderNumericsTest, DerivativesAreBitIdenticalForOneAndTwoThreads) {
  const testing::Triangles mesh = CubeOnGround();
  const RenderScene scene(mesh.positions, mesh.faces);
  const Material material = ConstantMaterial(static_cast<int>(mesh.faces.size()),
                                             Eigen::Vector3d(0.7, 0.5, 0.3), 0.4, 0.3);
  const ViewSetup view = CubeView();
  const DerivativeRender one = Render(scene, material, view, 1, nullptr);
  const DerivativeRender two = Render(scene, material, view, 2, nullptr);
  ASSERT_GT(one.output.rows.entries.size(), 1000u);
  ASSERT_EQ(one.output.rows.offsets, two.output.rows.offsets);
  ASSERT_EQ(one.output.rows.entries.size(), two.output.rows.entries.size());
  EXPECT_EQ(0, std::memcmp(one.output.rows.entries.data(), two.output.rows.entries.data(),
                           one.output.rows.entries.size() * sizeof(JacobianEntry)));
  EXPECT_EQ(one.image.data, two.image.data);
  // Every edge kind contributed: the ray counts include edge samples' side rays.
  EXPECT_GT(one.stats.shadow_rays, 0);
  EXPECT_EQ(one.stats.camera_rays, two.stats.camera_rays);
  EXPECT_EQ(one.stats.bounce_rays, two.stats.bounce_rays);

  Image weights(40, 40, 3);
  for (size_t i = 0; i < weights.data.size(); ++i) {
    weights.data[i] = static_cast<float>((i * 7919) % 101) / 101.0f;
  }
  const DerivativeRender g1 = Render(scene, material, view, 1, &weights);
  const DerivativeRender g2 = Render(scene, material, view, 2, &weights);
  ASSERT_EQ(g1.output.gradient.size(), g2.output.gradient.size());
  int non_zero = 0;
  for (size_t i = 0; i < g1.output.gradient.size(); ++i) {
    EXPECT_EQ(g1.output.gradient[i], g2.output.gradient[i]) << "parameter " << i;
    non_zero += g1.output.gradient[i] != 0.0;
  }
  EXPECT_GT(non_zero, 20);
}

// The adjoint gradient equals Σ_pixels w·(the pixel's float row) up to summation order, and the
// render holds one term per distinct parameter of each 8×8 tile, not one per row entry.
TEST(RenderNumericsTest, AdjointIsTheWeightedRowsSummedPerTile) {
  const testing::Triangles mesh = CubeOnGround();
  const RenderScene scene(mesh.positions, mesh.faces);
  const Material material = ConstantMaterial(static_cast<int>(mesh.faces.size()),
                                             Eigen::Vector3d(0.7, 0.5, 0.3), 0.4, 0.3);
  const ViewSetup view = CubeView();
  const int res = view.camera.width;
  Image weights(res, res, 3);
  for (size_t i = 0; i < weights.data.size(); ++i) {
    weights.data[i] = static_cast<float>((i * 7919) % 101) / 50.5f - 1.0f;
  }
  RenderOptions options;
  options.spp = 4;
  options.bounces = 2;
  DerivativeRequest request;
  request.params.vertices = true;
  request.jacobian_rows = true;
  request.adjoint_weights = &weights;
  request.primary_edge_ratio = 1.0;
  request.shadow_edge_ratio = 1.0;
  request.secondary_edge_samples = 2.0;
  Image image;
  DerivativeOutput out;
  RenderStats stats;
  RenderViewWithDerivatives(scene, material, view, options, request, 1, &image, &out, &stats);

  constexpr int kTile = 8;
  const int tiles_x = (res + kTile - 1) / kTile;
  ASSERT_EQ(RenderTileCount(res, res), tiles_x * tiles_x);
  std::vector<double> expected(out.gradient.size(), 0.0);
  std::vector<std::vector<int>> tile_params(RenderTileCount(res, res));
  for (int p = 0; p < res * res; ++p) {
    const int tile = (p / res / kTile) * tiles_x + (p % res) / kTile;
    for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
      const JacobianEntry& entry = out.rows.entries[e];
      double g = 0.0;
      for (int c = 0; c < 3; ++c) g += weights.data[3 * p + c] * static_cast<double>(entry.d[c]);
      expected[entry.param] += g;
      if (g != 0.0) tile_params[tile].push_back(entry.param);
    }
  }
  int64_t distinct = 0;
  for (std::vector<int>& params : tile_params) {
    std::sort(params.begin(), params.end());
    distinct += std::unique(params.begin(), params.end()) - params.begin();
  }
  EXPECT_EQ(stats.gradient_terms, distinct);
  EXPECT_LT(stats.gradient_terms, static_cast<int64_t>(out.rows.entries.size()) / 2);
  double max_abs = 0.0;
  for (double g : expected) max_abs = std::max(max_abs, std::abs(g));
  ASSERT_GT(max_abs, 0.0);
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(out.gradient[i], expected[i], 1e-12 * max_abs) << "parameter " << i;
  }
}

// A light of infinite intensity in one channel makes every sample that sees it non-finite: the
// samples are counted and dropped with their derivative terms, so image and rows stay finite.
TEST(RenderNumericsTest, NonFiniteSamplesAreCountedAndDropped) {
  const testing::Triangles mesh = CubeOnGround();
  const RenderScene scene(mesh.positions, mesh.faces);
  const Material material = ConstantMaterial(static_cast<int>(mesh.faces.size()),
                                             Eigen::Vector3d(0.7, 0.5, 0.3), 0.4, 0.0);
  ViewSetup view = CubeView();
  view.point_lights[0].intensity.x() = std::numeric_limits<double>::infinity();
  view.point_lights[0].light_index = 0;
  RenderOptions options;
  options.spp = 2;
  options.bounces = 1;
  DerivativeRequest request;
  request.params.vertices = true;
  request.jacobian_rows = true;
  Image image;
  DerivativeOutput output;
  RenderStats stats;
  RenderViewWithDerivatives(scene, material, view, options, request, 1, &image, &output, &stats);
  // Lit pixels lose their samples; the background and shadowed ground keep theirs.
  EXPECT_GT(stats.nonfinite_samples, 40 * 40 * 2 / 4);
  EXPECT_LT(stats.nonfinite_samples, 40 * 40 * 2);
  EXPECT_EQ(stats.nonfinite_outputs, 0);
  for (float v : image.data) ASSERT_TRUE(std::isfinite(v));
  for (const JacobianEntry& e : output.rows.entries) {
    for (float d : e.d) ASSERT_TRUE(std::isfinite(d));
  }

  // A finite intensity whose pixel values and derivatives overflow float: counted as outputs.
  view.point_lights[0].intensity = Eigen::Vector3d::Constant(1e300);
  RenderViewWithDerivatives(scene, material, view, options, request, 1, &image, &output, &stats);
  EXPECT_EQ(stats.nonfinite_samples, 0);
  EXPECT_GT(stats.nonfinite_outputs, 40 * 40 / 4);
  for (const JacobianEntry& e : output.rows.entries) {
    for (float d : e.d) ASSERT_TRUE(std::isfinite(d));
  }
  RenderStats forward;
  RenderView(scene, material, view, options, &image, &forward);
  EXPECT_GT(forward.nonfinite_outputs, 40 * 40 / 4);
}

// Tracing threads run with flush-to-zero / denormals-are-zero; the caller's mode (its thread
// runs tasks of the render's arena too) is the same after the render as before.
TEST(RenderNumericsTest, CallersFloatingPointModeIsRestored) {
  const testing::Triangles mesh = CubeOnGround();
  const RenderScene scene(mesh.positions, mesh.faces);
  const Material material = ConstantMaterial(static_cast<int>(mesh.faces.size()),
                                             Eigen::Vector3d(0.7, 0.5, 0.3), 0.4, 0.3);
  const ViewSetup view = CubeView();
  const unsigned int saved = _mm_getcsr();
  _mm_setcsr(saved & ~(_MM_FLUSH_ZERO_MASK | 0x0040u));  // FTZ and DAZ off.
  const unsigned int before = _mm_getcsr();
  for (int threads : {1, 2}) {
    Render(scene, material, view, threads, nullptr);
    EXPECT_EQ(_mm_getcsr() & ~0x3Fu, before & ~0x3Fu) << threads << " threads";  // not flags.
  }
  _mm_setcsr(saved);
}

}  // namespace
}  // namespace sft
