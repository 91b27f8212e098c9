// Mesh-colour transfer across a topology change (src/init/texel_transfer.h): onto the same mesh
// it is exact; a smooth function of position carried from a coarse sphere to its midpoint
// subdivision stays within the texel-size error; the material's other fields are copied.
#include "src/init/texel_transfer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "src/init/remesh.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

TriMesh ReadFixture(const std::string& name) {
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(testing::DataDir() + "/meshes/" + name, &mesh).ok()) << name;
  return mesh;
}

// Each face split into four at its edge midpoints (the same surface, 4x the faces).
TriMesh MidpointSubdivision(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  std::map<std::pair<int, int>, int> midpoint;
  auto mid = [&](int a, int b) {
    const std::pair<int, int> key(std::min(a, b), std::max(a, b));
    auto it = midpoint.find(key);
    if (it != midpoint.end()) return it->second;
    positions.push_back(0.5 * (positions[a] + positions[b]));
    return midpoint[key] = static_cast<int>(positions.size()) - 1;
  };
  TriMesh out;
  std::vector<TriMesh::VertexHandle> v;
  std::vector<Eigen::Vector3i> fine;
  for (const Eigen::Vector3i& f : faces) {
    const int ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
    fine.insert(fine.end(), {{f[0], ab, ca}, {ab, f[1], bc}, {ca, bc, f[2]}, {ab, bc, ca}});
  }
  for (const Eigen::Vector3d& p : positions) v.push_back(out.add_vertex({p.x(), p.y(), p.z()}));
  for (const Eigen::Vector3i& f : fine) out.add_face(v[f[0]], v[f[1]], v[f[2]]);
  return out;
}

// Mesh colours whose texels hold g(texel centre) for g(p) = 0.5 + 0.5·p (3 channels).
MeshColors PositionColors(const TriMesh& mesh, int r) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  MeshColors colors(static_cast<int>(faces.size()), r, 3);
  int k = 0;
  for (const Eigen::Vector3i& f : faces) {
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; j <= r - i; ++j, ++k) {
        const Eigen::Vector2d c = MeshColors::TexelCenter(r, i, j);
        const Eigen::Vector3d p = positions[f[0]] + c.x() * (positions[f[1]] - positions[f[0]]) +
                                  c.y() * (positions[f[2]] - positions[f[0]]);
        for (int ch = 0; ch < 3; ++ch) colors.texel(k)[ch] = 0.5 + 0.5 * p[ch];
      }
    }
  }
  return colors;
}

TEST(TexelTransferTest, SameMeshReproducesEveryTexel) {
  const TriMesh sphere = ReadFixture("icosphere_r1_320f.obj");
  for (int r : {0, 1, 4, 7}) {
    SCOPED_TRACE(r);
    MeshColors colors(320, r, 2);
    std::mt19937 rng(r);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    for (double& v : colors.values()) v = uniform(rng);
    MeshColors out;
    const Status status = TransferMeshColors(sphere, colors, sphere, r, &out);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(out.num_faces(), 320);
    EXPECT_EQ(out.resolution(), r);
    EXPECT_EQ(out.values(), colors.values());
  }
}

// Old texel values are g at the old texel centres, g(p) = 0.5 + 0.5·p, so each channel has
// gradient norm 0.5. A new texel centre x lies on the old surface (midpoint subdivision), in an
// old texel whose region extends at most (2/3)(|e1| + |e2|)/r from its centre (header), so the
// transferred value is within 0.5·(2/3)(|e1| + |e2|)/r of g(x); with the longest old edge
// ℓ = 0.41 and r = 4 that is 0.069 per channel. The mean error is far smaller (most new centres
// are nearer to their old texel's centre than its farthest point).
TEST(TexelTransferTest, SmoothFunctionOntoTheSubdividedMesh) {
  const TriMesh coarse = ReadFixture("icosphere_r1_320f.obj");
  const TriMesh fine = MidpointSubdivision(coarse);
  ASSERT_EQ(fine.n_faces(), 4 * 320u);
  const int old_r = 4, new_r = 3;
  double longest_edge = 0.0;
  for (TriMesh::EdgeHandle e : coarse.edges()) {
    longest_edge = std::max(longest_edge, coarse.calc_edge_length(e));
  }
  const double bound = 0.5 * (2.0 / 3.0) * (2.0 * longest_edge) / old_r;
  MeshColors out;
  const Status status =
      TransferMeshColors(coarse, PositionColors(coarse, old_r), fine, new_r, &out);
  ASSERT_TRUE(status.ok()) << status.message();
  const MeshColors exact = PositionColors(fine, new_r);
  ASSERT_EQ(out.values().size(), exact.values().size());
  double max_error = 0.0, sum_error = 0.0;
  for (size_t n = 0; n < exact.values().size(); ++n) {
    const double error = std::abs(out.values()[n] - exact.values()[n]);
    max_error = std::max(max_error, error);
    sum_error += error;
  }
  const double mean_error = sum_error / exact.values().size();
  std::printf("transfer error: max %.4f mean %.4f, bound %.4f\n", max_error, mean_error, bound);
  EXPECT_LE(max_error, bound);
  EXPECT_LE(mean_error, 0.5 * bound);
}

TEST(TexelTransferTest, MaterialCarriesAlbedoRoughnessAndCopiesTheRest) {
  const TriMesh coarse = ReadFixture("icosphere_r1_320f.obj");
  const TriMesh fine = MidpointSubdivision(coarse);
  Material material = ConstantMaterial(320, Eigen::Vector3d(0.2, 0.4, 0.6), 0.3, 0.25, 2);
  material.fresnel = FresnelMode::kSchlick;
  Material out;
  const Status status = TransferMaterial(coarse, material, fine, 5, &out);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(out.specular, 0.25);
  EXPECT_EQ(out.fresnel, FresnelMode::kSchlick);
  ASSERT_EQ(out.albedo.num_faces(), 1280);
  EXPECT_EQ(out.albedo.resolution(), 5);
  EXPECT_EQ(out.albedo.channels(), 3);
  ASSERT_EQ(out.roughness.num_faces(), 1280);
  EXPECT_EQ(out.roughness.channels(), 1);
  for (int k = 0; k < out.albedo.num_texels(); ++k) {
    ASSERT_EQ(out.albedo.texel(k)[1], 0.4) << k;
    ASSERT_EQ(out.roughness.texel(k)[0], 0.3) << k;
  }
}

// Onto a remeshed sphere (vertices on the old surface, texel centres up to a sagitta inside it)
// the error adds the gradient times that distance; the bound of the previous test with the
// remeshed faces' sagitta, ℓ²/8 ≤ 0.005, added.
TEST(TexelTransferTest, SmoothFunctionOntoARemeshedSphere) {
  const TriMesh coarse = ReadFixture("icosphere_r1_320f.obj");
  RemeshOptions options;
  options.method = RemeshMethod::kIsotropic;
  options.target_edge_length = 0.15;
  TriMesh remeshed;
  ASSERT_TRUE(Remesh(coarse, options, &remeshed, nullptr).ok());
  const int old_r = 4, new_r = 2;
  double longest_edge = 0.0;
  for (TriMesh::EdgeHandle e : coarse.edges()) {
    longest_edge = std::max(longest_edge, coarse.calc_edge_length(e));
  }
  const double bound = 0.5 * ((2.0 / 3.0) * (2.0 * longest_edge) / old_r + 0.005);
  MeshColors out;
  ASSERT_TRUE(
      TransferMeshColors(coarse, PositionColors(coarse, old_r), remeshed, new_r, &out).ok());
  const MeshColors exact = PositionColors(remeshed, new_r);
  double max_error = 0.0;
  for (size_t n = 0; n < exact.values().size(); ++n) {
    max_error = std::max(max_error, std::abs(out.values()[n] - exact.values()[n]));
  }
  EXPECT_LE(max_error, bound);
}

TEST(TexelTransferTest, Errors) {
  const TriMesh sphere = ReadFixture("icosphere_r1_320f.obj");
  MeshColors out;
  EXPECT_FALSE(TransferMeshColors(sphere, MeshColors(319, 2, 3), sphere, 2, &out).ok());
  EXPECT_FALSE(TransferMeshColors(sphere, MeshColors(320, 2, 3), sphere, -1, &out).ok());
  EXPECT_FALSE(TransferMeshColors(sphere, MeshColors(320, 2, 3), TriMesh(), 2, &out).ok());
  EXPECT_FALSE(TransferMeshColors(TriMesh(), MeshColors(0, 2, 3), sphere, 2, &out).ok());
  // An old mesh of one zero-area face has nothing to read from.
  TriMesh flat;
  flat.add_face(flat.add_vertex({0, 0, 0}), flat.add_vertex({1, 0, 0}), flat.add_vertex({2, 0, 0}));
  const Status status = TransferMeshColors(flat, MeshColors(1, 2, 3), sphere, 2, &out);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("area"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace sft
