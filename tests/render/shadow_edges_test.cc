// The shadow-edge candidates of a point light (src/render/internal/shadow_edges.h): built once per
// mesh state and light position, and the same list as a fresh build.
#include "src/render/internal/shadow_edges.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "src/render/scene.h"
#include "tests/testing/meshes.h"

namespace sft {
namespace render_internal {
namespace {

void ExpectSameCandidates(const std::vector<EdgeCandidate>& a,
                          const std::vector<EdgeCandidate>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].edge, b[i].edge);
    EXPECT_EQ(a[i].s0, b[i].s0);
    EXPECT_EQ(a[i].s1, b[i].s1);
    EXPECT_EQ(a[i].weight, b[i].weight);
  }
}

TEST(ShadowEdgesTest, CandidatesAreBuiltOncePerMeshStateAndLightPosition) {
  const testing::Triangles cube = testing::ReadTestMesh("cube_2x2x2_12f.obj");
  RenderScene scene(cube.positions, cube.faces);
  const Eigen::Vector3d light(2.0, -3.0, 5.0);
  const auto first = ShadowEdgeCandidates(scene, light);
  ASSERT_NE(first, nullptr);
  // A cube seen from a point light: its silhouette from there is a loop of 6 edges.
  EXPECT_EQ(first->size(), 6u);
  EXPECT_EQ(ShadowEdgeCandidates(scene, light), first);

  // Another position is another list; the first is still kept.
  const auto moved = ShadowEdgeCandidates(scene, Eigen::Vector3d(2.0, -3.0, 5.5));
  EXPECT_NE(moved, first);
  EXPECT_EQ(ShadowEdgeCandidates(scene, light), first);

  // A scene with the same mesh is another mesh state: a new build, the same list.
  const RenderScene same_mesh(cube.positions, cube.faces);
  const auto other_scene = ShadowEdgeCandidates(same_mesh, light);
  EXPECT_NE(other_scene, first);
  ExpectSameCandidates(*other_scene, *first);

  // Moving the vertices is a new mesh state: the list follows the geometry.
  std::vector<Eigen::Vector3d> scaled = cube.positions;
  for (Eigen::Vector3d& p : scaled) p *= 1.5;
  scene.SetVertices(scaled);
  const auto after_move = ShadowEdgeCandidates(scene, light);
  EXPECT_NE(after_move, first);
  const RenderScene fresh(scaled, cube.faces);
  ExpectSameCandidates(*after_move, *ShadowEdgeCandidates(fresh, light));
  for (size_t i = 0; i < first->size(); ++i) {
    EXPECT_NE((*after_move)[i].weight, (*first)[i].weight) << "candidate " << i;
  }
}

TEST(ShadowEdgesTest, KeepsTheMostRecentBuilds) {
  const testing::Triangles cube = testing::ReadTestMesh("cube_2x2x2_12f.obj");
  const RenderScene scene(cube.positions, cube.faces);
  const Eigen::Vector3d light(-4.0, 1.0, 3.0);
  const auto first = ShadowEdgeCandidates(scene, light);
  // kShadowCandidateBuildsKept − 1 other positions: the first is still kept (and used again, so
  // the most recent)...
  for (size_t i = 1; i < kShadowCandidateBuildsKept; ++i) {
    ShadowEdgeCandidates(scene, light + Eigen::Vector3d(0.0, 0.0, 0.1 * i));
  }
  EXPECT_EQ(ShadowEdgeCandidates(scene, light), first);
  // ... and kShadowCandidateBuildsKept more push it out: rebuilt, the same list.
  for (size_t i = 1; i <= kShadowCandidateBuildsKept; ++i) {
    ShadowEdgeCandidates(scene, light + Eigen::Vector3d(0.0, 0.1 * i, 0.0));
  }
  const auto rebuilt = ShadowEdgeCandidates(scene, light);
  EXPECT_NE(rebuilt, first);
  ExpectSameCandidates(*rebuilt, *first);
}

}  // namespace
}  // namespace render_internal
}  // namespace sft
