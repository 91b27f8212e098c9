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

// Every non-coplanar edge is a record, in the tree's order, with its faces and length.
TEST(MeshEdgeTableTest, RecordsAreTheNonCoplanarEdgesInTreeOrder) {
  const RenderScene scene(Bunny());
  const MeshEdgeTable table(scene);
  ASSERT_FALSE(table.empty());
  EXPECT_LE(table.size(), static_cast<int>(scene.edges().size()));
  EXPECT_EQ(table.tree().order().size(), static_cast<size_t>(table.size()));
  std::set<int> edges;
  for (int i = 0; i < table.size(); ++i) {
    const MeshEdge& edge = scene.edges()[table.edge(i)];
    edges.insert(table.edge(i));
    const double length = (scene.positions()[edge.v1] - scene.positions()[edge.v0]).norm();
    EXPECT_NEAR(table.record(i).length, length, 1e-6 * length);
    EXPECT_EQ(table.record(i).f0, edge.f0);
    EXPECT_EQ(table.record(i).f1, edge.f1);
    EXPECT_LT((table.record(i).a.cast<double>() - scene.positions()[edge.v0]).norm(), 1e-6);
  }
  EXPECT_EQ(edges.size(), static_cast<size_t>(table.size()));  // each edge once.
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

// The mixture's probabilities sum to 1 and match its draws, and every record with a point
// above x's plane has a positive probability.
TEST(MeshEdgeTableTest, NearEdgeMixtureProbabilitiesMatchItsDraws) {
  const RenderScene scene(Bunny());
  const MeshEdgeTable table(scene);
  const int face = 1234;
  const Eigen::Vector3i& corners = scene.faces()[face];
  const Eigen::Vector3d x = (scene.positions()[corners[0]] + scene.positions()[corners[1]] +
                             scene.positions()[corners[2]]) /
                            3.0;
  const Eigen::Vector3d n = scene.FaceNormal(face);
  const NearEdgeMixture mixture(table, face, x, n);
  std::vector<double> p(table.size());
  double sum = 0.0;
  for (int i = 0; i < table.size(); ++i) {
    p[i] = 1.0 / mixture.InverseProbability(i);
    sum += p[i];
    const MeshEdgeTable::Record& r = table.record(i);
    const bool above = n.dot(r.a.cast<double>() - x) > 1e-6 || n.dot(r.b.cast<double>() - x) > 1e-6;
    if (above) {
      EXPECT_GT(p[i], 0.0) << i;
    }
  }
  EXPECT_LE(sum, 1.0 + 1e-9);  // the rest is the tree's empty draw (all below x's plane).
  const int draws = 1 << 20;
  std::vector<int> counts(table.size(), 0);
  double u[32], inverse_probability[32];
  int out[32], empty = 0;
  for (int i = 0; i < draws; i += 32) {
    for (int k = 0; k < 32; ++k) u[k] = (i + k + 0.5) / draws;
    mixture.SampleBatch(u, 32, out, inverse_probability);
    for (int k = 0; k < 32; ++k) {
      if (out[k] < 0) {
        ++empty;
        continue;
      }
      ++counts[out[k]];
      ASSERT_NEAR(1.0 / inverse_probability[k], p[out[k]], 1e-9 * p[out[k]]);
    }
  }
  for (const int* it = table.near_begin(face); it != table.near_end(face); ++it) {
    EXPECT_GT(p[*it], NearEdgeMixture::kNearFraction / 64);
  }
  // Stratified u: the counts follow the probabilities (5 standard deviations, at least 3 draws).
  for (int i = 0; i < table.size(); ++i) {
    const double expected = draws * p[i];
    EXPECT_NEAR(counts[i], expected, 5.0 * std::sqrt(expected) + 3.0) << i;
  }
  const double expected_empty = draws * std::max(0.0, 1.0 - sum);
  EXPECT_NEAR(empty, expected_empty, 5.0 * std::sqrt(expected_empty) + 3.0);
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
