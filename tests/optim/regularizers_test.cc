// The proximal smoothing hook of AddRegularizers (src/optim/regularizers.h): one block per vertex
// with √μ·(I + λL) only when vertices are active, anchored at `rest`, and RegularizerOptions'
// checks of μ and λ.
#include "src/optim/regularizers.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

struct Scene {
  TriMesh mesh;
  Material material;
  SceneParameters params;
};

void MakeScene(Scene* s) {
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &s->mesh).ok());
  s->material = ConstantMaterial(static_cast<int>(s->mesh.n_faces()), {0.5, 0.5, 0.5}, 0.5, 0.0);
  std::vector<Eigen::Vector3d> positions;
  for (TriMesh::VertexHandle v : s->mesh.vertices()) {
    const TriMesh::Point& p = s->mesh.point(v);
    positions.emplace_back(p[0], p[1], p[2]);
  }
  s->params = SceneParameters(positions, s->material, 0);
}

// Only the proximal term on: the options that add other regularizers are zeroed.
RegularizerOptions ProximalOnly(double mu, double lambda) {
  RegularizerOptions options;
  options.laplacian_weight = 0.0;
  options.orientation_weight = 0.0;
  options.proximal_weight = mu;
  options.proximal_lambda = lambda;
  return options;
}

TEST(RegularizersTest, ProximalTermOnlyWithActiveVertices) {
  Scene s;
  MakeScene(&s);
  ActiveParameters texture;  // albedo and roughness.
  ceres::Problem none;
  AddRegularizers(s.mesh, texture, ProximalOnly(4.0, 25.0), ParameterBounds(), s.material,
                  &s.params, &none);
  EXPECT_EQ(none.NumResidualBlocks(), 0);
  ActiveParameters geometry;
  geometry.vertices = true;
  geometry.albedo = geometry.roughness = false;
  ceres::Problem off;
  AddRegularizers(s.mesh, geometry, ProximalOnly(0.0, 25.0), ParameterBounds(), s.material,
                  &s.params, &off);
  EXPECT_EQ(off.NumResidualBlocks(), 0);
  ceres::Problem on;
  AddRegularizers(s.mesh, geometry, ProximalOnly(4.0, 25.0), ParameterBounds(), s.material,
                  &s.params, &on);
  EXPECT_EQ(on.NumResidualBlocks(), static_cast<int>(s.mesh.n_vertices()));
  // Anchored at `rest` (= the parameters here): zero cost; a translation of one vertex by d costs
  // ½μ((1 + λ·deg)² + deg·λ²)d² (its own residual and its neighbours').
  double cost = -1.0;
  ASSERT_TRUE(on.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr));
  EXPECT_EQ(cost, 0.0);
  const int degree = static_cast<int>(s.mesh.valence(s.mesh.vertex_handle(0)));
  const double d = 0.01;
  s.params.data()[0] += d;
  ASSERT_TRUE(on.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr));
  const double expected =
      0.5 * 4.0 * (std::pow(1.0 + 25.0 * degree, 2) + degree * 25.0 * 25.0) * d * d;
  EXPECT_NEAR(cost, expected, 1e-9 * expected);
}

TEST(RegularizersTest, CheckRejectsBadProximalOptions) {
  std::string why;
  EXPECT_TRUE(ProximalOnly(1e3, 0.0).Check(&why)) << why;
  EXPECT_FALSE(ProximalOnly(-1.0, 25.0).Check(&why));
  EXPECT_FALSE(ProximalOnly(std::numeric_limits<double>::infinity(), 25.0).Check(&why));
  EXPECT_FALSE(ProximalOnly(1.0, -1.0).Check(&why));
  EXPECT_FALSE(ProximalOnly(1.0, std::nan("")).Check(&why));
  EXPECT_NE(why.find("proximal"), std::string::npos);
}

}  // namespace
}  // namespace sft
