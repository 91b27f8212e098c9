// The UV-texture material in the renderer: derivatives with respect to its albedo and roughness
// texels against central finite differences (direct light and one indirect bounce), and the
// known answer that a constant UV texture renders and differentiates like the constant
// mesh-colors material.
//
// Finite differences render θ ± h·δ with the same seeds and detached sampling
// (RenderOptions::sampling_material = the material at θ), as tests/render/derivatives_test.cc
// does for mesh colors: both renders follow the same paths, and texels move no geometry and no
// visibility (a bilinear texture is continuous inside faces; no texel-boundary terms exist for
// it), so the estimator is smooth in the texels — linear in the albedo texels, since each hit's
// albedo is Σ w·texel with fixed bilinear weights w. The only errors are the central difference's
// O(h²) truncation (zero for albedo) and float32 rounding of the images and Jacobian entries
// (~6e-8 relative, divided by 2h). Tolerance: 2e-3 relative L2 over the image, as for mesh colors;
// measured values are printed.
#include <glog/logging.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/render/render.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

constexpr int kRes = 32;     // image width and height.
constexpr int kTexture = 8;  // texture width and height (texels).

// The bunny seen from the front, a point light near the camera; UVs by planar projection along z
// over the bounding box (continuous across every edge: no seams).
struct Fixture {
  TriMesh mesh;
  std::unique_ptr<RenderScene> scene;
  std::vector<Eigen::Vector2d> corner_uvs;
  ViewSetup view;

  Fixture() {
    CHECK(ReadMesh(testing::DataDir() + "/meshes/bunny_watertight_5k.obj", &mesh).ok());
    scene = std::make_unique<RenderScene>(mesh);
    Eigen::Vector3d lo, hi;
    MeshBounds(mesh, &lo, &hi);
    for (const Eigen::Vector3i& face : scene->faces()) {
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d& p = scene->positions()[face[k]];
        corner_uvs.emplace_back((p.x() - lo.x()) / (hi.x() - lo.x()),
                                (p.y() - lo.y()) / (hi.y() - lo.y()));
      }
    }
    // Camera at (0.3, 0.5, 3.5) looking at the origin (the bunny is y-up, ~[-1, 1]).
    view = testing::LookAtView(Eigen::Vector3d(0.3, 0.5, 3.5), Eigen::Vector3d::Zero(), kRes, 40,
                               Eigen::Vector3d::UnitY());
    PointLight light;
    light.position = Eigen::Vector3d(0.5, 1.0, 3.0);
    light.intensity = Eigen::Vector3d(6.0, 5.0, 4.0);
    light.light_index = 0;
    view.point_lights.push_back(light);
  }
};

Fixture& SharedFixture() {
  static Fixture* fixture = new Fixture();
  return *fixture;
}

// Random kTexture² textures: albedo in [0.2, 0.8], roughness within ±20% of `roughness`.
Material RandomUvMaterial(const Fixture& fx, double roughness, double specular) {
  Material m;
  m.specular = specular;
  m.uv.corner_uvs = fx.corner_uvs;
  m.uv.albedo = UvTexture(kTexture, kTexture, 3);
  m.uv.roughness = UvTexture(kTexture, kTexture, 1);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.2, 0.8);
  for (double& v : m.uv.albedo.values()) v = u(rng);
  for (double& v : m.uv.roughness.values()) v = roughness * (0.8 + 0.4 * (u(rng) - 0.2) / 0.6);
  return m;
}

struct Case {
  const char* name;
  ParameterKind kind;
  int bounces;
  double roughness;
  double specular;
};

class UvTextureDerivativesTest : public ::testing::TestWithParam<Case> {};

TEST_P(UvTextureDerivativesTest, MatchesCentralDifferences) {
  const Case& c = GetParam();
  Fixture& fx = SharedFixture();
  const Material base = RandomUvMaterial(fx, c.roughness, c.specular);
  RenderOptions options;
  options.spp = 4;
  options.bounces = c.bounces;
  options.seed = 3;
  options.sampling_material = &base;

  const ParameterLayout layout = MakeParameterLayout(*fx.scene, base, 1);
  ASSERT_EQ(layout.num_albedo_texels, kTexture * kTexture);
  ASSERT_EQ(layout.num_roughness_texels, kTexture * kTexture);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> delta(layout.size(), 0.0);
  for (int i = 0; i < layout.size(); ++i) {
    if (layout.KindOf(i) == c.kind) delta[i] = u(rng);
  }
  // Albedo enters linearly (h only limits float rounding); roughness is smooth on the scale of α.
  const double h = c.kind == ParameterKind::kRoughness ? 1e-3 * c.roughness : 1e-3;
  auto perturbed_render = [&](double sign) {
    Material m = base;
    for (size_t i = 0; i < m.AlbedoValues().size(); ++i) {
      m.AlbedoValues()[i] += sign * h * delta[layout.AlbedoOffset() + i];
    }
    for (size_t i = 0; i < m.RoughnessValues().size(); ++i) {
      m.RoughnessValues()[i] += sign * h * delta[layout.RoughnessOffset() + i];
    }
    Image image;
    RenderView(*fx.scene, m, fx.view, options, &image);
    return image;
  };
  const Image plus = perturbed_render(+1.0);
  const Image minus = perturbed_render(-1.0);

  DerivativeRequest request;
  request.params = ParameterSelection::Only(c.kind);
  request.jacobian_rows = true;
  Image image;
  DerivativeOutput out;
  RenderViewWithDerivatives(*fx.scene, base, fx.view, options, request, 1, &image, &out);

  double err2 = 0.0, ref2 = 0.0;
  int blended_pixels = 0;  // pixels whose rows hold more than one texel (bilinear blending).
  for (int p = 0; p < kRes * kRes; ++p) {
    Eigen::Vector3d analytic = Eigen::Vector3d::Zero();
    const uint64_t begin = out.rows.offsets[p], end = out.rows.offsets[p + 1];
    for (uint64_t e = begin; e < end; ++e) {
      const JacobianEntry& entry = out.rows.entries[e];
      ASSERT_EQ(layout.KindOf(entry.param), c.kind);
      for (int k = 0; k < 3; ++k) analytic[k] += entry.d[k] * delta[entry.param];
    }
    const uint64_t per_texel = c.kind == ParameterKind::kAlbedo ? 3 : 1;
    blended_pixels += end - begin > per_texel ? 1 : 0;
    for (int k = 0; k < 3; ++k) {
      const double fd = (plus.data[4 * p + k] - minus.data[4 * p + k]) / (2.0 * h);
      err2 += (analytic[k] - fd) * (analytic[k] - fd);
      ref2 += fd * fd;
    }
  }
  ASSERT_GT(ref2, 0.0) << "the perturbation does not change the image";
  const double rel = std::sqrt(err2 / ref2);
  std::printf("%s: relative L2 error %.2e, %d pixels blend several texels\n", c.name, rel,
              blended_pixels);
  EXPECT_GT(blended_pixels, 100) << "the rows do not carry the bilinear texels";
  EXPECT_LT(rel, 2e-3) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    Texels, UvTextureDerivativesTest,
    ::testing::Values(Case{"albedo_direct", ParameterKind::kAlbedo, 1, 0.4, 0.3},
                      Case{"albedo_1_bounce", ParameterKind::kAlbedo, 2, 0.4, 0.3},
                      Case{"roughness_direct", ParameterKind::kRoughness, 1, 0.3, 0.5},
                      Case{"roughness_1_bounce", ParameterKind::kRoughness, 2, 0.3, 0.5}),
    [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.name); });

// A constant UV texture (any size) is the constant material: the image matches the mesh-colors
// render with the same seed, and the derivative with respect to all texels together (Σ over the
// texels of the rows) matches the mesh-colors one. Not bit-identical: the bilinear weights' sum
// and products round (1 ulp of the albedo), which moves pixel values by ~1e-16 relative before
// float32 storage; lobe choices and paths are the same. Bound: 1e-6 relative per pixel.
TEST(UvTextureRenderTest, ConstantTextureMatchesConstantMeshColors) {
  Fixture& fx = SharedFixture();
  const int faces = static_cast<int>(fx.scene->faces().size());
  const Eigen::Vector3d albedo(0.6, 0.45, 0.3);
  const Material colors = ConstantMaterial(faces, albedo, 0.35, 0.3);
  Material uv;
  uv.specular = 0.3;
  uv.uv.corner_uvs = fx.corner_uvs;
  uv.uv.albedo = UvTexture(5, 3, 3);
  for (int k = 0; k < uv.uv.albedo.num_texels(); ++k) {
    for (int ch = 0; ch < 3; ++ch) uv.uv.albedo.texel(k)[ch] = albedo[ch];
  }
  uv.uv.roughness = UvTexture(5, 3, 1, 0.35);
  RenderOptions options;
  options.spp = 4;
  options.bounces = 2;
  options.seed = 7;
  DerivativeRequest request;
  request.params = ParameterSelection::Only(ParameterKind::kAlbedo);
  request.params.roughness = true;
  request.jacobian_rows = true;
  Image a, b;
  DerivativeOutput da, db;
  RenderViewWithDerivatives(*fx.scene, colors, fx.view, options, request, 1, &a, &da);
  RenderViewWithDerivatives(*fx.scene, uv, fx.view, options, request, 1, &b, &db);
  ASSERT_EQ(a.data.size(), b.data.size());
  double lit = 0.0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    EXPECT_NEAR(b.data[i], a.data[i], 1e-6 * std::abs(a.data[i]) + 1e-12) << i;
    lit += a.data[i];
  }
  EXPECT_GT(lit, 0.0);
  // Σ over texels of each pixel's rows, per kind and channel.
  auto sums = [](const DerivativeOutput& d, int p) {
    Eigen::Matrix<double, 4, 3> s = Eigen::Matrix<double, 4, 3>::Zero();
    for (uint64_t e = d.rows.offsets[p]; e < d.rows.offsets[p + 1]; ++e) {
      const JacobianEntry& entry = d.rows.entries[e];
      const ParameterKind kind = d.layout.KindOf(entry.param);
      const int row =
          kind == ParameterKind::kRoughness ? 3 : (entry.param - d.layout.AlbedoOffset()) % 3;
      for (int k = 0; k < 3; ++k) s(row, k) += entry.d[k];
    }
    return s;
  };
  for (int p = 0; p < kRes * kRes; ++p) {
    const Eigen::Matrix<double, 4, 3> sa = sums(da, p), sb = sums(db, p);
    EXPECT_LE((sa - sb).cwiseAbs().maxCoeff(), 1e-5 * sa.cwiseAbs().maxCoeff() + 1e-12) << p;
  }
}

}  // namespace
}  // namespace sft
