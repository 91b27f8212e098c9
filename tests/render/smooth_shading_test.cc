// Smooth shading (render.h's Shading::kSmooth): the angle-weighted vertex normals against known
// answers, their Jacobian against finite differences, and rendered vertex derivatives against
// central differences on curved surfaces where flat shading would need crease terms.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "src/eval/gradcheck.h"
#include "src/geometry/material.h"
#include "src/render/internal/vertex_normal_jacobian.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/finite_differences.h"
#include "tests/testing/meshes.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

using testing::CompareWithFiniteDifferences;
using testing::Comparison;
using testing::LookAtView;
using testing::Triangles;

double AngleDegrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

// Angle weighting does not depend on how a face is triangulated: at a corner of a cube three
// square faces meet at right angles whatever their diagonals, so every vertex normal is the
// diagonal sign(p)/√3 exactly (area weighting gives 1 or 2 triangles per square depending on
// the diagonal, so it tilts).
TEST(SmoothShadingTest, CubeCornerNormalsAreTheDiagonals) {
  const Triangles cube = testing::ReadTestMesh("cube_2x2x2_12f.obj");
  const RenderScene scene(cube.positions, cube.faces);
  for (size_t v = 0; v < cube.positions.size(); ++v) {
    const Eigen::Vector3d& p = cube.positions[v];
    const Eigen::Vector3d expected =
        Eigen::Vector3d(p.x() > 0 ? 1 : -1, p.y() > 0 ? 1 : -1, p.z() > 0 ? 1 : -1).normalized();
    EXPECT_LT((scene.VertexNormal(static_cast<int>(v)) - expected).norm(), 1e-12) << v;
  }
  // At a corner the interpolated normal is that corner's normal.
  const Eigen::Vector3i& f = cube.faces[0];
  EXPECT_LT((scene.SmoothNormal(0, 1.0, 0.0) - scene.VertexNormal(f[1])).norm(), 1e-12);
}

// On a unit icosphere the vertex normals are nearly radial and the interpolated normal follows
// the sphere's normal far more closely than the facets do. Measured on icosphere_r1_1280f:
// vertex normals within 0.02° of radial, interpolated normals at random points within 1.0°,
// face normals up to 2.3° off.
TEST(SmoothShadingTest, IcosphereNormalsFollowTheSphere) {
  const Triangles sphere = testing::ReadTestMesh("icosphere_r1_1280f.obj");
  const RenderScene scene(sphere.positions, sphere.faces);
  double max_vertex = 0.0;
  for (size_t v = 0; v < sphere.positions.size(); ++v) {
    max_vertex = std::max(max_vertex, AngleDegrees(scene.VertexNormal(static_cast<int>(v)),
                                                   sphere.positions[v].normalized()));
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  double max_smooth = 0.0, max_flat = 0.0;
  for (int f = 0; f < static_cast<int>(sphere.faces.size()); ++f) {
    double u = uniform(rng), v = uniform(rng);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const Eigen::Vector3d radial = scene.Point(f, u, v).normalized();
    max_smooth = std::max(max_smooth, AngleDegrees(scene.SmoothNormal(f, u, v), radial));
    max_flat = std::max(max_flat, AngleDegrees(scene.FaceNormal(f), radial));
  }
  std::printf("vertex %.3f°, smooth %.3f°, flat %.3f°\n", max_vertex, max_smooth, max_flat);
  EXPECT_LT(max_vertex, 0.4);
  EXPECT_LT(max_smooth, 0.4);
  EXPECT_GT(max_flat, 4.0);
}

// ∂N̂/∂p from VertexNormalJacobian against central differences of the scene's vertex normals,
// on an irregular sphere (random jitter of 5% of an edge, so no symmetry hides a wrong term).
// Step 1e-6 of a 0.3-long edge: truncation ~h² and rounding ~1e-16/h keep the difference within
// 1e-8 of the derivative; allowed 1e-6 absolute (entries are O(1/edge) ≈ 3).
TEST(SmoothShadingTest, VertexNormalJacobianMatchesFiniteDifferences) {
  Triangles sphere = testing::ReadTestMesh("icosphere_r1_320f.obj");
  std::mt19937 rng(5);
  std::normal_distribution<double> jitter(0.0, 0.015);
  for (Eigen::Vector3d& p : sphere.positions) p += Eigen::Vector3d(jitter(rng), jitter(rng), 0.0);
  const RenderScene scene(sphere.positions, sphere.faces);
  const render_internal::VertexNormalJacobian jacobian(scene);
  const double h = 1e-6;
  double max_error = 0.0;
  int checked = 0;
  for (int w = 0; w < static_cast<int>(sphere.positions.size()); w += 7) {
    for (auto e = jacobian.begin(w); e != jacobian.end(w); ++e) {
      for (int k = 0; k < 3; ++k) {
        std::vector<Eigen::Vector3d> plus = sphere.positions, minus = sphere.positions;
        plus[e->vertex][k] += h;
        minus[e->vertex][k] -= h;
        const Eigen::Vector3d fd = (RenderScene(plus, sphere.faces).VertexNormal(w) -
                                    RenderScene(minus, sphere.faces).VertexNormal(w)) /
                                   (2.0 * h);
        max_error = std::max(max_error, (fd - e->d.col(k)).cwiseAbs().maxCoeff());
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 300);
  EXPECT_LT(max_error, 1e-6);
}

// A flat grid has every vertex normal equal to the face normal: smooth and flat shading render
// the same image bit for bit.
TEST(SmoothShadingTest, PlanarGridRendersAsFlat) {
  Triangles grid;
  grid.positions = testing::QuadPositions(1.0);
  grid.faces = testing::QuadFaces();
  const RenderScene scene(grid.positions, grid.faces);
  const Material material = ConstantMaterial(2, Eigen::Vector3d(0.5, 0.4, 0.3), 0.3, 0.5);
  ViewSetup view = LookAtView(Eigen::Vector3d(0.3, -0.4, 2.0), Eigen::Vector3d::Zero(), 32, 40.0);
  testing::AddPointLight(Eigen::Vector3d(0.2, 0.1, 1.5), 2.0, &view);
  RenderOptions options;
  options.spp = 4;
  Image flat, smooth;
  RenderView(scene, material, view, options, &flat);
  options.shading = Shading::kSmooth;
  RenderView(scene, material, view, options, &smooth);
  EXPECT_EQ(flat.data, smooth.data);
}

// A 16 × 16 grid over [−2, 2]² bent into smooth bumps (height 0.25: neighbouring faces are up to
// ~10° apart, every edge a crease for flat shading), seen from above with no silhouette in view.
Triangles BumpyGrid() {
  Triangles g;
  const int n = 16;
  const double half = 2.0;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = -half + 2.0 * half * i / n, y = -half + 2.0 * half * j / n;
      g.positions.emplace_back(x, y, 0.25 * std::sin(1.7 * x + 0.3) * std::cos(1.3 * y - 0.2));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      g.faces.emplace_back(a, b, d);
      g.faces.emplace_back(a, d, c);
    }
  }
  return g;
}

RenderOptions SmoothOptions(int spp, int bounces) {
  RenderOptions options;
  options.spp = spp;
  options.bounces = bounces;
  options.shading = Shading::kSmooth;
  options.effects.shadows = false;
  options.effects.environment = false;
  options.effects.bounces = bounces > 1;
  return options;
}

// Direct light on the smooth bumpy grid, Lambert and glossy (roughness 0.3, specular 0.5, the
// light beside the camera so highlights are in view). The derivative has the interior terms only
// (the normal through the two-ring's vertex normals and the sliding barycentrics; no crease is a
// discontinuity); block sums within 5% of the central difference (h = 1e-3 of the unit field:
// the image is smooth in t, and at 64 spp the common random numbers leave the quotient ≈ 1% noise
// at this step), as for the flat interior plane tests; measured 0.01% and 0.00%. Leaving out the
// barycentric (sliding) term gave 13% and 27% (61% in the indirect test below), so the test
// sees it.
TEST(SmoothShadingTest, BumpyGridDirectMatchesFiniteDifferences) {
  const Triangles grid = BumpyGrid();
  const std::vector<double> delta = SmoothDisplacementField(grid.positions, 7);
  ViewSetup view = LookAtView(Eigen::Vector3d(0, 0, 2.2), Eigen::Vector3d::Zero(), 64, 64.0,
                              Eigen::Vector3d::UnitY());
  view.point_lights.push_back({Eigen::Vector3d(0.3, 0.2, 2.0), Eigen::Vector3d(4, 3, 2), -1});
  for (double specular : {0.0, 0.5}) {
    const Material material = ConstantMaterial(static_cast<int>(grid.faces.size()),
                                               Eigen::Vector3d(0.6, 0.5, 0.4), 0.3, specular);
    const std::string name = "smooth direct, specular " + std::to_string(specular);
    const Comparison c = CompareWithFiniteDifferences(grid, delta, 1e-3, material, view,
                                                      SmoothOptions(64, 1), name.c_str());
    EXPECT_TRUE(c.finite) << name;
    EXPECT_LT(c.block_error, 0.05) << name;
    EXPECT_LT(c.sum_error, 0.05) << name;
    EXPECT_LT(c.adjoint_mismatch, 1e-4) << name;
  }
}

// One indirect bounce on the same grid (the bumps light each other): the scatter factor's normal
// terms at the first vertex and the light term at the second, both through smooth normals, and
// the secondary edges of the bumps' silhouettes seen from the first vertex. Tolerance 5% as
// above, at 256 spp (the indirect part is ≈ 10% of the image and noisier).
TEST(SmoothShadingTest, BumpyGridIndirectMatchesFiniteDifferences) {
  const Triangles grid = BumpyGrid();
  const std::vector<double> delta = SmoothDisplacementField(grid.positions, 11);
  ViewSetup view = LookAtView(Eigen::Vector3d(0, 0, 2.2), Eigen::Vector3d::Zero(), 64, 64.0,
                              Eigen::Vector3d::UnitY());
  view.point_lights.push_back({Eigen::Vector3d(1.5, 0.5, 0.8), Eigen::Vector3d(4, 4, 4), -1});
  const Material material = ConstantMaterial(static_cast<int>(grid.faces.size()),
                                             Eigen::Vector3d(0.7, 0.6, 0.5), 0.4, 0.4);
  RenderOptions options = SmoothOptions(256, 2);
  options.effects.shadows = true;
  const Comparison c =
      CompareWithFiniteDifferences(grid, delta, 1e-3, material, view, options, "smooth indirect");
  EXPECT_TRUE(c.finite);
  EXPECT_LT(c.block_error, 0.05);
  EXPECT_LT(c.sum_error, 0.05);
  EXPECT_LT(c.adjoint_mismatch, 1e-4);
}

}  // namespace
}  // namespace sft
