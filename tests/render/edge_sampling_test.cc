// Vertex derivatives in scenes where one kind of term is the only one: a shadow cast on a
// ground quad by an occluder the camera does not see (shadow edges alone), a floating triangle
// against a black background (primary silhouette edges alone), a ridge between two large faces
// (crease edges alone, point and environment light), and a tilted plane (interior terms alone).
// Directional derivatives Jδ are compared with central finite differences (renders at
// θ ± hδ with the same seeds) on 8×8 pixel-block sums and on two smooth projections Σ w·I.
//
// Tolerance 5% for boundary terms (the bound): both sides are Monte Carlo estimates —
// the edge estimator is stratified along the edges and has ~1% error here, the finite difference
// of a moving boundary is quantised by the camera samples that cross it and smeared over the
// ±h displacement, hence steps that move boundaries by about a pixel. Interior-only cases are
// deterministic functions of θ for fixed samples: tolerance 1%.
#include <gtest/gtest.h>

#include <memory>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/render/camera_rig.h"
#include "src/render/environment.h"
#include "src/render/render.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

using testing::AddPointLight;
using testing::LookAtView;

struct EdgeScene {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  std::vector<double> delta;  // direction over 3·V coordinates.
  ViewSetup view;
};

// A 6×6 plane (two triangles) filling the view and tilting/shifting along δ: no edge of it is
// seen, so only interior terms move the image.
EdgeScene TiltingPlaneScene() {
  EdgeScene s;
  s.positions = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
  s.faces = {{0, 1, 2}, {0, 2, 3}};
  for (const auto& p : s.positions) {
    s.delta.push_back(0.1);
    s.delta.push_back(0.0);
    s.delta.push_back(0.3 * p.x() + 0.2 * p.y() + 0.5);
  }
  s.view = LookAtView({1, 0.5, 3}, {0, 0, 0}, 64, 150);
  return s;
}

// A dim uniform environment with one bright patch above the horizon.
const EnvironmentMap& PatchEnvironment() {
  static const EnvironmentMap* env = [] {
    Image image(32, 16, 3, 0.3f);
    for (int y = 3; y < 7; ++y) {
      for (int x = 10; x < 15; ++x) image.at(x, y, 0) = image.at(x, y, 1) = 5.f;
    }
    return new EnvironmentMap(image, Eigen::Matrix3d::Identity(), 1.0);
  }();
  return *env;
}

// Sum over pixels and channels of w(x, y)·image, w = 1 or a smooth ramp.
double Project(const Image& image, int weight) {
  double sum = 0.0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const double w = weight == 0 ? 1.0 : (x + 0.5) / image.width;
      for (int c = 0; c < 3; ++c) sum += w * image.at(x, y, c);
    }
  }
  return sum;
}

double ProjectRows(const DerivativeOutput& out, const std::vector<double>& delta, int weight) {
  double sum = 0.0;
  const int width = out.rows.width;
  for (int p = 0; p < width * out.rows.height; ++p) {
    const double w = weight == 0 ? 1.0 : ((p % width) + 0.5) / width;
    for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
      const JacobianEntry& entry = out.rows.entries[e];
      for (int c = 0; c < 3; ++c) sum += w * entry.d[c] * delta[entry.param];
    }
  }
  return sum;
}

void CheckScene(const EdgeScene& s, const RenderOptions& options, double h, double tolerance) {
  const RenderScene scene(s.positions, s.faces);
  const Material material =
      ConstantMaterial(static_cast<int>(s.faces.size()), Eigen::Vector3d(0.6, 0.5, 0.4), 0.5, 0.0);
  DerivativeRequest request;
  request.params = ParameterSelection::Only(ParameterKind::kVertex);
  request.jacobian_rows = true;
  Image image, plus, minus;
  DerivativeOutput out;
  RenderViewWithDerivatives(scene, material, s.view, options, request, 1, &image, &out);
  auto displaced = [&](double t) {
    std::vector<Eigen::Vector3d> p = s.positions;
    for (size_t v = 0; v < p.size(); ++v) {
      for (int k = 0; k < 3; ++k) p[v][k] += t * s.delta[3 * v + k];
    }
    return p;
  };
  RenderView(RenderScene(displaced(h), s.faces), material, s.view, options, &plus);
  RenderView(RenderScene(displaced(-h), s.faces), material, s.view, options, &minus);
  {
    // 8×8 block sums.
    const int w = image.width, hgt = image.height, nb = (w / 8) * (hgt / 8);
    std::vector<double> a(nb, 0.0), f(nb, 0.0);
    for (int p = 0; p < w * hgt; ++p) {
      const int b = (p / w / 8) * (w / 8) + (p % w) / 8;
      for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
        for (int c = 0; c < 3; ++c)
          a[b] += out.rows.entries[e].d[c] * s.delta[out.rows.entries[e].param];
      }
      for (int c = 0; c < 3; ++c) f[b] += (plus.data[4 * p + c] - minus.data[4 * p + c]) / (2 * h);
    }
    double e2 = 0, r2 = 0;
    for (int b = 0; b < nb; ++b) {
      e2 += (a[b] - f[b]) * (a[b] - f[b]);
      r2 += f[b] * f[b];
    }
    EXPECT_LT(std::sqrt(e2 / r2), tolerance) << "8x8 block relative error, |fd| " << std::sqrt(r2);
  }
  for (int weight = 0; weight < 2; ++weight) {
    const double fd = (Project(plus, weight) - Project(minus, weight)) / (2 * h);
    const double analytic = ProjectRows(out, s.delta, weight);
    EXPECT_NEAR(analytic, fd, tolerance * std::abs(fd)) << "weight " << weight;
  }
}

// Ground quad z = 0; a small triangle near the light casts a shadow into the view; the camera
// looks at the shadow and does not see the triangle.
EdgeScene ShadowScene() {
  EdgeScene s;
  s.positions = {{-3, -3, 0},        {3, -3, 0},          {3, 3, 0},        {-3, 3, 0},
                 {-0.9, -0.08, 1.6}, {-0.7, -0.05, 1.62}, {-0.8, 0.1, 1.58}};
  s.faces = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}};
  s.delta.assign(3 * s.positions.size(), 0.0);
  // The occluder moves sideways and its first corner up.
  for (int v = 4; v < 7; ++v) s.delta[3 * v + 0] = 1.0;
  s.delta[3 * 4 + 2] = 0.5;
  s.view = LookAtView({3, 0.2, 3}, {0, 0, 0}, 64, 200);
  PointLight light;
  light.position = Eigen::Vector3d(-1, 0, 2);
  light.intensity = Eigen::Vector3d::Constant(10.0);
  light.light_index = 0;
  s.view.point_lights.push_back(light);
  return s;
}

TEST(EdgeSamplingTest, ShadowEdgesAlone) {
  RenderOptions options;
  options.spp = 256;
  options.bounces = 1;
  CheckScene(ShadowScene(), options, 5e-3, 0.05);
}

// A triangle floating in front of a black background, lit by a point light: only its
// silhouette moves.
TEST(EdgeSamplingTest, PrimaryEdgesAlone) {
  EdgeScene s;
  s.positions = {{-0.5, -0.4, 0}, {0.6, -0.3, 0.1}, {0.0, 0.5, -0.1}};
  s.faces = {{0, 1, 2}};
  s.delta = {1, 0, 0, 0, 0.5, 0, 0.3, -0.2, 0.4};
  s.view = LookAtView({0.2, 0.1, 3}, {0, 0, 0}, 64, 80);
  AddPointLight(Eigen::Vector3d(0.5, 0.5, 3), 10.0, &s.view);
  RenderOptions options;
  options.spp = 64;
  options.bounces = 1;
  CheckScene(s, options, 2e-2, 0.05);
}

TEST(EdgeSamplingTest, PrimaryEdgesInPlane) {
  EdgeScene s;
  s.positions = {{-0.5, -0.4, 0}, {0.6, -0.3, 0}, {0.0, 0.5, 0}};
  s.faces = {{0, 1, 2}};
  s.delta = {1, 0, 0, 0, 0.5, 0, 0.3, -0.2, 0};
  s.view = LookAtView({0.2, 0.1, 3}, {0, 0, 0}, 64, 80);
  AddPointLight(Eigen::Vector3d(0.5, 0.5, 3), 10.0, &s.view);
  RenderOptions options;
  options.spp = 64;
  options.bounces = 1;
  CheckScene(s, options, 2e-2, 0.05);
}

TEST(EdgeSamplingTest, InteriorOnlyTilt) {
  EdgeScene s = TiltingPlaneScene();
  AddPointLight(Eigen::Vector3d(0.5, 0.5, 1), 10.0, &s.view);
  RenderOptions options;
  options.spp = 4;
  options.bounces = 1;
  CheckScene(s, options, 1e-4, 0.01);
}

TEST(EdgeSamplingTest, InteriorOnlyEnvironment) {
  EdgeScene s = TiltingPlaneScene();
  s.view.environment = &PatchEnvironment();
  RenderOptions options;
  options.spp = 16;
  options.bounces = 1;
  // Without shadows the environment is lit by light sampling alone, whose directions do not
  // depend on the normal: the finite difference then differentiates exactly the estimator the
  // analytic derivative differentiates (with shadows, BSDF-sampled directions turn with the
  // normal and the two agree only in expectation).
  options.effects.shadows = false;
  CheckScene(s, options, 1e-4, 0.01);
}

// Two large faces meeting at a ridge in view: the crease (flat shading differs on either side)
// is the only boundary; the ridge vertices move.
EdgeScene TentScene() {
  EdgeScene s;
  s.positions = {{-3, -3, 0}, {0, -3, 0.5}, {0, 3, 0.5}, {-3, 3, 0}, {3, -3, 0}, {3, 3, 0}};
  s.faces = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}};
  s.delta.assign(18, 0.0);
  s.delta[3 * 1 + 0] = 1.0;
  s.delta[3 * 2 + 0] = 0.5;
  s.delta[3 * 1 + 2] = 0.5;
  s.view = LookAtView({0.5, 0.3, 3}, {0, 0, 0.3}, 64, 100);
  return s;
}

TEST(EdgeSamplingTest, CreaseUnderPointLight) {
  EdgeScene s = TentScene();
  AddPointLight(Eigen::Vector3d(2, -1, 3), 10.0, &s.view);
  RenderOptions options;
  options.spp = 64;
  options.bounces = 1;
  CheckScene(s, options, 3e-2, 0.05);
}

// Under an environment light each camera sample that crosses the crease carries a one-sample
// light estimate, so the finite difference converges slowly: 256 spp gives ~3% block error
// (2048 spp: 2.6%). Before the sampler's index shuffle was made nonlinear (rng.h), the light
// sample was tied to the sub-pixel position and the finite difference stalled at 6% for any spp.
TEST(EdgeSamplingTest, CreaseUnderEnvironment) {
  EdgeScene s = TentScene();
  s.view.environment = &PatchEnvironment();
  RenderOptions options;
  options.spp = 256;
  options.bounces = 1;
  options.effects.shadows = false;
  CheckScene(s, options, 3e-2, 0.05);
}

}  // namespace
}  // namespace sft
