// The adjoint gradient split by derivative term (DerivativeRequest::gradient_parts,
// GradientParts in src/render/derivatives.h), on a scene where every edge term is present: a cube
// above a floor, both with a mesh-colors albedo that varies per texel (texel edges, seen directly
// and through a bounce), lit by a point light that casts the cube's shadow onto the floor (shadow
// edges), seen with the cube's silhouettes against the floor (primary edges), with two segments
// (secondary edges).
//
// Every edge term draws its random numbers from streams of its own (primary, shadow and texel
// edge samples from per-sample keys, secondary edges from forks of the path's sampler that do not
// advance it), so at one seed the gradient with a term minus the gradient without it is that
// term's part, up to rounding: the pass rounds each pixel's derivative sums to float before
// weighting them, so removing a term changes other entries by float rounding of the pixel sums
// (relative ~6e-8 each). Tolerance: 1e-6 of the gradient's RMS per entry (RMS over the vertex
// entries; measured 1e-8 to 7e-8 here). Were the streams not independent (e.g. a term consuming
// the path's sampler), the difference would be Monte Carlo noise; here the smallest part, the
// secondary edges', is 1.6% of the gradient's RMS and the largest, the primary edges', 100%.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "src/geometry/material.h"
#include "src/render/render.h"
#include "tests/testing/meshes.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

constexpr int kTexelResolution = 2;

struct Scene {
  testing::Triangles mesh;
  std::unique_ptr<RenderScene> render_scene;
  Material material;
  ViewSetup view;
  Image weights;
};

Scene MakeScene() {
  Scene s;
  s.mesh = testing::ReadTestMesh("cube_2x2x2_12f.obj");  // [−1, 1]³.
  for (Eigen::Vector3d& p : s.mesh.positions) p = 0.5 * p + Eigen::Vector3d(0.0, 0.0, 0.2);
  testing::Triangles floor;
  for (const Eigen::Vector3d& p : testing::QuadPositions(3.0)) {
    floor.positions.push_back(p - Eigen::Vector3d(0.0, 0.0, 0.8));
  }
  floor.faces = testing::QuadFaces();
  s.mesh.Append(floor);
  s.render_scene = std::make_unique<RenderScene>(s.mesh.positions, s.mesh.faces);
  const int num_faces = static_cast<int>(s.mesh.faces.size());
  s.material =
      ConstantMaterial(num_faces, Eigen::Vector3d(0.5, 0.5, 0.5), 0.5, 0.0, kTexelResolution);
  for (int k = 0; k < s.material.albedo.num_texels(); ++k) {
    const double level = 0.2 + 0.6 * ((k * 7919) % 13) / 12.0;  // a fixed pseudo-random pattern.
    for (int c = 0; c < 3; ++c) s.material.albedo.texel(k)[c] = level * (1.0 - 0.2 * c);
  }
  s.view = testing::LookAtView(Eigen::Vector3d(2.5, -3.0, 2.5), Eigen::Vector3d(0.0, 0.0, -0.2), 32,
                               30.0);
  testing::AddPointLight(Eigen::Vector3d(1.5, 0.8, 3.0), 12.0, &s.view);
  s.view.point_lights[0].light_index = 0;
  // Smooth, signed per-pixel weights, as an image loss's residuals are.
  s.weights = Image(32, 32, 3);
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      for (int c = 0; c < 3; ++c) {
        s.weights.at(x, y, c) = static_cast<float>(std::sin(0.3 * x + 0.2 * y + c) + 0.3);
      }
    }
  }
  return s;
}

RenderOptions Options() {
  RenderOptions options;
  options.spp = 4;
  options.bounces = 2;
  options.seed = 11;
  options.threads = 2;
  return options;
}

// Every edge term on with budgets that make each term's part clearly non-zero here.
DerivativeRequest Request(const Scene& s, bool parts) {
  DerivativeRequest request;
  request.params.vertices = true;
  request.adjoint_weights = &s.weights;
  request.primary_edge_ratio = 0.5;
  request.shadow_edge_ratio = 0.5;
  request.texel_edge_ratio = 0.5;
  request.secondary_edge_samples = 1.0;
  request.gradient_parts = parts;
  return request;
}

DerivativeOutput Render(const Scene& s, const DerivativeRequest& request) {
  Image image;
  DerivativeOutput output;
  RenderStats stats;
  RenderViewWithDerivatives(*s.render_scene, s.material, s.view, Options(), request, 1, &image,
                            &output, &stats);
  EXPECT_EQ(stats.NonFinite(), 0);
  return output;
}

// The request with term `term`'s budget 0.
DerivativeRequest Without(DerivativeRequest request, DerivativeTerm term) {
  switch (term) {
    case DerivativeTerm::kPrimaryEdges:
      request.primary_edge_ratio = 0.0;
      break;
    case DerivativeTerm::kShadowEdges:
      request.shadow_edge_ratio = 0.0;
      break;
    case DerivativeTerm::kTexelEdges:
      request.texel_edge_ratio = 0.0;
      break;
    case DerivativeTerm::kSecondaryEdges:
      request.secondary_edge_samples = 0.0;
      break;
    case DerivativeTerm::kRest:
      break;
  }
  return request;
}

const DerivativeTerm kEdgeTerms[] = {DerivativeTerm::kPrimaryEdges, DerivativeTerm::kShadowEdges,
                                     DerivativeTerm::kTexelEdges, DerivativeTerm::kSecondaryEdges};

// RMS of the vertex entries of a gradient.
double VertexRms(const std::vector<double>& g, int num_vertices) {
  double sum = 0.0;
  for (int i = 0; i < 3 * num_vertices; ++i) sum += g[i] * g[i];
  return std::sqrt(sum / (3 * num_vertices));
}

TEST(GradientPartsTest, PartsSumToTheGradientWhichTheyDoNotChange) {
  const Scene s = MakeScene();
  const DerivativeOutput plain = Render(s, Request(s, false));
  const DerivativeOutput split = Render(s, Request(s, true));
  EXPECT_TRUE(plain.gradient_parts.empty());
  ASSERT_EQ(split.gradient, plain.gradient);  // to the bit: the split does not touch the total.
  const int n = static_cast<int>(plain.gradient.size());
  const int num_vertices = split.layout.num_vertices;
  const double rms = VertexRms(plain.gradient, num_vertices);
  ASSERT_GT(rms, 0.0);
  for (const DerivativeTerm term : kEdgeTerms) {
    const std::vector<double>& part = split.gradient_parts.part(term);
    ASSERT_EQ(static_cast<int>(part.size()), n);
    // Each edge term matters in this scene (else the tests below would prove nothing for it) and
    // moves vertices only.
    EXPECT_GT(VertexRms(part, num_vertices), 1e-3 * rms) << DerivativeTermName(term);
    for (int i = 3 * num_vertices; i < n; ++i) ASSERT_EQ(part[i], 0.0) << i;
  }
  double max_error = 0.0;
  for (int i = 0; i < n; ++i) {
    double sum = 0.0;
    for (const std::vector<double>& part : split.gradient_parts.parts) sum += part[i];
    max_error = std::max(max_error, std::abs(sum - plain.gradient[i]));
  }
  EXPECT_LT(max_error, 1e-12 * std::max(1.0, rms));
}

TEST(GradientPartsTest, ATermThatIsOffHasNoPart) {
  const Scene s = MakeScene();
  for (const DerivativeTerm term : kEdgeTerms) {
    const DerivativeOutput out = Render(s, Without(Request(s, true), term));
    for (const double g : out.gradient_parts.part(term))
      ASSERT_EQ(g, 0.0) << DerivativeTermName(term);
  }
}

TEST(GradientPartsTest, APartIsTheGradientWithTheTermMinusWithoutItAtTheSameSeed) {
  const Scene s = MakeScene();
  const DerivativeOutput all = Render(s, Request(s, true));
  const int num_vertices = all.layout.num_vertices;
  const double rms = VertexRms(all.gradient, num_vertices);
  for (const DerivativeTerm term : kEdgeTerms) {
    const DerivativeOutput without = Render(s, Without(Request(s, true), term));
    const std::vector<double>& part = all.gradient_parts.part(term);
    double max_error = 0.0;
    for (size_t i = 0; i < part.size(); ++i) {
      max_error = std::max(max_error, std::abs(all.gradient[i] - without.gradient[i] - part[i]));
    }
    EXPECT_LT(max_error, 1e-6 * rms) << DerivativeTermName(term);
    // The other terms' parts are those of the pass with every term.
    for (const DerivativeTerm other : kEdgeTerms) {
      if (other == term) continue;
      EXPECT_EQ(without.gradient_parts.part(other), all.gradient_parts.part(other))
          << DerivativeTermName(term) << " off changed " << DerivativeTermName(other);
    }
  }
}

}  // namespace
}  // namespace sft
