// The per-mesh-state table of (A)'s secondary edge candidates and its near-edge mixture
// (src/render/internal/mesh_edge_table.h).
#include "src/render/internal/mesh_edge_table.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "src/geometry/mesh.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace render_internal {
namespace {

TriMesh Bunny() {
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(testing::DataDir() + "/meshes/bunny_watertight_5k.obj", &mesh).ok());
  return mesh;
}

// Every non-coplanar edge is a record; records are drawn ∝ length, and InverseProbability is the
// inverse of that probability (to float precision).
TEST(MeshEdgeTableTest, RecordsAreTheNonCoplanarEdgesDrawnInProportionToLength) {
  const RenderScene scene(Bunny());
  const MeshEdgeTable table(scene);
  ASSERT_FALSE(table.empty());
  EXPECT_LE(table.size(), static_cast<int>(scene.edges().size()));
  double total_length = 0.0, probability_sum = 0.0;
  for (int i = 0; i < table.size(); ++i) {
    const MeshEdge& edge = scene.edges()[table.edge(i)];
    total_length += (scene.positions()[edge.v1] - scene.positions()[edge.v0]).norm();
    probability_sum += 1.0 / table.InverseProbability(i);
    EXPECT_EQ(table.record(i).f0, edge.f0);
    EXPECT_EQ(table.record(i).f1, edge.f1);
  }
  EXPECT_NEAR(probability_sum, 1.0, 1e-4);
  const int n = 1 << 20;
  std::vector<int> counts(table.size(), 0);
  std::vector<double> u(32);
  int out[32];
  for (int i = 0; i < n; i += 32) {
    for (int k = 0; k < 32; ++k) u[k] = (i + k + 0.5) / n;  // stratified
    table.SampleBatch(u.data(), 32, out);
    for (int k = 0; k < 32; ++k) ++counts[out[k]];
  }
  for (int i = 0; i < table.size(); i += 97) {
    const MeshEdge& edge = scene.edges()[table.edge(i)];
    const double length = (scene.positions()[edge.v1] - scene.positions()[edge.v0]).norm();
    // Stratified u over the alias cells: within 2 draws of the expected count.
    EXPECT_NEAR(counts[i], n * length / total_length, 2.0) << i;
  }
}

// A face's near records are exactly the edges at its corners that are not its own.
TEST(MeshEdgeTableTest, NearRecordsAreTheEdgesAtTheFacesCorners) {
  const RenderScene scene(Bunny());
  const MeshEdgeTable table(scene);
  for (int f = 0; f < static_cast<int>(scene.faces().size()); f += 101) {
    std::set<int> corners;
    for (int k = 0; k < 3; ++k) corners.insert(scene.WeldedVertex(scene.faces()[f][k]));
    std::set<int> expected;
    for (int i = 0; i < table.size(); ++i) {
      const MeshEdge& edge = scene.edges()[table.edge(i)];
      if (edge.f0 == f || edge.f1 == f) continue;
      if (corners.count(edge.v0) || corners.count(edge.v1)) expected.insert(i);
    }
    const std::set<int> near(table.near_begin(f), table.near_end(f));
    EXPECT_EQ(near, expected) << f;
    EXPECT_TRUE(std::is_sorted(table.near_begin(f), table.near_end(f)));
  }
}

// The mixture's probabilities sum to 1 and match its draws.
TEST(MeshEdgeTableTest, NearEdgeMixtureProbabilitiesMatchItsDraws) {
  const RenderScene scene(Bunny());
  const MeshEdgeTable table(scene);
  const int face = 1234;
  const NearEdgeMixture mixture(table, face);
  double sum = 0.0;
  for (int i = 0; i < table.size(); ++i) sum += 1.0 / mixture.InverseProbability(i);
  EXPECT_NEAR(sum, 1.0, 1e-4);
  const int n = 1 << 20;
  std::vector<int> counts(table.size(), 0);
  double u[32];
  int out[32];
  for (int i = 0; i < n; i += 32) {
    for (int k = 0; k < 32; ++k) u[k] = (i + k + 0.5) / n;
    mixture.SampleBatch(u, 32, out);
    for (int k = 0; k < 32; ++k) ++counts[out[k]];
  }
  for (const int* it = table.near_begin(face); it != table.near_end(face); ++it) {
    const double p = 1.0 / mixture.InverseProbability(*it);
    EXPECT_GT(p, NearEdgeMixture::kNearFraction / 64);
    EXPECT_NEAR(counts[*it], n * p, 2.0) << *it;
  }
}

// The table follows the mesh state: a moved vertex gives a new table with the new positions.
TEST(MeshEdgeTableTest, OfFollowsTheMeshState) {
  RenderScene scene(Bunny());
  const auto first = MeshEdgeTable::Of(scene);
  EXPECT_EQ(MeshEdgeTable::Of(scene), first);  // the same state: the same table.
  std::vector<Eigen::Vector3d> moved = scene.positions();
  const MeshEdge& edge = scene.edges()[first->edge(0)];
  moved[edge.v0] += Eigen::Vector3d(0.01, 0.0, 0.0);
  scene.SetVertices(moved);
  const auto second = MeshEdgeTable::Of(scene);
  EXPECT_NE(second, first);
  bool found = false;
  for (int i = 0; i < second->size(); ++i) {
    if (second->edge(i) != first->edge(0)) continue;
    found = true;
    EXPECT_NEAR(second->record(i).a.x(), moved[edge.v0].x(), 1e-6);
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace render_internal
}  // namespace sft
