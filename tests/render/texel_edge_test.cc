// Vertex derivatives at texel boundaries of mesh-colors materials. Albedo and roughness are
// piecewise constant on each face's barycentric texel grid, so when the vertices move the grid
// lines (and coplanar mesh edges between differing texels) move in the image and the image
// jumps across them: a boundary term like a primary edge's, sampled by AddEdgeTerms with
// DerivativeRequest::texel_edge_ratio.
//
// Scene: a flat 4×4-quad grid (32 coplanar triangles) larger than the view, so that no mesh
// edge is a silhouette or crease in view and the only boundaries are texel boundaries; a
// checkerboard at r = 4; a point light, shadows off, direct light only. The vertices move by a
// smooth field with in-plane and out-of-plane parts. Directional derivatives are compared with
// central finite differences (same seeds) on 8×8 pixel-block sums, as in edge_sampling_test.cc.
//
// Tolerance 5% (as for the other boundary terms in edge_sampling_test.cc): both sides are
// Monte Carlo estimates of the boundary term. The finite difference counts the camera samples
// that change texel over the ±h step (~0.4 pixel here), so its noise falls like 1/√(h·spp), and
// its truncation error grows with h as lines cross pixel and block boundaries: on these scenes
// its block error was 1.6–2.5% over seeds 1–5 at 128 spp and h = 1e-2 (checkerboard: 2.4% at
// h = 5e-3 and 1024 spp, 13% at 64 spp with smaller texels), leaving a 2× margin. Without texel
// edges the comparison fails at ~100% (the in-plane motion of the texels is nearly all of the
// image's derivative), which shows the term matters. BoundarySeenThroughABounce checks the same
// boundaries seen through a bounce (secondary edges (C)).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>

#include "src/geometry/material.h"
#include "src/render/camera_rig.h"
#include "src/render/render.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

constexpr int kResolution = 4;

struct PlaneScene {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  std::vector<double> delta;  // direction over 3·V coordinates.
  ViewSetup view;
};

// Vertices on [−2, 2]² at z = 0 (5 × 5), two triangles per unit quad with alternating
// diagonals (so both corner orders of the texel grid appear); a camera looking down near the
// centre sees about [−0.8, 0.8]² (texels of ~10 pixels), away from the grid's border. The view
// is deliberately not aligned with the grid: a world line x = 0 projected exactly onto the
// central column (a block boundary) would make the block sums' derivative one-sided there.
PlaneScene MakePlane() {
  PlaneScene s;
  constexpr int kN = 5;
  for (int y = 0; y < kN; ++y) {
    for (int x = 0; x < kN; ++x) s.positions.emplace_back(x - 2.0, y - 2.0, 0.0);
  }
  for (int y = 0; y + 1 < kN; ++y) {
    for (int x = 0; x + 1 < kN; ++x) {
      const int a = y * kN + x, b = a + 1, c = a + kN + 1, d = a + kN;
      if ((x + y) % 2 == 0) {
        s.faces.emplace_back(a, b, c);
        s.faces.emplace_back(a, c, d);
      } else {
        s.faces.emplace_back(b, c, d);
        s.faces.emplace_back(b, d, a);
      }
    }
  }
  // Smooth field: in-plane swirl and shear (moves the texel lines) plus a gentle bump (tilts
  // the faces: interior terms).
  for (const Eigen::Vector3d& p : s.positions) {
    s.delta.push_back(0.6 * std::sin(0.9 * p.y() + 0.3) + 0.3);
    s.delta.push_back(0.5 * std::cos(0.7 * p.x() - 0.2) - 0.2 * p.x());
    s.delta.push_back(0.2 * std::sin(0.8 * p.x() + 0.6 * p.y()));
  }
  s.view = testing::LookAtView(Eigen::Vector3d(0.3, -0.6, 3.0), Eigen::Vector3d(0.13, 0.07, 0), 64,
                               120.0, Eigen::Vector3d(0, 1, 0));
  PointLight light;
  light.position = Eigen::Vector3d(0.5, 0.3, 2.0);
  light.intensity = Eigen::Vector3d::Constant(8.0);
  light.light_index = 0;
  s.view.point_lights.push_back(light);
  return s;
}

RenderOptions DirectOptions(int spp) {
  RenderOptions options;
  options.spp = spp;
  options.bounces = 1;
  options.effects.shadows = false;
  return options;
}

// Texel (i, j) of face f is light when i + j + f is even, dark otherwise (jumps across every
// grid line and most face edges); with `per_face` the whole face takes one colour by f's parity
// (no texel boundaries inside the faces, only at coplanar mesh edges).
Material Checkerboard(int num_faces, bool per_face) {
  Material material =
      ConstantMaterial(num_faces, Eigen::Vector3d(0.5, 0.5, 0.5), 0.5, 0.0, kResolution);
  for (int f = 0; f < num_faces; ++f) {
    for (int i = 0; i <= kResolution; ++i) {
      for (int j = 0; i + j <= kResolution; ++j) {
        const bool light = per_face ? f % 2 == 0 : (i + j + f) % 2 == 0;
        double* texel = material.albedo.texel(f * MeshColors::TexelsPerFace(kResolution) +
                                              MeshColors::LocalIndex(kResolution, i, j));
        texel[0] = light ? 0.8 : 0.15;
        texel[1] = light ? 0.6 : 0.3;
        texel[2] = light ? 0.3 : 0.5;
      }
    }
  }
  return material;
}

DerivativeRequest VertexRequest(double texel_edge_ratio) {
  DerivativeRequest request;
  request.params = ParameterSelection::Only(ParameterKind::kVertex);
  request.jacobian_rows = true;
  request.texel_edge_ratio = texel_edge_ratio;
  return request;
}

// ‖analytic − fd‖/‖fd‖ over 8×8 block sums and RGB of the directional derivative along
// s.delta, with texel edges at the default ratio (`with`) and without them (`without`: interior
// and primary-edge terms only), against one central difference with step h.
struct Comparison {
  double with = 0.0;
  double without = 0.0;
  double fd_norm = 0.0;
};

// The budget that Compare's `without` run turns off.
enum class Term { kTexelEdges, kSecondaryEdges };

Comparison Compare(const PlaneScene& s, const Material& material, const RenderOptions& options,
                   double h, Term term = Term::kTexelEdges) {
  auto displaced = [&](double t) {
    std::vector<Eigen::Vector3d> p = s.positions;
    for (size_t v = 0; v < p.size(); ++v) {
      for (int k = 0; k < 3; ++k) p[v][k] += t * s.delta[3 * v + k];
    }
    return p;
  };
  Image plus, minus;
  RenderView(RenderScene(displaced(h), s.faces), material, s.view, options, &plus);
  RenderView(RenderScene(displaced(-h), s.faces), material, s.view, options, &minus);
  const int w = plus.width, num_pixels = w * plus.height, nb = (w / 8) * (plus.height / 8);
  auto block = [&](int p) { return (p / w / 8) * (w / 8) + (p % w) / 8; };
  std::vector<Eigen::Vector3d> fd(nb, Eigen::Vector3d::Zero());
  for (int p = 0; p < num_pixels; ++p) {
    for (int c = 0; c < 3; ++c) {
      fd[block(p)][c] += (plus.data[4 * p + c] - minus.data[4 * p + c]) / (2 * h);
    }
  }
  Comparison result;
  for (const Eigen::Vector3d& f : fd) result.fd_norm += f.squaredNorm();
  result.fd_norm = std::sqrt(result.fd_norm);
  const RenderScene scene(s.positions, s.faces);
  for (const bool with : {true, false}) {
    DerivativeRequest request = VertexRequest(DerivativeRequest().texel_edge_ratio);
    if (!with && term == Term::kTexelEdges) request.texel_edge_ratio = 0.0;
    if (!with && term == Term::kSecondaryEdges) request.secondary_edge_samples = 0.0;
    Image image;
    DerivativeOutput out;
    RenderViewWithDerivatives(scene, material, s.view, options, request, 1, &image, &out);
    std::vector<Eigen::Vector3d> analytic(nb, Eigen::Vector3d::Zero());
    for (int p = 0; p < num_pixels; ++p) {
      for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
        const JacobianEntry& entry = out.rows.entries[e];
        for (int c = 0; c < 3; ++c) analytic[block(p)][c] += entry.d[c] * s.delta[entry.param];
      }
    }
    double e2 = 0.0;
    for (int b = 0; b < nb; ++b) e2 += (analytic[b] - fd[b]).squaredNorm();
    (with ? result.with : result.without) = std::sqrt(e2) / result.fd_norm;
  }
  return result;
}

TEST(TexelEdgeTest, CheckerboardMatchesFiniteDifferences) {
  const PlaneScene s = MakePlane();
  const Material material = Checkerboard(static_cast<int>(s.faces.size()), /*per_face=*/false);
  const Comparison c = Compare(s, material, DirectOptions(128), 1e-2);
  EXPECT_LT(c.with, 0.05) << "|fd| " << c.fd_norm;
  EXPECT_GT(c.without, 0.5) << "interior terms alone should miss the texel jumps";
}

// One colour per face: no texel boundary inside the faces; the coplanar mesh edges between faces
// of different colours (not primary edges: the faces are coplanar) carry the jump.
TEST(TexelEdgeTest, CoplanarFaceEdgesMatchFiniteDifferences) {
  const PlaneScene s = MakePlane();
  const Material material = Checkerboard(static_cast<int>(s.faces.size()), /*per_face=*/true);
  const Comparison c = Compare(s, material, DirectOptions(128), 1e-2);
  EXPECT_LT(c.with, 0.05) << "|fd| " << c.fd_norm;
  EXPECT_GT(c.without, 0.5) << "interior terms alone should miss the face-edge jumps";
}

// A roughness checkerboard under a glossy lobe (constant albedo): the jump is in the highlight.
TEST(TexelEdgeTest, GlossyRoughnessCheckerboard) {
  const PlaneScene s = MakePlane();
  const int num_faces = static_cast<int>(s.faces.size());
  Material material = Checkerboard(num_faces, /*per_face=*/false);
  for (int k = 0; k < material.albedo.num_texels(); ++k) {
    *material.roughness.texel(k) = material.albedo.texel(k)[0] > 0.5 ? 0.15 : 0.5;
    for (int c = 0; c < 3; ++c) material.albedo.texel(k)[c] = 0.3;
  }
  material.specular = 0.5;
  const Comparison c = Compare(s, material, DirectOptions(128), 1e-2);
  EXPECT_LT(c.with, 0.05) << "|fd| " << c.fd_norm;
  EXPECT_GT(c.without, 0.5) << "interior terms alone should miss the highlight's jumps";
}

// Materials without visible texel jumps trace no texel-edge samples: a constant material at
// r = 4, and a roughness checkerboard without a glossy lobe (roughness then changes nothing).
// Texel boundaries seen through a bounce (secondary edges (C)): the camera looks up at a white
// ceiling (z = 1) lit by the point light and by the light the checkerboard floor below reflects;
// the floor is not in view. The floor's vertices move in its plane (zero on its border, so no
// floor edge moves), which changes no normal and no hit point's position, only which texel the
// bounce rays land on: the whole derivative is the texel boundaries' motion seen from the
// ceiling. Without secondary edges the analytic side is zero.
//
// The finite difference is noisy here (bounce rays near the boundary switch texels over the ±h
// step), so h is long (0.1; the irradiance is smooth in the boundary's position) and the samples
// many. Block error with the term sampled at every secondary sample: 4.8%, 5.0%, 5.6%, 5.0% for
// seeds 0–3 at 2048 spp; 4.1% at 4096 and 3.4% at 8192 spp (seed 0); at h = 0.05: 13% (1024 spp),
// 5.3% (4096); at a quarter of them (the default, kSecondaryTexelProbability) 6.0%–8.3% over
// seeds 0–4 at 2048 spp (one seed had given 5.2% before the random streams of the secondary
// samples changed; no other term contributes here: the moving vertices carry no mesh edge),
// and 7.0% at 4096, 3.7% at 8192 spp (seed 0). Hence 10% at 2048 spp (~7 s on 2 cores), above
// the 5% because of that noise.
TEST(TexelEdgeTest, BoundarySeenThroughABounce) {
  PlaneScene s = MakePlane();
  s.delta.clear();
  for (const Eigen::Vector3d& p : s.positions) {
    const double bump = (4.0 - p.x() * p.x()) * (4.0 - p.y() * p.y()) / 16.0;
    s.delta.push_back(0.8 * std::sin(0.9 * p.y() + 0.3) * bump);
    s.delta.push_back(0.8 * std::cos(0.7 * p.x() - 0.2) * bump);
    s.delta.push_back(0.0);
  }
  const int floor_faces = static_cast<int>(s.faces.size());
  const int base = static_cast<int>(s.positions.size());
  for (const auto& [x, y] : {std::pair{-3.0, -3.0}, {3.0, -3.0}, {3.0, 3.0}, {-3.0, 3.0}}) {
    s.positions.emplace_back(x, y, 1.0);
    for (int k = 0; k < 3; ++k) s.delta.push_back(0.0);
  }
  s.faces.emplace_back(base, base + 2, base + 1);
  s.faces.emplace_back(base, base + 3, base + 2);
  s.view = testing::LookAtView(Eigen::Vector3d(0.1, 0.05, 0.3), Eigen::Vector3d(0.15, 0.1, 1.0), 32,
                               24.0, Eigen::Vector3d(0, 1, 0));
  testing::AddPointLight(Eigen::Vector3d(0.3, -0.2, 0.6), 3.0, &s.view);
  // Floor texels bright where their lattice point lies at x < 0.25, dark elsewhere: one
  // staircase boundary across the floor, along grid lines inside faces and along face edges
  // (a fine checkerboard would cancel out in the ceiling's irradiance); the ceiling white.
  Material material = ConstantMaterial(static_cast<int>(s.faces.size()),
                                       Eigen::Vector3d::Constant(0.8), 0.5, 0.0, kResolution);
  for (int f = 0; f < floor_faces; ++f) {
    const Eigen::Vector3i& corners = s.faces[f];
    for (int i = 0; i <= kResolution; ++i) {
      for (int j = 0; i + j <= kResolution; ++j) {
        const double alpha = static_cast<double>(i) / kResolution;
        const double beta = static_cast<double>(j) / kResolution;
        const double x = (1.0 - alpha - beta) * s.positions[corners[0]].x() +
                         alpha * s.positions[corners[1]].x() + beta * s.positions[corners[2]].x();
        double* texel = material.albedo.texel(f * MeshColors::TexelsPerFace(kResolution) +
                                              MeshColors::LocalIndex(kResolution, i, j));
        texel[0] = texel[1] = texel[2] = x < 0.25 ? 0.9 : 0.05;
      }
    }
  }
  RenderOptions options = DirectOptions(2048);
  options.bounces = 2;
  const Comparison c = Compare(s, material, options, 0.1, Term::kSecondaryEdges);
  std::printf("texel boundaries through a bounce: with %.4f, without %.4f (fd norm %.4g)\n", c.with,
              c.without, c.fd_norm);
  EXPECT_GT(c.fd_norm, 0.0);
  EXPECT_GT(c.without, 0.9);
  EXPECT_LT(c.with, 0.10);
}

TEST(TexelEdgeTest, NoJumpsNoSamples) {
  const PlaneScene s = MakePlane();
  const RenderScene scene(s.positions, s.faces);
  const int num_faces = static_cast<int>(s.faces.size());
  const Material constant =
      ConstantMaterial(num_faces, Eigen::Vector3d(0.5, 0.4, 0.3), 0.5, 0.0, kResolution);
  Material rough = constant;
  for (int k = 0; k < rough.roughness.num_texels(); ++k) {
    *rough.roughness.texel(k) = k % 2 == 0 ? 0.2 : 0.8;
  }
  const RenderOptions options = DirectOptions(4);
  for (const Material* material : std::vector<const Material*>{&constant, &rough}) {
    Image image;
    DerivativeOutput with_out, without_out;
    RenderStats with_stats, without_stats;
    RenderViewWithDerivatives(scene, *material, s.view, options, VertexRequest(16.0), 1, &image,
                              &with_out, &with_stats);
    RenderViewWithDerivatives(scene, *material, s.view, options, VertexRequest(0.0), 1, &image,
                              &without_out, &without_stats);
    EXPECT_EQ(with_stats.camera_rays, without_stats.camera_rays);
    EXPECT_EQ(with_stats.bounce_rays, without_stats.bounce_rays);
    EXPECT_EQ(with_out.rows.entries.size(), without_out.rows.entries.size());
  }
}

}  // namespace
}  // namespace sft
