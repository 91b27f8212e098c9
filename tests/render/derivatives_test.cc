// Derivatives of rendered images with respect to albedo texels, roughness texels, the specular
// weight, light intensity scales and fitted environment texels, against central finite
// differences (issue 3; environment texels issue 22).
//
// The finite differences render θ ± h·δ with the same seeds and with detached sampling
// (RenderOptions::sampling_material = the material at θ), so both renders follow exactly the same
// paths and the difference quotient differentiates the same estimator the analytic derivative
// differentiates. These parameters move no geometry, so there are no visibility discontinuities,
// and the estimator is a smooth function of them: the only errors are the O(h²) truncation of the
// central difference and float32 storage (images and Jacobian entries, ~6e-8 relative, divided by
// 2h); environment texels enter linearly too, their importance sampling detached like the
// material's. Tolerance: 2e-3 relative L2 error over the image. Measured: ≲ 1.2e-4 for albedo,
// specular and light scales (h = 1e-3); up to ~1e-3 for roughness, whose small steps (h = 1e-3·r,
// needed at r = 0.05 where D changes on the scale of α = r²) make float32 rounding of the images
// the dominant error.
#include <glog/logging.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/render/bsdf.h"
#include "src/render/render.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

struct Case {
  const char* name;
  ParameterKind kind;
  int bounces;
  bool shadows;
  bool point_light;
  bool environment;
  double roughness;
  double specular;
  FresnelMode fresnel = FresnelMode::kConstant;
};

class DerivativesTest : public ::testing::TestWithParam<Case> {};

// The scene: the bunny seen from above-front, a point light near the camera, optionally a
// studio-like environment with a bright patch.
struct Fixture {
  TriMesh mesh;
  std::unique_ptr<RenderScene> scene;
  Image env_image;
  ViewSetup view;

  Fixture() {
    CHECK(ReadMesh(testing::DataDir() + "/meshes/bunny_watertight_5k.obj", &mesh).ok());
    scene = std::make_unique<RenderScene>(mesh);
    env_image = Image(32, 16, 3, 0.3f);
    for (int y = 2; y < 6; ++y) {
      for (int x = 10; x < 14; ++x) env_image.at(x, y, 0) = env_image.at(x, y, 1) = 6.f;
    }
    view.camera.model = CameraModel::kPinhole;
    view.camera.width = view.camera.height = 32;
    view.camera.params = {40, 40, 16, 16};
    // Camera at (0.3, 0.5, 3.5) looking at the origin (bunny is y-up, ~[-1,1]).
    const Eigen::Vector3d c(0.3, 0.5, 3.5);
    const Eigen::Vector3d fwd = (-c).normalized();
    const Eigen::Vector3d right = fwd.cross(Eigen::Vector3d(0, 1, 0)).normalized();
    const Eigen::Vector3d down = fwd.cross(right);
    Eigen::Matrix3d r;
    r.row(0) = right;
    r.row(1) = down;
    r.row(2) = fwd;
    view.cam_from_world.rotation = Eigen::Quaterniond(r);
    view.cam_from_world.translation = -(r * c);
  }
};

Fixture& SharedFixture() {
  static Fixture* fixture = new Fixture();
  return *fixture;
}

// Random material with spatial variation: resolution-2 mesh colors, albedo in [0.2, 0.8].
Material RandomMaterial(int faces, double roughness, double specular, FresnelMode fresnel) {
  Material m = ConstantMaterial(faces, Eigen::Vector3d::Constant(0.5), roughness, specular, 2);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.2, 0.8);
  for (double& v : m.albedo.values()) v = u(rng);
  for (double& v : m.roughness.values()) v = roughness * (0.8 + 0.4 * (u(rng) - 0.2) / 0.6);
  m.fresnel = fresnel;
  return m;
}

TEST_P(DerivativesTest, MatchesCentralDifferences) {
  const Case& c = GetParam();
  Fixture& fx = SharedFixture();
  const int faces = static_cast<int>(fx.mesh.n_faces());
  const Material base = RandomMaterial(faces, c.roughness, c.specular, c.fresnel);
  const double light_scale_base = 1.0;
  std::unique_ptr<EnvironmentMap> env;
  // Environment texels: the perturbed renders sample directions from the map at θ (detached
  // sampling, RenderOptions::sampling_environment), as the material's.
  const EnvironmentMap sampling_env(fx.env_image, Eigen::Matrix3d::Identity(), 1.0);
  Image env_image = fx.env_image;
  auto make_view = [&](double point_scale, double env_scale) {
    ViewSetup view = fx.view;
    if (c.point_light) {
      PointLight light;
      light.position = Eigen::Vector3d(0.5, 1.0, 3.0);
      light.intensity = Eigen::Vector3d(6.0, 5.0, 4.0) * point_scale;
      light.light_index = 0;
      view.point_lights.push_back(light);
    }
    if (c.environment) {
      env = std::make_unique<EnvironmentMap>(env_image, Eigen::Matrix3d::Identity(), env_scale);
      view.environment = env.get();
      view.environment_light_index = 1;
      view.environment_background = c.kind == ParameterKind::kEnvironment;
    }
    return view;
  };

  RenderOptions options;
  options.spp = 4;
  options.bounces = c.bounces;
  options.effects.shadows = c.shadows;
  options.seed = 3;
  options.sampling_material = &base;
  if (c.environment) options.sampling_environment = &sampling_env;

  // Direction δ: random over the selected kind.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ParameterLayout layout;
  layout.num_vertices = static_cast<int>(fx.scene->positions().size());
  layout.num_albedo_texels = base.albedo.num_texels();
  layout.num_roughness_texels = base.roughness.num_texels();
  layout.num_lights = 2;
  if (c.kind == ParameterKind::kEnvironment) {
    layout.num_environment_texels = fx.env_image.width * fx.env_image.height;
    layout.environment_light = 1;
  }
  std::vector<double> delta(layout.size(), 0.0);
  for (int i = 0; i < layout.size(); ++i) {
    if (layout.KindOf(i) == c.kind) delta[i] = u(rng);
  }
  // Step sizes: albedo and light scales enter linearly (h only limits float rounding); roughness
  // and specular are smooth at the scale of α.
  const double h = c.kind == ParameterKind::kRoughness ? 1e-3 * c.roughness : 1e-3;

  auto perturbed_render = [&](double sign) {
    Material m = base;
    for (int t = 0; t < m.albedo.num_texels() * 3; ++t) {
      m.albedo.values()[t] += sign * h * delta[layout.AlbedoOffset() + t];
    }
    for (int t = 0; t < m.roughness.num_texels(); ++t) {
      m.roughness.values()[t] += sign * h * delta[layout.RoughnessOffset() + t];
    }
    m.specular += sign * h * delta[layout.SpecularIndex()];
    env_image = fx.env_image;
    for (int t = 0; t < layout.num_environment_texels; ++t) {
      for (int k = 0; k < 3; ++k) {
        env_image.at(t % env_image.width, t / env_image.width, k) +=
            static_cast<float>(sign * h * delta[layout.EnvironmentOffset() + 3 * t + k]);
      }
    }
    const ViewSetup view = make_view(light_scale_base + sign * h * delta[layout.LightOffset()],
                                     light_scale_base + sign * h * delta[layout.LightOffset() + 1]);
    Image image;
    RenderView(*fx.scene, m, view, options, &image);
    return image;
  };
  const Image plus = perturbed_render(+1.0);
  const Image minus = perturbed_render(-1.0);
  env_image = fx.env_image;

  // Analytic: rows and adjoint from one render at θ.
  const ViewSetup view = make_view(1.0, 1.0);
  Image weights(32, 32, 3);
  for (float& w : weights.data) w = static_cast<float>(u(rng));
  DerivativeRequest request;
  request.params = ParameterSelection::Only(c.kind);
  request.jacobian_rows = true;
  request.adjoint_weights = &weights;
  Image image, reference;
  DerivativeOutput out;
  RenderViewWithDerivatives(*fx.scene, base, view, options, request, layout, &image, &out);
  RenderView(*fx.scene, base, view, options, &reference);
  EXPECT_EQ(image.data, reference.data) << "derivative pass changed the image";

  double err2 = 0.0, ref2 = 0.0, weighted_fd = 0.0, weighted_rows = 0.0, weighted_abs = 0.0;
  for (int p = 0; p < 32 * 32; ++p) {
    Eigen::Vector3d analytic = Eigen::Vector3d::Zero();
    for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
      const JacobianEntry& entry = out.rows.entries[e];
      ASSERT_EQ(layout.KindOf(entry.param), c.kind);
      for (int k = 0; k < 3; ++k) analytic[k] += entry.d[k] * delta[entry.param];
    }
    for (int k = 0; k < 3; ++k) {
      const double fd = (plus.data[4 * p + k] - minus.data[4 * p + k]) / (2.0 * h);
      err2 += (analytic[k] - fd) * (analytic[k] - fd);
      ref2 += fd * fd;
      weighted_fd += weights.data[3 * p + k] * fd;
      weighted_rows += weights.data[3 * p + k] * analytic[k];
      weighted_abs += std::abs(weights.data[3 * p + k] * analytic[k]);
    }
  }
  ASSERT_GT(ref2, 0.0) << "the perturbation does not change the image";
  const double rel = std::sqrt(err2 / ref2);
  double adjoint = 0.0;
  for (int i = 0; i < layout.size(); ++i) adjoint += out.gradient[i] * delta[i];
  std::printf("%s: relative L2 error %.2e, adjoint %.6g, rows %.6g, FD %.6g\n", c.name, rel,
              adjoint, weighted_rows, weighted_fd);
  EXPECT_LT(rel, 2e-3) << c.name;
  // The adjoint gradient is the rows' weighted sum, up to float32 rounding of the entries.
  EXPECT_NEAR(adjoint, weighted_rows, 1e-5 * weighted_abs + 1e-12) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    Effects, DerivativesTest,
    ::testing::Values(
        Case{"albedo_direct", ParameterKind::kAlbedo, 1, true, true, false, 0.4, 0.3},
        Case{"albedo_no_shadows", ParameterKind::kAlbedo, 1, false, true, false, 0.4, 0.3},
        Case{"albedo_2_bounces", ParameterKind::kAlbedo, 2, true, true, false, 0.4, 0.3},
        Case{"albedo_3_bounces_env", ParameterKind::kAlbedo, 3, true, true, true, 0.4, 0.3},
        Case{"albedo_env", ParameterKind::kAlbedo, 1, true, false, true, 0.5, 0.0},
        Case{"roughness_0.05", ParameterKind::kRoughness, 1, true, true, false, 0.05, 0.5},
        Case{"roughness_0.3_2_bounces", ParameterKind::kRoughness, 2, true, true, false, 0.3, 0.5},
        Case{"roughness_1_env", ParameterKind::kRoughness, 2, true, true, true, 1.0, 0.5},
        Case{"specular_direct", ParameterKind::kSpecular, 1, true, true, false, 0.3, 0.4},
        Case{"specular_2_bounces_env", ParameterKind::kSpecular, 2, true, true, true, 0.3, 0.4},
        Case{"specular_schlick", ParameterKind::kSpecular, 2, true, true, false, 0.3, 0.4,
             FresnelMode::kSchlick},
        Case{"light_point_2_bounces", ParameterKind::kLight, 2, true, true, false, 0.3, 0.3},
        Case{"light_env_and_point", ParameterKind::kLight, 2, true, true, true, 0.3, 0.3},
        // Environment texels: light- and BSDF-sampled (MIS), through two bounces, and the
        // background the camera sees; without shadows light sampling alone.
        Case{"environment_2_bounces", ParameterKind::kEnvironment, 2, true, true, true, 0.3, 0.4},
        Case{"environment_no_shadows", ParameterKind::kEnvironment, 1, false, false, true, 0.5,
             0.3}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string name = info.param.name;
      for (char& ch : name) {
        if (ch == '.') ch = '_';
      }
      return name;
    });

// The GGX α-derivatives used by EvalBsdfDerivatives against central differences.
TEST(BsdfDerivativeTest, GgxAlphaDerivatives) {
  for (double alpha : {0.01, 0.1, 0.5, 1.0}) {
    for (double cos_t : {0.05, 0.5, 0.99}) {
      const double h = 1e-6 * alpha;
      const double fd_d = (GgxD(cos_t, alpha + h) - GgxD(cos_t, alpha - h)) / (2 * h);
      const double fd_g = (GgxG1(cos_t, alpha + h) - GgxG1(cos_t, alpha - h)) / (2 * h);
      EXPECT_NEAR(GgxDAlphaDerivative(cos_t, alpha), fd_d, 1e-5 * std::abs(fd_d) + 1e-6);
      EXPECT_NEAR(GgxG1AlphaDerivative(cos_t, alpha), fd_g, 1e-5 * std::abs(fd_g) + 1e-9);
    }
  }
}

// Vertex derivatives are accepted; the edge-sampling ratios are checked and named when out of
// range.
TEST(DerivativeRequestTest, VertexDerivativesAndEdgeRatios) {
  DerivativeRequest request;
  request.params = ParameterSelection::Only(ParameterKind::kVertex);
  request.jacobian_rows = true;
  std::string why;
  EXPECT_TRUE(request.Check(&why)) << why;
  request.primary_edge_ratio = 0.0;  // edge terms off: allowed.
  request.shadow_edge_ratio = 16.0;  // the upper end: allowed.
  request.texel_edge_ratio = 0.0;
  EXPECT_TRUE(request.Check(&why)) << why;
  for (double bad : {-0.5, 16.5, std::nan("")}) {
    DerivativeRequest primary = request;
    primary.primary_edge_ratio = bad;
    EXPECT_FALSE(primary.Check(&why)) << bad;
    EXPECT_NE(why.find("primary-edge-ratio"), std::string::npos) << why;
    DerivativeRequest shadow = request;
    shadow.shadow_edge_ratio = bad;
    EXPECT_FALSE(shadow.Check(&why)) << bad;
    EXPECT_NE(why.find("shadow-edge-ratio"), std::string::npos) << why;
    DerivativeRequest texel = request;
    texel.texel_edge_ratio = bad;
    EXPECT_FALSE(texel.Check(&why)) << bad;
    EXPECT_NE(why.find("texel-edge-ratio"), std::string::npos) << why;
  }
  for (double bad : {-1.0, 16.5, std::nan("")}) {
    DerivativeRequest secondary = request;
    secondary.secondary_edge_samples = bad;
    EXPECT_FALSE(secondary.Check(&why)) << bad;
    EXPECT_NE(why.find("secondary-edge-samples"), std::string::npos) << why;
  }
}

}  // namespace
}  // namespace sft
