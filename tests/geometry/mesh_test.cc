// Mesh files: the fixtures in data/, every error path of the validating readers, degenerate-face
// accounting, per-corner UVs, and write/read round trips.
#include "src/geometry/mesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "src/core/file_util.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

std::string MeshesDir() { return testing::DataDir() + "/meshes"; }
std::string SpotDir() { return testing::DataDir() + "/cycles/spot_textured_point/gt"; }

// Reads `contents` written to a file named `name` in a fresh temporary directory.
Status ReadString(const testing::TempDir& tmp, const std::string& name, const std::string& contents,
                  TriMesh* mesh, MeshReport* report = nullptr) {
  testing::WriteTestFile(tmp.Join(name), contents);
  return ReadMesh(tmp.Join(name), mesh, report);
}

TEST(MeshReadTest, ObjFixtures) {
  struct Case {
    const char* file;
    int vertices, faces;
  } cases[] = {{"quad_z0_2x2_2f.obj", 4, 2},
               {"cube_2x2x2_12f.obj", 8, 12},
               {"icosphere_r1_320f.obj", 162, 320},
               {"icosphere_r1_1280f.obj", 642, 1280},
               {"bunny_watertight_5k.obj", 2502, 5000}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    TriMesh mesh;
    MeshReport report;
    ASSERT_TRUE(ReadMesh(MeshesDir() + "/" + c.file, &mesh, &report).ok());
    EXPECT_EQ(report.num_vertices, c.vertices);
    EXPECT_EQ(report.num_faces, c.faces);
    EXPECT_EQ(static_cast<int>(mesh.n_faces()), c.faces);
    EXPECT_EQ(report.num_degenerate_faces, 0);
    EXPECT_EQ(report.num_isolated_vertices, 0);
    EXPECT_FALSE(report.has_texcoords);
    EXPECT_TRUE(FaceCornerUvs(mesh).empty());
  }
}

TEST(MeshReadTest, QuadGeometryAndArrays) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(MeshesDir() + "/quad_z0_2x2_2f.obj", &mesh).ok());
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  ASSERT_EQ(positions.size(), 4u);
  EXPECT_EQ(positions[2], Eigen::Vector3d(1, 1, 0));
  // Face vertex order is the file's (f 1 2 3 / f 1 3 4): the mesh-colors layout depends on it.
  ASSERT_EQ(faces.size(), 2u);
  EXPECT_EQ(faces[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(faces[1], Eigen::Vector3i(0, 2, 3));
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  EXPECT_EQ(lo, Eigen::Vector3d(-1, -1, 0));
  EXPECT_EQ(hi, Eigen::Vector3d(1, 1, 0));
}

TEST(MeshReadTest, CyclesGroundTruthPly) {
  struct Case {
    const char* dataset;
    int vertices, faces;
  } cases[] = {{"bunny_point_diffuse", 2502, 5000},
               {"bunny_point_ggx_gi", 2502, 5000},
               {"sphere_env_studio", 2562, 5120},
               {"spot_textured_point", 2930, 5856}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.dataset);
    TriMesh mesh;
    MeshReport report;
    ASSERT_TRUE(
        ReadMesh(testing::DataDir() + "/cycles/" + c.dataset + "/gt/mesh.ply", &mesh, &report)
            .ok());
    EXPECT_EQ(report.num_vertices, c.vertices);
    EXPECT_EQ(report.num_faces, c.faces);
    EXPECT_EQ(report.num_isolated_vertices, 0);
    Eigen::Vector3d lo, hi;
    MeshBounds(mesh, &lo, &hi);
    // The datasets scale the object to a bounding-box diagonal of 1 (gen_spec.json).
    EXPECT_NEAR((hi - lo).norm(), 1.0, 1e-3);
  }
}

// The spot ground truth comes as binary PLY and as OBJ with UVs: both must give the same mesh
// (same vertex and face order). Positions agree to the OBJ's 7 significant digits (float PLY).
TEST(MeshReadTest, SpotPlyAndObjAgree) {
  TriMesh ply, obj;
  ASSERT_TRUE(ReadMesh(SpotDir() + "/mesh.ply", &ply).ok());
  ASSERT_TRUE(ReadMesh(SpotDir() + "/mesh_uv.obj", &obj).ok());
  std::vector<Eigen::Vector3d> p1, p2;
  std::vector<Eigen::Vector3i> f1, f2;
  MeshToArrays(ply, &p1, &f1);
  MeshToArrays(obj, &p2, &f2);
  ASSERT_EQ(p1.size(), p2.size());
  ASSERT_EQ(f1, f2);
  double max_diff = 0.0;
  for (size_t i = 0; i < p1.size(); ++i) max_diff = std::max(max_diff, (p1[i] - p2[i]).norm());
  EXPECT_LT(max_diff, 1e-6);
}

// Per-corner UVs of mesh_uv.obj, checked against an independent parse of its vt and f lines.
TEST(MeshReadTest, ObjUvsMatchFile) {
  TriMesh mesh;
  MeshReport report;
  ASSERT_TRUE(ReadMesh(SpotDir() + "/mesh_uv.obj", &mesh, &report).ok());
  EXPECT_TRUE(report.has_texcoords);
  const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
  ASSERT_EQ(uvs.size(), 3 * mesh.n_faces());

  std::ifstream in(SpotDir() + "/mesh_uv.obj");
  std::string line;
  std::vector<Eigen::Vector2d> vt;
  std::vector<std::array<int, 3>> face_vt;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string key;
    ss >> key;
    if (key == "vt") {
      double u, v;
      ss >> u >> v;
      vt.emplace_back(u, v);
    } else if (key == "f") {
      std::array<int, 3> t;
      for (int c = 0; c < 3; ++c) {
        std::string corner;
        ss >> corner;
        t[c] = std::stoi(corner.substr(corner.find('/') + 1)) - 1;
      }
      face_vt.push_back(t);
    }
  }
  ASSERT_EQ(face_vt.size(), mesh.n_faces());
  for (size_t f = 0; f < face_vt.size(); ++f) {
    for (int c = 0; c < 3; ++c) {
      // Values are stored as doubles parsed from the same text: exact.
      ASSERT_EQ(uvs[3 * f + c], vt[face_vt[f][c]]) << "face " << f << " corner " << c;
    }
  }
}

// A quad with UVs is triangulated into (0,1,2), (0,2,3) with each corner keeping its UV; a
// non-manifold face (a third face on one edge) keeps its UVs on its duplicated vertices. Both
// are cases OpenMesh's own OBJ importer gets wrong.
TEST(MeshReadTest, ObjPolygonAndNonManifoldUvs) {
  testing::TempDir tmp;
  TriMesh mesh;
  MeshReport report;
  ASSERT_TRUE(ReadString(tmp, "q.obj",
                         "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nv 0.5 0.5 -1\n"
                         "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\nvt 0.25 0.75\n"
                         "f 1/1 2/2 3/3 4/4\n"
                         "f 2/2 1/1 5/5\n"
                         "f 1/4 2/3 6/6\n",  // Third face on edge 1-2, same direction as 1st.
                         &mesh, &report)
                  .ok());
  EXPECT_TRUE(report.has_texcoords);
  ASSERT_EQ(mesh.n_faces(), 4u);
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
  // Each corner's UV, looked up by its position (UVs were chosen as a function of position
  // within each face here, so position -> UV is well defined per face).
  auto expect_face = [&](int f, const std::vector<Eigen::Vector3d>& p,
                         const std::vector<Eigen::Vector2d>& t) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(positions[faces[f][c]], p[c]) << "face " << f << " corner " << c;
      EXPECT_EQ(uvs[3 * f + c], t[c]) << "face " << f << " corner " << c;
    }
  };
  const Eigen::Vector3d v1(0, 0, 0), v2(1, 0, 0), v3(1, 1, 0), v4(0, 1, 0), v5(0.5, 0.5, 1),
      v6(0.5, 0.5, -1);
  expect_face(0, {v1, v2, v3}, {{0, 0}, {1, 0}, {1, 1}});
  expect_face(1, {v1, v3, v4}, {{0, 0}, {1, 1}, {0, 1}});
  expect_face(2, {v2, v1, v5}, {{1, 0}, {0, 0}, {0.5, 0.5}});
  expect_face(3, {v1, v2, v6}, {{0, 1}, {1, 1}, {0.25, 0.75}});
  EXPECT_EQ(mesh.n_vertices(), 9u);  // 6 + 3 copies for the non-manifold face.
}

TEST(MeshReadTest, ObjIndexForms) {
  testing::TempDir tmp;
  TriMesh mesh;
  // Negative indices are relative to the vertices defined so far; positive indices may refer to
  // vertices defined later (as OpenMesh's reader allows); v//vn and v/vt/vn forms.
  ASSERT_TRUE(ReadString(tmp, "a.obj",
                         "f 1//1 2//1 3//1\n"
                         "vn 0 0 1\n"
                         "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                         "v 5 0 0\nv 6 0 0\nv 5 1 0\n"
                         "f -3 -2 -1\n"
                         "vt 0 0\n"
                         "f 1/1/1 6/1/1 5/-1/-1\n",
                         &mesh)
                  .ok());
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, nullptr, &faces);
  ASSERT_EQ(faces.size(), 3u);
  EXPECT_EQ(faces[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(faces[1], Eigen::Vector3i(3, 4, 5));
  EXPECT_EQ(faces[2], Eigen::Vector3i(0, 5, 4));
  EXPECT_EQ(mesh.n_vertices(), 6u);  // No non-manifold copies.
}

TEST(MeshReadTest, OffVariants) {
  testing::TempDir tmp;
  TriMesh mesh;
  MeshReport report;
  // Counts on the keyword line, comments, blank lines, vertex colours (COFF), a quad, and
  // trailing face colours.
  ASSERT_TRUE(ReadString(tmp, "a.off",
                         "COFF 6 2 0\n# comment\n\n"
                         "0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n"
                         "0 1 0 1 1 1 255\n1 -1 0 1 1 1 255\n5 5 5 1 1 1 255\n"
                         "4 0 1 2 3 255 0 0\n3 1 0 4\n",
                         &mesh, &report)
                  .ok());
  EXPECT_EQ(report.num_faces, 3);  // quad -> 2 triangles, plus one triangle.
  EXPECT_EQ(report.num_vertices, 6);
  EXPECT_EQ(report.num_isolated_vertices, 1);  // vertex 5 is in no face.
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, nullptr, &faces);
  EXPECT_EQ(faces[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(faces[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(faces[2], Eigen::Vector3i(1, 0, 4));
  ASSERT_TRUE(ReadString(tmp, "b.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", &mesh).ok());
  EXPECT_EQ(mesh.n_faces(), 1u);
}

TEST(MeshReadTest, PlyAsciiWithVertexUvsAndBigEndian) {
  testing::TempDir tmp;
  TriMesh mesh;
  MeshReport report;
  ASSERT_TRUE(ReadString(tmp, "a.ply",
                         "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\n"
                         "property double x\nproperty double y\nproperty double z\n"
                         "property float s\nproperty float t\n"
                         "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
                         "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                         "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n"
                         "0 1\n"
                         "4 0 1 2 3\n",
                         &mesh, &report)
                  .ok());
  EXPECT_EQ(report.num_faces, 2);
  EXPECT_TRUE(report.has_texcoords);
  const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
  ASSERT_EQ(uvs.size(), 6u);
  EXPECT_EQ(uvs[2], Eigen::Vector2d(1, 1));
  EXPECT_EQ(uvs[5], Eigen::Vector2d(0, 1));

  // Binary big endian: one triangle, float coordinates, uchar count, int indices.
  std::string body;
  auto put_be = [&](const void* p, int n) {
    const char* c = static_cast<const char*>(p);
    for (int i = n - 1; i >= 0; --i) body.push_back(c[i]);
  };
  const float coords[9] = {0, 0, 0, 2, 0, 0, 0, 3, 0};
  for (float v : coords) put_be(&v, 4);
  body.push_back(3);
  for (int32_t i : {0, 1, 2}) put_be(&i, 4);
  ASSERT_TRUE(ReadString(tmp, "b.ply",
                         "ply\nformat binary_big_endian 1.0\nelement vertex 3\n"
                         "property float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\nend_header\n" +
                             body,
                         &mesh)
                  .ok());
  std::vector<Eigen::Vector3d> positions;
  MeshToArrays(mesh, &positions, nullptr);
  ASSERT_EQ(positions.size(), 3u);
  EXPECT_EQ(positions[1], Eigen::Vector3d(2, 0, 0));
  EXPECT_EQ(positions[2], Eigen::Vector3d(0, 3, 0));
}

// Zero-area faces (collinear or coincident vertices) are kept and counted; faces that repeat a
// vertex cannot exist in a halfedge mesh, so they are counted and left out.
TEST(MeshReadTest, DegenerateFacesCounted) {
  testing::TempDir tmp;
  TriMesh mesh;
  MeshReport report;
  ASSERT_TRUE(ReadString(tmp, "d.obj",
                         "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 0 1 0\n"
                         "f 1 2 3\n"   // fine
                         "f 2 1 4\n"   // collinear: zero area
                         "f 3 2 5\n"   // vertices 3 and 5 coincide: zero area
                         "f 1 1 2\n",  // repeated vertex: dropped
                         &mesh, &report)
                  .ok());
  EXPECT_EQ(report.num_faces, 3);
  EXPECT_EQ(static_cast<int>(mesh.n_faces()), 3);
  EXPECT_EQ(report.num_degenerate_faces, 3);
  EXPECT_EQ(report.num_isolated_vertices, 0);
  EXPECT_EQ(report.num_vertices, 5);  // No non-manifold copies.
}

// A file whose faces all have some but not all UVs reads without UVs (a warning is logged).
TEST(MeshReadTest, PartialUvsAreDropped) {
  testing::TempDir tmp;
  TriMesh mesh;
  MeshReport report;
  ASSERT_TRUE(ReadString(tmp, "p.obj",
                         "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\n"
                         "f 1/1 2/1 3/1\nf 2 4 3\n",
                         &mesh, &report)
                  .ok());
  EXPECT_FALSE(report.has_texcoords);
  EXPECT_TRUE(FaceCornerUvs(mesh).empty());
}

struct ErrorCase {
  const char* name;      // file name (its extension selects the reader).
  std::string contents;  // file contents.
  const char* expected;  // substring of the error message.
};

std::string BinaryPly(int num_vertices, const std::vector<float>& coords,
                      const std::vector<int>& face, bool truncate = false) {
  std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                       std::to_string(num_vertices) +
                       "\nproperty float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  std::string body(reinterpret_cast<const char*>(coords.data()), 4 * coords.size());
  body.push_back(static_cast<char>(face.size()));
  body.append(reinterpret_cast<const char*>(face.data()), 4 * face.size());
  if (truncate) body.resize(body.size() - 2);
  return header + body;
}

TEST(MeshReadTest, ErrorsNameFileAndCause) {
  const float nan = std::nanf("");
  const std::vector<ErrorCase> cases = {
      {"empty.obj", "", "no faces"},
      {"blank.ply", "  \n", "no faces"},
      {"novert.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"},
      {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4: vertex index 4 out of range"},
      {"negrange.obj", "v 0 0 0\nv 1 0 0\nf -3 -2 -1\nv 0 1 0\n", "line 3: vertex index -3"},
      {"zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "index 0"},
      {"vtrange.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n",
       "texture coordinate index 2 out of range"},
      {"vnrange.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n", "normal index 1"},
      {"nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "line 2: non-finite"},
      {"inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n", "line 3: non-finite"},
      {"bad.obj", "v 0 0 0\nv 1 0 zero\nv 0 1 0\nf 1 2 3\n", "malformed vertex coordinate"},
      {"two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", "fewer than 3"},
      {"range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "vertex index 3 out of range"},
      {"nan.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", "non-finite"},
      {"short.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "truncated"},
      {"header.off", "PFF\n3 1 0\n", "OFF header"},
      {"range.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
       "vertex index 7 out of range"},
      {"nan.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n",
       "vertex 1: non-finite"},
      {"binrange.ply", BinaryPly(3, {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 3}),
       "vertex index 3 out of range"},
      {"binnan.ply", BinaryPly(3, {0, 0, 0, 1, nan, 0, 0, 1, 0}, {0, 1, 2}), "non-finite"},
      {"bintrunc.ply", BinaryPly(3, {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}, true), "truncated"},
      {"noface.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n0 0 0\n",
       "no faces"},
      {"notply.ply", "hello\n", "not a PLY"},
      {"mesh.stl", "solid x\n", "unknown mesh extension"},
  };
  testing::TempDir tmp;
  for (const ErrorCase& c : cases) {
    SCOPED_TRACE(c.name);
    TriMesh mesh;
    const Status status = ReadString(tmp, c.name, c.contents, &mesh);
    ASSERT_FALSE(status.ok());
    EXPECT_THAT(status.message(), HasSubstr(tmp.Join(c.name)));
    EXPECT_THAT(status.message(), HasSubstr(c.expected));
    EXPECT_EQ(status.message().find('\n'), std::string::npos);  // one line.
  }
  TriMesh mesh;
  const Status missing = ReadMesh(tmp.Join("missing.obj"), &mesh);
  ASSERT_FALSE(missing.ok());
  EXPECT_THAT(missing.message(), HasSubstr(tmp.Join("missing.obj")));
  EXPECT_THAT(missing.message(), HasSubstr("not found"));
}

// Reading a mesh, writing it in each format and reading it back gives the same faces (vertex
// order included) and the same positions: exactly for OBJ and OFF (17 significant digits), to
// float precision for PLY (binary float32 vertices, as OpenMesh writes them).
TEST(MeshWriteTest, RoundTripEachFormat) {
  TriMesh original;
  ASSERT_TRUE(ReadMesh(MeshesDir() + "/bunny_watertight_5k.obj", &original).ok());
  // Perturb so that coordinates need all of double precision.
  for (TriMesh::VertexHandle vh : original.vertices()) {
    original.point(vh) *= 1.0 + 1e-3 / 3.0;
  }
  std::vector<Eigen::Vector3d> p0;
  std::vector<Eigen::Vector3i> f0;
  MeshToArrays(original, &p0, &f0);
  testing::TempDir tmp;
  for (const char* ext : {"obj", "ply", "off"}) {
    SCOPED_TRACE(ext);
    const std::string path = tmp.Join(std::string("sub/dir/out.") + ext);
    ASSERT_TRUE(WriteMesh(path, original).ok());
    TriMesh read;
    MeshReport report;
    ASSERT_TRUE(ReadMesh(path, &read, &report).ok());
    std::vector<Eigen::Vector3d> p1;
    std::vector<Eigen::Vector3i> f1;
    MeshToArrays(read, &p1, &f1);
    EXPECT_EQ(f1, f0);
    ASSERT_EQ(p1.size(), p0.size());
    double max_diff = 0.0;
    for (size_t i = 0; i < p0.size(); ++i) {
      max_diff = std::max(max_diff, (p1[i] - p0[i]).cwiseAbs().maxCoeff());
    }
    // Bunny coordinates are within [-1, 1]: float spacing there is <= 6e-8.
    EXPECT_LE(max_diff, std::string(ext) == "ply" ? 1e-7 : 0.0);
  }
  // Only the final files are left: no temporaries.
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(tmp.Join("sub/dir"))) {
    ++files;
    EXPECT_EQ(entry.path().filename().string().rfind("out.", 0), 0u) << entry.path();
  }
  EXPECT_EQ(files, 3);
}

TEST(MeshWriteTest, ObjKeepsUvs) {
  TriMesh original;
  ASSERT_TRUE(ReadMesh(SpotDir() + "/mesh_uv.obj", &original).ok());
  testing::TempDir tmp;
  ASSERT_TRUE(WriteMesh(tmp.Join("spot.obj"), original).ok());
  TriMesh read;
  MeshReport report;
  ASSERT_TRUE(ReadMesh(tmp.Join("spot.obj"), &read, &report).ok());
  EXPECT_TRUE(report.has_texcoords);
  EXPECT_EQ(FaceCornerUvs(read), FaceCornerUvs(original));
  // Shared UVs are written once: the spot file has 3225 distinct vt.
  std::ifstream in(tmp.Join("spot.obj"));
  std::string line;
  int vt = 0;
  while (std::getline(in, line)) vt += line.rfind("vt ", 0) == 0;
  EXPECT_EQ(vt, 3225);
}

TEST(MeshWriteTest, UnknownExtensionFails) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(MeshesDir() + "/quad_z0_2x2_2f.obj", &mesh).ok());
  testing::TempDir tmp;
  const Status status = WriteMesh(tmp.Join("out.stl"), mesh);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("out.stl"));
  EXPECT_FALSE(std::filesystem::exists(tmp.Join("out.stl")));
}

// ParseMesh (the fuzzed entry point) is ReadMesh without the file read.
TEST(MeshReadTest, ParseMeshMatchesReadMesh) {
  for (const std::string name : {"cube_2x2x2_12f.obj", "icosphere_r1_320f.obj"}) {
    const std::string path = MeshesDir() + "/" + name;
    std::string text;
    ASSERT_TRUE(ReadTextFile(path, &text).ok());
    TriMesh from_file, from_buffer;
    MeshReport file_report, buffer_report;
    ASSERT_TRUE(ReadMesh(path, &from_file, &file_report).ok());
    const Status status = ParseMesh(text, path, &from_buffer, &buffer_report);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_EQ(from_buffer.n_vertices(), from_file.n_vertices());
    ASSERT_EQ(from_buffer.n_faces(), from_file.n_faces());
    for (size_t v = 0; v < from_file.n_vertices(); ++v) {
      const auto vh = TriMesh::VertexHandle(static_cast<int>(v));
      EXPECT_EQ(from_buffer.point(vh), from_file.point(vh));
    }
    EXPECT_EQ(buffer_report.num_degenerate_faces, file_report.num_degenerate_faces);
  }
  TriMesh mesh;
  const Status status = ParseMesh("v 0 0 0\n", "in_memory.stl", &mesh);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("in_memory.stl: unknown mesh extension"));
}

// Found by mesh_ply_fuzzer (data/fuzz_regressions/): an element without properties but with a
// count of 444444444 made the reader loop for minutes; it occupies no bytes and is skipped.
TEST(MeshFuzzRegression, PlyElementWithoutPropertiesIsSkipped) {
  const std::string path =
      testing::DataDir() + "/fuzz_regressions/mesh_ply_empty_element_timeout.ply";
  TriMesh mesh;
  const auto start = std::chrono::steady_clock::now();
  const Status status = ReadMesh(path, &mesh);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), ::testing::StartsWith(path + ": face 1 has 0 vertices"));
  EXPECT_EQ(status.message().find('\n'), std::string::npos);
  EXPECT_LT(seconds, 1.0);

  // The same header shape with valid data reads: the empty element is ignored.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement nothing 2147483647\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const Status ok = ParseMesh(ply, "empty_element.ply", &mesh);
  ASSERT_TRUE(ok.ok()) << ok.message();
  EXPECT_EQ(mesh.n_vertices(), 3u);
  EXPECT_EQ(mesh.n_faces(), 1u);
}

}  // namespace
}  // namespace sft
