// Mesh readers on careless input (issue 9): concave polygons through OBJ, OFF and PLY (exact
// area, corner UVs following their corners, winding), non-planar and self-intersecting polygons
// refused with the face named, byte-order marks, and writers' error reasons.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "src/geometry/mesh.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

Status ReadString(const testing::TempDir& tmp, const std::string& name, const std::string& contents,
                  TriMesh* mesh, MeshReport* report = nullptr) {
  testing::WriteTestFile(tmp.Join(name), contents);
  return ReadMesh(tmp.Join(name), mesh, report);
}

// The notched pentagon (0,0) (4,0) (4,4) (2,1) (0,4) at z = 0, area 10, counter-clockwise seen
// from +z, as vertex lines of OBJ (v x y z) or OFF/PLY (x y z).
const char* kPentagonObjVertices = "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 2 1 0\nv 0 4 0\n";
const char* kPentagonVertices = "0 0 0\n4 0 0\n4 4 0\n2 1 0\n0 4 0\n";

// Checks that `mesh` is the notched pentagon exactly triangulated: total area 10 (a fan gives
// 14 in absolute value), every triangle facing +z (the polygon's winding), and, when the mesh has
// UVs, every corner's UV equal to (x, y) / 4 of its own position.
void ExpectPentagon(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  ASSERT_EQ(faces.size(), 3u);
  const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
  double area = 0.0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const Eigen::Vector3d& a = positions[faces[f][0]];
    const Eigen::Vector3d n = (positions[faces[f][1]] - a).cross(positions[faces[f][2]] - a);
    EXPECT_GT(n.z(), 0.0) << "face " << f;
    area += 0.5 * n.norm();
    for (int c = 0; c < 3 && !uvs.empty(); ++c) {
      const Eigen::Vector3d& p = positions[faces[f][c]];
      EXPECT_EQ(uvs[3 * f + c], Eigen::Vector2d(p.x() / 4, p.y() / 4)) << "face " << f;
    }
  }
  EXPECT_EQ(area, 10.0);
}

TEST(MeshPolygonTest, ConcavePentagonInObjOffPly) {
  testing::TempDir tmp;
  TriMesh mesh;
  MeshReport report;
  // OBJ with per-corner UVs listed in a different order than the vertices.
  ASSERT_TRUE(ReadString(tmp, "p.obj",
                         std::string(kPentagonObjVertices) +
                             "vt 0 1\nvt 0.5 0.25\nvt 1 1\nvt 1 0\nvt 0 0\n"
                             "f 1/5 2/4 3/3 4/2 5/1\n",
                         &mesh, &report)
                  .ok());
  EXPECT_TRUE(report.has_texcoords);
  EXPECT_EQ(report.num_degenerate_faces, 0);
  ExpectPentagon(mesh);
  ASSERT_TRUE(ReadString(tmp, "p.off",
                         "OFF\n5 1 0\n" + std::string(kPentagonVertices) + "5 0 1 2 3 4\n", &mesh)
                  .ok());
  ExpectPentagon(mesh);
  // PLY with MeshLab-style per-corner texcoords.
  ASSERT_TRUE(ReadString(tmp, "p.ply",
                         "ply\nformat ascii 1.0\nelement vertex 5\n"
                         "property float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\n"
                         "property list uchar float texcoord\nend_header\n" +
                             std::string(kPentagonVertices) +
                             "5 0 1 2 3 4 10 0 0 1 0 1 1 0.5 0.25 0 1\n",
                         &mesh, &report)
                  .ok());
  EXPECT_TRUE(report.has_texcoords);
  ExpectPentagon(mesh);
}

TEST(MeshPolygonTest, ConvexQuadIsStillTheFan) {
  testing::TempDir tmp;
  TriMesh mesh;
  ASSERT_TRUE(
      ReadString(tmp, "q.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 2 3 4 1\n", &mesh).ok());
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, nullptr, &faces);
  ASSERT_EQ(faces.size(), 2u);
  EXPECT_EQ(faces[0], Eigen::Vector3i(1, 2, 3));
  EXPECT_EQ(faces[1], Eigen::Vector3i(1, 3, 0));
}

TEST(MeshPolygonTest, NonPlanarPolygonRefusedNamingTheFace) {
  testing::TempDir tmp;
  TriMesh mesh;
  // Face 1 (line 7) is a quad with one corner lifted by 0.5 over a unit square.
  Status s = ReadString(tmp, "warped.obj",
                        "v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nv 0 0 1\n"
                        "f 1 2 5\nf 1 2 3 4\n",
                        &mesh);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("warped.obj: face 1 (line 7): polygon is not planar"));
  EXPECT_EQ(s.message().find('\n'), std::string::npos);
  // OFF names the line too; PLY (binary or not) names the face index.
  s = ReadString(tmp, "warped.off",
                 "OFF\n5 2 0\n0 0 0\n4 0 0\n4 4 0\n2 1 3\n0 4 0\n3 0 1 2\n5 0 1 2 3 4\n", &mesh);
  EXPECT_THAT(s.message(), HasSubstr("warped.off: face 1 (line 9): polygon is not planar"));
  s = ReadString(tmp, "warped.ply",
                 "ply\nformat ascii 1.0\nelement vertex 5\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                 "0 0 0\n4 0 0\n4 4 0\n2 1 3\n0 4 0\n5 0 1 2 3 4\n",
                 &mesh);
  EXPECT_THAT(s.message(), HasSubstr("warped.ply: face 0: polygon is not planar"));
}

TEST(MeshPolygonTest, SelfIntersectingPolygonRefusedNamingTheFace) {
  testing::TempDir tmp;
  TriMesh mesh;
  // A bow-tie quad and a pentagon whose corner 3 touches its first edge.
  Status s =
      ReadString(tmp, "bowtie.obj", "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n", &mesh);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("bowtie.obj: face 0 (line 5): polygon is self-intersecting"));
  s = ReadString(tmp, "touch.off", "OFF\n5 1 0\n0 0 0\n4 0 0\n4 4 0\n2 0 0\n0 4 0\n5 0 1 2 3 4\n",
                 &mesh);
  EXPECT_THAT(s.message(), HasSubstr("touch.off: face 0 (line 8): polygon is self-intersecting"));
  s = ReadString(tmp, "bowtie.ply",
                 "ply\nformat ascii 1.0\nelement vertex 4\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
                 "0 0 0\n1 1 0\n1 0 0\n0 1 0\n3 0 2 1\n4 0 1 2 3\n",
                 &mesh);
  EXPECT_THAT(s.message(), HasSubstr("bowtie.ply: face 1: polygon is self-intersecting"));
}

TEST(MeshInputTest, ByteOrderMarkIsSkipped) {
  testing::TempDir tmp;
  TriMesh mesh;
  const std::string bom = "\xEF\xBB\xBF";
  // The first line is a vertex: with the BOM left in, it was an unknown keyword and was dropped.
  ASSERT_TRUE(ReadString(tmp, "a.obj", bom + "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", &mesh).ok());
  EXPECT_EQ(mesh.n_faces(), 1u);
  EXPECT_EQ(mesh.n_vertices(), 3u);
  ASSERT_TRUE(
      ReadString(tmp, "a.off", bom + "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", &mesh).ok());
  EXPECT_EQ(mesh.n_faces(), 1u);
  ASSERT_TRUE(ReadString(tmp, "a.ply",
                         bom +
                             "ply\nformat ascii 1.0\nelement vertex 3\n"
                             "property float x\nproperty float y\nproperty float z\n"
                             "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                             "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                         &mesh)
                  .ok());
  EXPECT_EQ(mesh.n_faces(), 1u);
}

TEST(MeshInputTest, WriteErrorsGiveTheReason) {
  TriMesh mesh;
  testing::TempDir tmp;
  testing::WriteTestFile(tmp.Join("a.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ASSERT_TRUE(ReadMesh(tmp.Join("a.obj"), &mesh).ok());
  // The target is a non-empty directory: the final rename fails with "Is a directory" (or
  // "Directory not empty"), which the message must carry instead of "Success".
  std::filesystem::create_directories(tmp.Join("out.obj/x"));
  const Status s = WriteMesh(tmp.Join("out.obj"), mesh);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("out.obj: cannot write ("));
  EXPECT_THAT(s.message(), ::testing::Not(HasSubstr("Success")));
}

}  // namespace
}  // namespace sft
