// Mesh accuracy measures (src/eval/mesh_metrics.h) on shapes whose distances are known in closed
// form: identical meshes, a sphere against a scaled and a translated copy, a two-sphere reference,
// and the same pair at another scale.
#include "src/eval/mesh_metrics.h"

#include <glog/logging.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

constexpr int kTestSamples = 100000;

TriMesh LoadSphere() {
  TriMesh mesh;
  const Status s = ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_1280f.obj", &mesh);
  CHECK(s.ok()) << s.message();
  return mesh;
}

// p ↦ scale·p + offset for every vertex.
TriMesh Transformed(const TriMesh& mesh, double scale, const Eigen::Vector3d& offset) {
  TriMesh out = mesh;
  for (TriMesh::VertexHandle v : out.vertices()) {
    TriMesh::Point& p = out.point(v);
    for (int c = 0; c < 3; ++c) p[c] = scale * p[c] + offset[c];
  }
  return out;
}

// The union of two meshes (vertex indices of `b` shifted).
TriMesh Union(const TriMesh& a, const TriMesh& b) {
  TriMesh out = a;
  std::vector<TriMesh::VertexHandle> handles;
  for (TriMesh::VertexHandle v : b.vertices()) handles.push_back(out.add_vertex(b.point(v)));
  for (TriMesh::FaceHandle f : b.faces()) {
    std::vector<TriMesh::VertexHandle> corners;
    for (TriMesh::VertexHandle v : b.fv_range(f)) corners.push_back(handles[v.idx()]);
    out.add_face(corners);
  }
  return out;
}

double Diagonal(const TriMesh& mesh) {
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  return (hi - lo).norm();
}

MeshMetricsOptions TestOptions(double tolerance = 0.01) {
  MeshMetricsOptions options;
  options.samples = kTestSamples;
  options.tolerance = tolerance;
  return options;
}

TEST(PointTriangleDistanceTest, RegionsOfTheTriangle) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_NEAR(PointTriangleDistance({0.2, 0.3, 0.5}, a, b, c), 0.5, 1e-15);   // above the face.
  EXPECT_NEAR(PointTriangleDistance({0.2, 0.3, -2.0}, a, b, c), 2.0, 1e-15);  // below it.
  EXPECT_NEAR(PointTriangleDistance({0.5, -1.0, 0.0}, a, b, c), 1.0, 1e-15);  // edge ab.
  EXPECT_NEAR(PointTriangleDistance({1.0, 1.0, 0.0}, a, b, c), std::sqrt(0.5), 1e-15);  // edge bc.
  EXPECT_NEAR(PointTriangleDistance({-3.0, -4.0, 0.0}, a, b, c), 5.0, 1e-15);           // corner a.
  EXPECT_NEAR(PointTriangleDistance({2.0, 0.0, 1.0}, a, b, c), std::sqrt(2.0), 1e-15);  // corner b.
  // Degenerate (collinear) triangle: the distance to the segment it covers.
  EXPECT_NEAR(PointTriangleDistance({0.5, 1.0, 0.0}, a, b, {0.5, 0, 0}), 1.0, 1e-15);
  EXPECT_NEAR(PointTriangleDistance({3.0, 0.0, 4.0}, a, a, a), 5.0, 1e-15);
}

TEST(SampleSurfaceTest, AreaUniformAndDeterministic) {
  // Two triangles of areas 1 and 3 (and a zero-area one that must get nothing).
  const std::vector<Eigen::Vector3d> p = {{0, 0, 0},  {2, 0, 0},  {0, 1, 0},  {10, 0, 0},
                                          {16, 0, 0}, {10, 1, 0}, {20, 0, 0}, {21, 0, 0}};
  const std::vector<Eigen::Vector3i> f = {{0, 1, 2}, {6, 7, 6}, {3, 4, 5}};
  const SurfaceSamples s = SampleSurface(p, f, 4000, 7, 0);
  int counts[3] = {0, 0, 0};
  Eigen::Vector3d centroid_small = Eigen::Vector3d::Zero();
  for (int k = 0; k < 4000; ++k) {
    ++counts[s.faces[k]];
    if (s.faces[k] == 0) centroid_small += s.points[k];
  }
  // Stratified by area: exact shares up to ±1.
  EXPECT_NEAR(counts[0], 1000, 1);
  EXPECT_EQ(counts[1], 0);
  EXPECT_NEAR(counts[2], 3000, 1);
  // Uniform inside the triangle: the sample mean is near the centroid (2/3, 1/3, 0); the standard
  // error of each coordinate is ≈ 0.47/√1000 ≈ 0.015.
  centroid_small /= counts[0];
  EXPECT_NEAR(centroid_small.x(), 2.0 / 3.0, 0.05);
  EXPECT_NEAR(centroid_small.y(), 1.0 / 3.0, 0.025);
  const SurfaceSamples again = SampleSurface(p, f, 4000, 7, 0);
  const SurfaceSamples other = SampleSurface(p, f, 4000, 7, 1);
  EXPECT_EQ(again.points, s.points);
  EXPECT_NE(other.points, s.points);
}

// A mesh against itself: every sample lies on the other surface. The samples of the two sides
// differ (separate streams), so a distance is not exactly 0 only when none of the 8 nearest
// samples of the other side lies on the query's own face; then it is the distance to a
// neighbouring face, at most (distance to the shared edge)·sin(dihedral angle) ≈ sample spacing ×
// the icosphere's 0.08 rad dihedral deviation, i.e. ~1e-5 of the diagonal at 1e5 samples.
TEST(MeshMetricsTest, IdenticalMeshes) {
  const TriMesh sphere = LoadSphere();
  MeshMetrics m;
  ASSERT_TRUE(ComputeMeshMetrics(sphere, sphere, TestOptions(), &m).ok());
  EXPECT_EQ(m.precision, 1.0);
  EXPECT_EQ(m.recall, 1.0);
  EXPECT_EQ(m.f1, 1.0);
  EXPECT_LT(m.chamfer, 1e-5);
  EXPECT_EQ(m.samples, kTestSamples);
  EXPECT_NEAR(m.reference_diagonal, Diagonal(sphere), 1e-12);
}

// Reference S (convex, centred at the origin), mesh (1+d)·S. A point of face f of S is at distance
// d·h_f from the plane of the scaled face (h_f its plane's distance from the centre), and that is
// its distance to (1+d)·S up to a thin band near edges; the same holds the other way. The
// area-weighted mean of h_f is 3V/A, so both directed means are d·3V/A / diagonal.
TEST(MeshMetricsTest, ScaledSphere) {
  const TriMesh sphere = LoadSphere();
  double volume = 0.0, area = 0.0;
  for (TriMesh::FaceHandle f : sphere.faces()) {
    std::vector<Eigen::Vector3d> c;
    for (TriMesh::VertexHandle v : sphere.fv_range(f)) {
      c.emplace_back(sphere.point(v)[0], sphere.point(v)[1], sphere.point(v)[2]);
    }
    volume += c[0].dot(c[1].cross(c[2])) / 6.0;
    area += 0.5 * (c[1] - c[0]).cross(c[2] - c[0]).norm();
  }
  const double d = 0.05;
  const double expected = d * 3.0 * volume / area / Diagonal(sphere);  // ≈ 0.0144
  const TriMesh scaled = Transformed(sphere, 1.0 + d, Eigen::Vector3d::Zero());
  MeshMetrics m;
  ASSERT_TRUE(ComputeMeshMetrics(sphere, scaled, TestOptions(0.01), &m).ok());
  EXPECT_NEAR(m.mean_reference_to_mesh, expected, 0.005 * expected);
  EXPECT_NEAR(m.mean_mesh_to_reference, expected, 0.005 * expected);
  EXPECT_NEAR(m.chamfer, expected, 0.005 * expected);
  // Every distance is ≈ 0.0144 > 0.01: nothing within tolerance; all within 0.02.
  EXPECT_EQ(m.f1, 0.0);
  ASSERT_TRUE(ComputeMeshMetrics(sphere, scaled, TestOptions(0.02), &m).ok());
  EXPECT_EQ(m.precision, 1.0);
  EXPECT_EQ(m.recall, 1.0);
}

// Mesh = S + t. For a sphere of radius r, the point r·u is at distance |‖r·u − t‖ − r| from the
// translated sphere, and u·t̂ = c is uniform on [−1, 1] (Archimedes), so the mean distance is
// ½∫|√(r² − 2r|t|c + |t|²) − r| dc ≈ |t|/2 and the fraction within τ is ≈ τ/|t|. Both are
// integrated here by the midpoint rule; the icosphere deviates from its sphere by < 1e-3 of the
// diagonal, which moves the mean by far less than the 1% tolerance.
TEST(MeshMetricsTest, TranslatedSphere) {
  const TriMesh sphere = LoadSphere();
  const double diagonal = Diagonal(sphere);
  const double t = 0.02 * diagonal, r = 1.0, tau = 0.01;
  const TriMesh moved = Transformed(sphere, 1.0, t * Eigen::Vector3d(1, 2, 3).normalized());
  double mean = 0.0, within = 0.0;
  const int steps = 200000;
  for (int k = 0; k < steps; ++k) {
    const double c = -1.0 + 2.0 * (k + 0.5) / steps;
    const double distance = std::abs(std::sqrt(r * r - 2.0 * r * t * c + t * t) - r) / diagonal;
    mean += distance / steps;
    within += (distance < tau) ? 1.0 / steps : 0.0;
  }
  MeshMetrics m;
  ASSERT_TRUE(ComputeMeshMetrics(sphere, moved, TestOptions(tau), &m).ok());
  EXPECT_NEAR(m.mean_mesh_to_reference, mean, 0.01 * mean);
  EXPECT_NEAR(m.mean_reference_to_mesh, mean, 0.01 * mean);
  EXPECT_NEAR(m.chamfer, mean, 0.01 * mean);
  EXPECT_NEAR(m.chamfer, 0.01, 0.001);  // ≈ |t|/2 in diagonal units.
  // Binomial noise of a fraction near 0.5 at 1e5 samples: 0.0016.
  EXPECT_NEAR(m.precision, within, 0.01);
  EXPECT_NEAR(m.recall, within, 0.01);
  EXPECT_NEAR(m.f1, within, 0.01);
  EXPECT_NEAR(within, 0.5, 0.02);
}

// Reference = two spheres far apart, mesh = one of them: all of the mesh is correct (precision 1)
// and it covers half of the reference's area (recall 0.5; the spheres have equal areas and the
// sampling is stratified by area, so the share is exact up to 1/samples).
TEST(MeshMetricsTest, PrecisionRecallAsymmetry) {
  const TriMesh sphere = LoadSphere();
  const TriMesh two = Union(sphere, Transformed(sphere, 1.0, Eigen::Vector3d(4, 0, 0)));
  MeshMetrics m;
  ASSERT_TRUE(ComputeMeshMetrics(two, sphere, TestOptions(), &m).ok());
  EXPECT_EQ(m.precision, 1.0);
  EXPECT_NEAR(m.recall, 0.5, 2.0 / kTestSamples);
  EXPECT_NEAR(m.f1, 2.0 * 0.5 / 1.5, 1e-4);
  EXPECT_LT(m.mean_mesh_to_reference, 1e-5);
  EXPECT_GT(m.mean_reference_to_mesh, 0.2);  // half the samples are ≥ 2 radii (≥ 0.3) away.
  // Swapped roles swap precision and recall.
  MeshMetrics swapped;
  ASSERT_TRUE(ComputeMeshMetrics(sphere, two, TestOptions(), &swapped).ok());
  EXPECT_NEAR(swapped.precision, 0.5, 2.0 / kTestSamples);
  EXPECT_EQ(swapped.recall, 1.0);
}

// Scaling (and moving) both meshes together changes nothing: distances are in units of the
// reference's diagonal. (The translation avoids a coincidence: by (0.03, −0.05, 0.02) the faces
// with normal ∝ (−1, 1, 1) would be exactly 0.01 diagonals from their copies, putting all their
// samples on the threshold, where the last bit decides.)
TEST(MeshMetricsTest, ScaleInvariance) {
  const TriMesh sphere = LoadSphere();
  const TriMesh moved = Transformed(sphere, 1.0, Eigen::Vector3d(0.031, -0.047, 0.023));
  MeshMetrics small, large;
  ASSERT_TRUE(ComputeMeshMetrics(sphere, moved, TestOptions(), &small).ok());
  const Eigen::Vector3d offset(5000, -200, 30);
  ASSERT_TRUE(ComputeMeshMetrics(Transformed(sphere, 1000.0, offset),
                                 Transformed(moved, 1000.0, offset), TestOptions(), &large)
                  .ok());
  ASSERT_GT(small.f1, 0.1);  // a non-trivial case.
  ASSERT_LT(small.f1, 0.99);
  EXPECT_NEAR(large.f1, small.f1, 1e-9);
  EXPECT_NEAR(large.precision, small.precision, 1e-9);
  EXPECT_NEAR(large.recall, small.recall, 1e-9);
  EXPECT_NEAR(large.chamfer, small.chamfer, 1e-9 * small.chamfer);
  EXPECT_NEAR(large.reference_diagonal, 1000.0 * small.reference_diagonal, 1e-6);
}

TEST(MeshMetricsTest, SeedsGiveDeterministicAndConsistentNumbers) {
  const TriMesh sphere = LoadSphere();
  const TriMesh moved = Transformed(sphere, 1.0, Eigen::Vector3d(0.031, -0.047, 0.023));
  MeshMetricsOptions options = TestOptions();
  MeshMetrics a, b, c;
  ASSERT_TRUE(ComputeMeshMetrics(sphere, moved, options, &a).ok());
  ASSERT_TRUE(ComputeMeshMetrics(sphere, moved, options, &b).ok());
  options.seed = 1;
  ASSERT_TRUE(ComputeMeshMetrics(sphere, moved, options, &c).ok());
  EXPECT_EQ(a.f1, b.f1);
  EXPECT_EQ(a.chamfer, b.chamfer);
  EXPECT_NE(a.chamfer, c.chamfer);
  EXPECT_NEAR(a.f1, c.f1, 0.01);
  EXPECT_NEAR(a.chamfer, c.chamfer, 0.01 * a.chamfer);
}

TEST(MeshMetricsTest, InvalidInputsAreErrorsNamingTheMeshOrField) {
  const TriMesh sphere = LoadSphere();
  MeshMetrics m;
  MeshMetricsOptions options = TestOptions();
  for (double tolerance : {0.0, -0.1, std::nan(""), 1.5}) {
    options.tolerance = tolerance;
    const Status s = ComputeMeshMetrics(sphere, sphere, options, &m);
    EXPECT_FALSE(s.ok());
    EXPECT_THAT(s.message(), HasSubstr("tolerance"));
  }
  options = TestOptions();
  for (int samples : {0, 99, MeshMetricsOptions::kMaxSamples + 1}) {
    options.samples = samples;
    const Status s = ComputeMeshMetrics(sphere, sphere, options, &m);
    EXPECT_FALSE(s.ok());
    EXPECT_THAT(s.message(), HasSubstr("samples"));
  }
  const TriMesh empty;
  Status s = ComputeMeshMetrics(sphere, empty, TestOptions(), &m, "gt.ply", "ours.ply");
  EXPECT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("ours.ply"));
  s = ComputeMeshMetrics(empty, sphere, TestOptions(), &m, "gt.ply", "ours.ply");
  EXPECT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("gt.ply"));
  // All faces of zero area (collinear corners): nothing to sample.
  TriMesh flat;
  flat.add_face(flat.add_vertex({0, 0, 0}), flat.add_vertex({1, 0, 0}), flat.add_vertex({2, 0, 0}));
  s = ComputeMeshMetrics(sphere, flat, TestOptions(), &m, "gt.ply", "ours.ply");
  EXPECT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("ours.ply: every face has zero area"));
  // A reference collapsed to a point has no size to measure in.
  TriMesh point;
  point.add_face(point.add_vertex({1, 1, 1}), point.add_vertex({1, 1, 1}),
                 point.add_vertex({1, 1, 1}));
  s = ComputeMeshMetrics(point, sphere, TestOptions(), &m, "gt.ply", "ours.ply");
  EXPECT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("gt.ply: bounding box has zero diagonal"));
}

}  // namespace
}  // namespace sft
