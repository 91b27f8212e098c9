// Local untangling (src/init/untangle.h): a vertex pushed through a sphere's far side comes back
// to a surface without self-intersections, moving only the vertices near the tangle; a clean
// surface is left exactly as it was; two spheres that cross broadly are beyond its reach, and
// the repair never leaves more intersections than it found.
#include "src/init/untangle.h"

#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "src/init/cgal_surface_mesh.h"
#include "src/init/self_intersection.h"
#include "tests/testing/meshes.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

TriMesh Sphere(double push, testing::Triangles* triangles) {
  *triangles = testing::ReadTestMesh("icosphere_r1_320f.obj");
  triangles->positions[0] *= push;
  TriMesh mesh;
  EXPECT_TRUE(ArraysToTriMesh(triangles->positions, triangles->faces, &mesh).ok());
  return mesh;
}

TEST(UntangleTest, VertexPushedThroughTheFarSideComesBack) {
  testing::Triangles triangles;
  // Through the centre and out beyond the antipodal side (SelfIntersectionTest: 10-100 faces).
  TriMesh mesh = Sphere(-1.3, &triangles);
  UntangleReport report;
  ASSERT_TRUE(Untangle(UntangleOptions(), &mesh, &report).ok());
  EXPECT_GE(report.faces_before, 10);
  EXPECT_EQ(report.faces_after, 0);
  EXPECT_EQ(CountSelfIntersectingFaces(mesh), 0);
  // The pushed vertex is back on its own side of the centre (measured 0.29 of the radius along its
  // original direction): smoothing undoes the crossing, not the dent; the fit's next steps do.
  const Eigen::Vector3d original = testing::ReadTestMesh("icosphere_r1_320f.obj").positions[0];
  const TriMesh::Point p = mesh.point(mesh.vertex_handle(0));
  EXPECT_GT(Eigen::Vector3d(p[0], p[1], p[2]).dot(original), 0.1);
  // Vertices far from the tangle keep their exact positions: the 320-face sphere has 162
  // vertices; the neighbourhood of the spike's fan and the far faces it crosses is a minority.
  int unchanged = 0;
  for (int v = 1; v < static_cast<int>(mesh.n_vertices()); ++v) {
    const TriMesh::Point q = mesh.point(mesh.vertex_handle(v));
    if (Eigen::Vector3d(q[0], q[1], q[2]) == triangles.positions[v]) ++unchanged;
  }
  EXPECT_GT(unchanged, 40) << report.moved_vertices << " moved";
  EXPECT_EQ(unchanged + report.moved_vertices, static_cast<int>(mesh.n_vertices()));
}

TEST(UntangleTest, CleanSurfaceIsUnchanged) {
  testing::Triangles triangles;
  TriMesh mesh = Sphere(1.0, &triangles);
  UntangleReport report;
  ASSERT_TRUE(Untangle(UntangleOptions(), &mesh, &report).ok());
  EXPECT_EQ(report.faces_before, 0);
  EXPECT_EQ(report.rounds, 0);
  for (int v = 0; v < static_cast<int>(mesh.n_vertices()); ++v) {
    const TriMesh::Point q = mesh.point(mesh.vertex_handle(v));
    EXPECT_EQ(Eigen::Vector3d(q[0], q[1], q[2]), triangles.positions[v]);
  }
}

// Two spheres that cross along a whole circle: smoothing cannot separate them. The result is
// never worse than the input, and when no round improves on it the input comes back unchanged.
TEST(UntangleTest, BroadCrossingIsNeverMadeWorse) {
  testing::Triangles one = testing::ReadTestMesh("icosphere_r1_320f.obj");
  testing::Triangles two = one;
  for (Eigen::Vector3d& p : two.positions) p += Eigen::Vector3d(1.0, 0.0, 0.0);
  testing::Triangles both = one;
  both.Append(two);
  TriMesh mesh;
  ASSERT_TRUE(ArraysToTriMesh(both.positions, both.faces, &mesh).ok());
  UntangleReport report;
  ASSERT_TRUE(Untangle(UntangleOptions(), &mesh, &report).ok());
  EXPECT_GT(report.faces_before, 20);
  EXPECT_GT(report.faces_after, 0);
  EXPECT_LE(report.faces_after, report.faces_before);
  EXPECT_EQ(CountSelfIntersectingFaces(mesh), report.faces_after);
  if (report.faces_after == report.faces_before) {
    EXPECT_EQ(report.moved_vertices, 0);
    for (int v = 0; v < static_cast<int>(mesh.n_vertices()); ++v) {
      const TriMesh::Point q = mesh.point(mesh.vertex_handle(v));
      EXPECT_EQ(Eigen::Vector3d(q[0], q[1], q[2]), both.positions[v]);
    }
  }
}

TEST(UntangleTest, RejectsBadOptions) {
  testing::Triangles triangles;
  TriMesh mesh = Sphere(1.0, &triangles);
  UntangleOptions options;
  options.step = 0.0;
  UntangleReport report;
  const Status status = Untangle(options, &mesh, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("step"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace sft
