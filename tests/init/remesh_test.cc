// Remeshing at a target edge length (src/init/remesh.h), both methods: a sphere (edge lengths,
// face count, orientation, distance to the input), a cube with a zero-area face, two tetrahedra
// sharing a vertex, the max_faces cap, and the errors.
#include "src/init/remesh.h"

// CGAL 5.5's distance.h calls CGAL::midpoint on Point_3 without including its declaration.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "src/init/cgal_surface_mesh.h"
#include "src/init/surface_cleanup.h"
#include "tests/testing/meshes.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

constexpr double kEquilateralArea = 0.43301270189221932;  // √3/4.

TriMesh ReadFixture(const std::string& name) {
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(testing::DataDir() + "/meshes/" + name, &mesh).ok()) << name;
  return mesh;
}

// The vertices, edge midpoints and face centroids of `mesh`.
std::vector<CgalPoint> SamplePoints(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  std::vector<CgalPoint> points;
  auto add = [&](const Eigen::Vector3d& p) { points.emplace_back(p.x(), p.y(), p.z()); };
  for (const Eigen::Vector3d& p : positions) add(p);
  for (const Eigen::Vector3i& f : faces) {
    add((positions[f[0]] + positions[f[1]] + positions[f[2]]) / 3.0);
    for (int c = 0; c < 3; ++c) add(0.5 * (positions[f[c]] + positions[f[(c + 1) % 3]]));
  }
  return points;
}

// A Hausdorff-like distance between the two surfaces: the largest distance from the sample points
// of either to the other surface (CGAL max_distance_to_triangle_mesh, exact closest points).
double SampledHausdorffDistance(const TriMesh& a, const TriMesh& b) {
  SurfaceMesh surface_a, surface_b;
  SoupRepairReport report;
  EXPECT_TRUE(TriMeshToSurfaceMesh(a, &surface_a, &report).ok());
  EXPECT_TRUE(TriMeshToSurfaceMesh(b, &surface_b, &report).ok());
  namespace PMP = CGAL::Polygon_mesh_processing;
  return std::max(
      PMP::max_distance_to_triangle_mesh<CGAL::Sequential_tag>(SamplePoints(a), surface_b),
      PMP::max_distance_to_triangle_mesh<CGAL::Sequential_tag>(SamplePoints(b), surface_a));
}

// Faces whose normal points towards the origin (inwards on a star-shaped surface around it),
// and faces with zero area.
void CountBadFaces(const TriMesh& mesh, int* inward, int* zero_area) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  *inward = *zero_area = 0;
  for (const Eigen::Vector3i& f : faces) {
    const Eigen::Vector3d n =
        (positions[f[1]] - positions[f[0]]).cross(positions[f[2]] - positions[f[0]]);
    const Eigen::Vector3d centroid = (positions[f[0]] + positions[f[1]] + positions[f[2]]) / 3.0;
    *inward += n.dot(centroid) <= 0.0;
    *zero_area += n.norm() == 0.0;
  }
}

class RemeshMethodTest : public ::testing::TestWithParam<RemeshMethod> {};

// The unit icosphere of 1280 faces (edges 0.11..0.14) remeshed at L = 0.08: about 1.9x finer.
// Bounds:
//  - mean edge length within 10% of L: both methods aim at L (isotropic remeshing keeps edges in
//    [4/5 L, 4/3 L] and settles a few percent below L; decimation to A/(√3/4·L²) faces gives mean
//    L for equilateral faces, more for elongated ones, which the aspect-ratio guard limits);
//  - face count: adaptive within 1% of A/(√3/4·L²), its decimation target; isotropic within 20%,
//    since its count follows its mean edge length (−6% in length is +13% in faces);
//  - sampled Hausdorff distance to the input at most the sagitta of a 2L chord on the unit sphere,
//    (2L)²/8 = 0.0032, plus the input's own sagitta (its longest edge 0.14: 0.0025): both
//    surfaces are within their sagitta of the sphere, vertices on it.
TEST_P(RemeshMethodTest, EdgeLengthFaceCountOrientationAndDistance) {
  const TriMesh sphere = ReadFixture("icosphere_r1_1280f.obj");
  RemeshOptions options;
  options.method = GetParam();
  options.target_edge_length = 0.08;
  TriMesh out;
  RemeshReport report;
  const Status status = Remesh(sphere, options, &out, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  const double area = SurfaceArea(sphere);
  const double implied_faces = area / (kEquilateralArea * 0.08 * 0.08);
  std::printf("%s: %d faces (implied %.0f), edges mean %.4f min %.4f max %.4f, %.3f s\n",
              RemeshMethodName(GetParam()), report.faces_after, implied_faces,
              report.mean_edge_length_after, report.min_edge_length_after,
              report.max_edge_length_after, report.seconds);
  EXPECT_EQ(report.faces_before, 1280);
  EXPECT_EQ(report.faces_after, static_cast<int>(out.n_faces()));
  EXPECT_EQ(report.vertices_after, static_cast<int>(out.n_vertices()));
  EXPECT_EQ(report.non_manifold_vertices_split, 0);
  EXPECT_DOUBLE_EQ(report.edge_length_used, 0.08);
  EXPECT_NEAR(report.mean_edge_length_after, 0.08, 0.1 * 0.08);
  const double face_tolerance = GetParam() == RemeshMethod::kAdaptive ? 0.01 : 0.2;
  EXPECT_NEAR(report.faces_after, implied_faces, face_tolerance * implied_faces);
  std::string why;
  EXPECT_TRUE(IsClosedManifold(out, &why)) << why;
  EXPECT_EQ(static_cast<int>(out.n_vertices()) - static_cast<int>(out.n_edges()) +
                static_cast<int>(out.n_faces()),
            2);  // still a sphere (Euler characteristic).
  int inward = 0, zero_area = 0;
  CountBadFaces(out, &inward, &zero_area);
  EXPECT_EQ(inward, 0);
  EXPECT_EQ(zero_area, 0);
  EXPECT_GT(EnclosedVolume(out), 0.0);
  EXPECT_NEAR(EnclosedVolume(out), EnclosedVolume(sphere), 0.02 * EnclosedVolume(sphere));
  const double hausdorff = SampledHausdorffDistance(sphere, out);
  std::printf("  Hausdorff distance to the input %.5f\n", hausdorff);
  EXPECT_LT(hausdorff, 0.0032 + 0.0025);
}

INSTANTIATE_TEST_SUITE_P(Methods, RemeshMethodTest,
                         ::testing::Values(RemeshMethod::kAdaptive, RemeshMethod::kIsotropic),
                         [](const ::testing::TestParamInfo<RemeshMethod>& info) {
                           return std::string(RemeshMethodName(info.param));
                         });

// A closed 2x2x2 cube whose face (a, b, c) is split at the midpoint m of edge ab, with the
// zero-area face (a, b, m) keeping it closed.
TriMesh CubeWithZeroAreaFace() {
  TriMesh cube = ReadFixture("cube_2x2x2_12f.obj");
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(cube, &positions, &faces);
  const Eigen::Vector3i abc = faces[0];
  const int m = static_cast<int>(positions.size());
  positions.push_back(0.5 * (positions[abc[0]] + positions[abc[1]]));  // exact: coordinates ±1.
  faces[0] = Eigen::Vector3i(abc[0], m, abc[2]);
  faces.emplace_back(m, abc[1], abc[2]);
  faces.emplace_back(abc[0], abc[1], m);
  TriMesh mesh;
  EXPECT_TRUE(ArraysToTriMesh(positions, faces, &mesh).ok());
  std::string why;
  EXPECT_TRUE(IsClosedManifold(mesh, &why)) << why;
  return mesh;
}

TEST_P(RemeshMethodTest, ZeroAreaFaceInAClosedCube) {
  const TriMesh cube = CubeWithZeroAreaFace();
  RemeshOptions options;
  options.method = GetParam();
  options.target_edge_length = 0.4;
  TriMesh out;
  RemeshReport report;
  const Status status = Remesh(cube, options, &out, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  std::string why;
  EXPECT_TRUE(IsClosedManifold(out, &why)) << why;
  int inward = 0, zero_area = 0;
  CountBadFaces(out, &inward, &zero_area);
  EXPECT_EQ(inward, 0);
  EXPECT_EQ(zero_area, 0);
  // Projection onto the input keeps the cube's volume to a few percent (isotropic remeshing
  // rounds the edges a little).
  EXPECT_NEAR(EnclosedVolume(out), 8.0, 0.05 * 8.0);
}

// Two unit right-corner tetrahedra (one the other's point reflection) sharing the origin, or also
// the edge from the origin to (0, 0, 1) with the second one turned, read from an OBJ file: OpenMesh
// cannot hold the non-manifold vertex or edge, so the TriMesh comes with vertex copies there.
TriMesh TetrahedraSharing(bool edge) {
  testing::TempDir dir;
  testing::Triangles tetrahedra;
  tetrahedra.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tetrahedra.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  testing::Triangles second = tetrahedra;
  for (Eigen::Vector3d& p : second.positions) {
    p = edge ? Eigen::Vector3d(-p.x(), -p.y(), p.z()) : Eigen::Vector3d(-p);
  }
  if (!edge) {  // a point reflection reverses the orientation.
    for (Eigen::Vector3i& f : second.faces) std::swap(f[1], f[2]);
  }
  tetrahedra.Append(second);
  const std::string path = dir.Join("tetrahedra.obj");
  testing::WriteObj(path, tetrahedra);
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(path, &mesh).ok());
  return mesh;
}

TEST_P(RemeshMethodTest, TetrahedraSharingAVertexOrAnEdgeAreSplitThere) {
  for (bool edge : {false, true}) {
    SCOPED_TRACE(edge ? "edge" : "vertex");
    const TriMesh tetrahedra = TetrahedraSharing(edge);
    ASSERT_EQ(tetrahedra.n_faces(), 8u);
    ASSERT_GT(tetrahedra.n_vertices(), edge ? 6u : 7u);  // the reader's vertex copies.
    RemeshOptions options;
    options.method = GetParam();
    options.target_edge_length = 0.2;
    TriMesh out;
    RemeshReport report;
    const Status status = Remesh(tetrahedra, options, &out, &report);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_GT(report.merged_vertices, 0);  // the reader's copies, welded back.
    EXPECT_EQ(report.non_manifold_vertices_split, edge ? 2 : 1);
    std::string why;
    EXPECT_TRUE(IsClosedManifold(out, &why)) << why;
    // Two spheres: Euler characteristic 4.
    EXPECT_EQ(static_cast<int>(out.n_vertices()) - static_cast<int>(out.n_edges()) +
                  static_cast<int>(out.n_faces()),
              4);
    EXPECT_NEAR(EnclosedVolume(out), 2.0 / 6.0, 0.1 * 2.0 / 6.0);
    EXPECT_GT(out.n_faces(), 100u);
  }
}

// An implied face count above max_faces raises the edge length to what max_faces allows.
TEST_P(RemeshMethodTest, MaxFacesCapsTheOutput) {
  const TriMesh sphere = ReadFixture("icosphere_r1_320f.obj");
  RemeshOptions options;
  options.method = GetParam();
  options.target_edge_length = 0.005;  // 1.1 million faces implied.
  options.max_faces = 2000;
  TriMesh out;
  RemeshReport report;
  const Status status = Remesh(sphere, options, &out, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_LE(report.faces_after, 2000);
  EXPECT_GE(report.faces_after, 1600);
  EXPECT_NEAR(report.edge_length_used, std::sqrt(SurfaceArea(sphere) / (kEquilateralArea * 2000)),
              1e-12);
  std::string why;
  EXPECT_TRUE(IsClosedManifold(out, &why)) << why;
}

TEST(RemeshTest, MethodNames) {
  for (RemeshMethod method : {RemeshMethod::kAdaptive, RemeshMethod::kIsotropic}) {
    RemeshMethod parsed =
        method == RemeshMethod::kAdaptive ? RemeshMethod::kIsotropic : RemeshMethod::kAdaptive;
    EXPECT_TRUE(RemeshMethodFromName(RemeshMethodName(method), &parsed));
    EXPECT_EQ(parsed, method);
  }
  RemeshMethod unchanged = RemeshMethod::kIsotropic;
  EXPECT_FALSE(RemeshMethodFromName("loop", &unchanged));
  EXPECT_EQ(unchanged, RemeshMethod::kIsotropic);
}

TEST(RemeshTest, ErrorsAreStatuses) {
  const TriMesh sphere = ReadFixture("icosphere_r1_320f.obj");
  TriMesh out;
  RemeshOptions options;
  std::string why;
  EXPECT_FALSE(options.Check(&why));  // no target edge length.
  EXPECT_NE(Remesh(sphere, options, &out, nullptr).message().find("target_edge_length"),
            std::string::npos);
  options.target_edge_length = 0.1;
  EXPECT_TRUE(options.Check(&why)) << why;
  for (auto spoil : std::vector<void (*)(RemeshOptions*)>{
           [](RemeshOptions* o) { o->target_edge_length = std::nan(""); },
           [](RemeshOptions* o) { o->max_faces = 3; }, [](RemeshOptions* o) { o->iterations = 0; },
           [](RemeshOptions* o) { o->subdivision_ratio = 1.5; },
           [](RemeshOptions* o) { o->max_normal_deviation_degrees = 0.0; },
           [](RemeshOptions* o) { o->max_aspect_ratio = 1.0; }}) {
    RemeshOptions bad = options;
    spoil(&bad);
    EXPECT_FALSE(bad.Check(&why));
    EXPECT_FALSE(Remesh(sphere, bad, &out, nullptr).ok());
  }
  EXPECT_NE(Remesh(TriMesh(), options, &out, nullptr).message().find("no faces"),
            std::string::npos);
  TriMesh alias = sphere;
  EXPECT_FALSE(Remesh(alias, options, &alias, nullptr).ok());
  // Every face degenerate: nothing left to remesh.
  TriMesh flat;
  const auto a = flat.add_vertex({0, 0, 0});
  const auto b = flat.add_vertex({1, 0, 0});
  const auto c = flat.add_vertex({2, 0, 0});
  flat.add_face(a, b, c);
  const Status status = Remesh(flat, options, &out, nullptr);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("area"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace sft
