// Counting self-intersecting faces (src/init/self_intersection.h): a closed sphere has none, a
// vertex pushed through the opposite side makes some, and two interpenetrating spheres count
// exactly the faces that a brute-force test over all face pairs finds.
#include "src/init/self_intersection.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "src/init/cgal_surface_mesh.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

void ReadFixture(const std::string& name, std::vector<Eigen::Vector3d>* positions,
                 std::vector<Eigen::Vector3i>* faces) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/" + name, &mesh).ok()) << name;
  MeshToArrays(mesh, positions, faces);
}

TriMesh MeshOf(const std::vector<Eigen::Vector3d>& positions,
               const std::vector<Eigen::Vector3i>& faces) {
  TriMesh mesh;
  EXPECT_TRUE(ArraysToTriMesh(positions, faces, &mesh).ok());
  return mesh;
}

Kernel::Triangle_3 TriangleOf(const std::vector<Eigen::Vector3d>& positions,
                              const Eigen::Vector3i& f) {
  auto point = [&](int v) {
    return Kernel::Point_3(positions[v].x(), positions[v].y(), positions[v].z());
  };
  return Kernel::Triangle_3(point(f[0]), point(f[1]), point(f[2]));
}

TEST(SelfIntersectionTest, ClosedSphereHasNone) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  ReadFixture("icosphere_r1_1280f.obj", &positions, &faces);
  EXPECT_EQ(CountSelfIntersectingFaces(MeshOf(positions, faces)), 0);
}

TEST(SelfIntersectionTest, VertexPushedThroughTheOppositeSide) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  ReadFixture("icosphere_r1_320f.obj", &positions, &faces);
  positions[0] *= -1.3;  // through the centre and out beyond the antipodal side.
  const int count = CountSelfIntersectingFaces(MeshOf(positions, faces));
  // At least the vertex's fan (5 or 6 faces, stretched across the sphere) crosses the far side,
  // and each of them crosses some far face.
  EXPECT_GE(count, 10);
  EXPECT_LT(count, 100);
}

// Sphere B is sphere A moved by 1 along x: they cross along a circle of radius √3/2. The faces
// of one sphere cannot meet each other (the sphere alone has no intersection), so the expected
// count is the number of distinct faces in intersecting (A face, B face) pairs, found by testing
// every pair with CGAL's exact triangle-triangle predicate.
TEST(SelfIntersectionTest, TwoInterpenetratingSpheresCountTheCrossingFaces) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  ReadFixture("icosphere_r1_320f.obj", &positions, &faces);
  const int num_positions = static_cast<int>(positions.size());
  const int num_faces = static_cast<int>(faces.size());
  for (int v = 0; v < num_positions; ++v) {
    positions.push_back(positions[v] + Eigen::Vector3d(1.0, 0.0, 0.0));
  }
  for (int f = 0; f < num_faces; ++f) {
    faces.push_back(faces[f] + Eigen::Vector3i::Constant(num_positions));
  }
  std::set<int> crossing;
  for (int a = 0; a < num_faces; ++a) {
    for (int b = num_faces; b < 2 * num_faces; ++b) {
      if (CGAL::do_intersect(TriangleOf(positions, faces[a]), TriangleOf(positions, faces[b]))) {
        crossing.insert(a);
        crossing.insert(b);
      }
    }
  }
  ASSERT_GT(crossing.size(), 20u);
  EXPECT_EQ(CountSelfIntersectingFaces(MeshOf(positions, faces)),
            static_cast<int>(crossing.size()));
  // The listed faces are exactly those, in the mesh's own face indices.
  std::vector<int> listed;
  ASSERT_TRUE(SelfIntersectingFaces(MeshOf(positions, faces), &listed));
  EXPECT_EQ(listed, std::vector<int>(crossing.begin(), crossing.end()));
}

TEST(SelfIntersectionTest, EmptyMeshIsMinusOne) {
  EXPECT_EQ(CountSelfIntersectingFaces(TriMesh()), -1);
}

}  // namespace
}  // namespace sft
