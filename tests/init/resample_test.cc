// Surface resampling (src/init/resample.h): a sphere comes back as a sphere, a fold is removed,
// Poisson's closure of an unseen part is trimmed to the visual hull, and bad inputs (a mesh that no
// view sees, a flat one, no views, bad options) are clear errors.
#include "src/init/resample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numeric>
#include <string>

#include "src/init/view_samples.h"
#include "src/render/camera_rig.h"
#include "src/render/scene.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

constexpr double kRadius = 1.0;
constexpr double kFov = 40.0;  // degrees.
constexpr double kFill = 0.6;  // the sphere's radius fills this fraction of the half image.

// A latitude-longitude sphere of kRadius: `rows` bands of polar angle, `columns` of azimuth,
// outward winding. Vertex positions come from `place(θ, φ)`; the plain sphere by default.
TriMesh UvSphere(int rows, int columns,
                 const std::function<Eigen::Vector3d(double, double)>& place) {
  TriMesh mesh;
  auto add = [&](const Eigen::Vector3d& p) { return mesh.add_vertex({p.x(), p.y(), p.z()}); };
  const TriMesh::VertexHandle north = add(place(0.0, 0.0));
  std::vector<TriMesh::VertexHandle> ring;  // (rows − 1) rings of `columns` vertices.
  for (int r = 1; r < rows; ++r) {
    for (int c = 0; c < columns; ++c)
      ring.push_back(add(place(M_PI * r / rows, 2 * M_PI * c / columns)));
  }
  const TriMesh::VertexHandle south = add(place(M_PI, 0.0));
  auto at = [&](int r, int c) { return ring[(r - 1) * columns + (c % columns)]; };
  for (int c = 0; c < columns; ++c) {
    mesh.add_face(north, at(1, c), at(1, c + 1));
    for (int r = 1; r + 1 < rows; ++r) {
      mesh.add_face(at(r, c), at(r + 1, c), at(r + 1, c + 1));
      mesh.add_face(at(r, c), at(r + 1, c + 1), at(r, c + 1));
    }
    mesh.add_face(south, at(rows - 1, c + 1), at(rows - 1, c));
  }
  return mesh;
}

Eigen::Vector3d SpherePoint(double theta, double phi, double radius) {
  return radius * Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                  std::cos(theta));
}

TriMesh PlainSphere() {
  return UvSphere(48, 96, [](double t, double p) { return SpherePoint(t, p, kRadius); });
}

// The fold's band of polar angles [kFoldStart, kFoldStart + kFoldWidth], its amplitude (radians)
// and how far its inverted layer stands out (relative to kRadius).
constexpr double kFoldStart = M_PI / 3;
constexpr double kFoldWidth = M_PI / 3;
constexpr double kFoldAmplitude = 0.35;
constexpr double kFoldBump = 0.02;

// A sphere with a Z-fold: polar angles in the band map through θ → θ + A·sin(2π(θ − start)/W),
// which decreases where cos(2π(θ − start)/W) < −W/(2πA). The rows there run backwards, so their
// faces are wound inwards: three layers cover part of the band, the middle one inverted. The
// middle layer stands out by up to kFoldBump·R (zero at the creases), so that the cameras see it
// first and hit the back faces of an inverted sheet.
TriMesh FoldedSphere() {
  const double k = 2 * M_PI / kFoldWidth;
  const double steepest_backwards = kFoldAmplitude * k - 1;  // −(smallest slope), > 0.
  return UvSphere(48, 96, [=](double t, double p) {
    if (t < kFoldStart || t > kFoldStart + kFoldWidth) return SpherePoint(t, p, kRadius);
    const double a = k * (t - kFoldStart);
    const double slope = 1 + kFoldAmplitude * k * std::cos(a);
    const double bump = kFoldBump * std::max(0.0, -slope) / steepest_backwards;
    return SpherePoint(t + kFoldAmplitude * std::sin(a), p, kRadius * (1 + bump));
  });
}

// Views from Fibonacci directions k of n (only those with z ≥ min_z), res × res pixels.
std::vector<ViewSetup> OrbitViews(int n, int res, double min_z = -1.0) {
  std::vector<ViewSetup> views;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d direction = FibonacciSphereDirection(k, n);
    if (direction.z() < min_z) continue;
    views.push_back(testing::LookAtView(OrbitDistance(kRadius, kFov, kFill) * direction,
                                        Eigen::Vector3d::Zero(), res, OrbitFocal(res, kFov)));
  }
  return views;
}

// Carving views of `mesh` seen from `views`: a pixel is object when the ray through its centre
// hits the mesh.
std::vector<CarvingView> CarvingViewsOf(const TriMesh& mesh, const std::vector<ViewSetup>& views) {
  const RenderScene scene(mesh);
  std::vector<CarvingView> carving;
  for (const ViewSetup& view : views) {
    const Rigid3d world_from_cam = view.cam_from_world.Inverse();
    const Camera& camera = view.camera;
    Image mask(camera.width, camera.height, 1);
    for (int y = 0; y < camera.height; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        const Eigen::Vector3d ray = camera.CamFromImage(Eigen::Vector2d(x + 0.5, y + 0.5));
        const Eigen::Vector3d d = (world_from_cam.rotation * ray).normalized();
        mask.at(x, y) = scene.Intersect(world_from_cam.translation, d, 0.0, 1e30).hit ? 1.f : 0.f;
      }
    }
    carving.emplace_back();
    const Status status = MakeCarvingView("view " + std::to_string(carving.size() - 1), camera,
                                          view.cam_from_world, mask, &carving.back());
    EXPECT_TRUE(status.ok()) << status.message();
  }
  return carving;
}

// A closed cylinder around z with flat caps fanned from their centres, outward winding.
TriMesh Cylinder(double radius, double half_height, int segments, int stacks) {
  TriMesh mesh;
  auto add = [&](double x, double y, double z) { return mesh.add_vertex({x, y, z}); };
  std::vector<TriMesh::VertexHandle> ring;  // (stacks + 1) rings from z = −half_height up.
  for (int k = 0; k <= stacks; ++k) {
    const double z = -half_height + 2.0 * half_height * k / stacks;
    for (int c = 0; c < segments; ++c) {
      const double phi = 2 * M_PI * c / segments;
      ring.push_back(add(radius * std::cos(phi), radius * std::sin(phi), z));
    }
  }
  auto at = [&](int k, int c) { return ring[k * segments + c % segments]; };
  const TriMesh::VertexHandle bottom = add(0, 0, -half_height), top = add(0, 0, half_height);
  for (int c = 0; c < segments; ++c) {
    for (int k = 0; k < stacks; ++k) {
      mesh.add_face(at(k, c), at(k, c + 1), at(k + 1, c + 1));
      mesh.add_face(at(k, c), at(k + 1, c + 1), at(k + 1, c));
    }
    mesh.add_face(bottom, at(0, c + 1), at(0, c));
    mesh.add_face(top, at(stacks, c), at(stacks, c + 1));
  }
  return mesh;
}

// Largest |‖p‖ − kRadius| over the vertices.
double MaxRadialDeviation(const TriMesh& mesh) {
  double deviation = 0.0;
  for (auto vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    deviation = std::max(deviation, std::abs(p.norm() - kRadius));
  }
  return deviation;
}

// Faces whose geometric normal points inwards (n · centroid ≤ 0).
int InwardFaces(const TriMesh& mesh) {
  int inward = 0;
  for (auto fh : mesh.faces()) {
    std::vector<Eigen::Vector3d> p;
    for (auto vh : mesh.fv_range(fh)) {
      const auto& q = mesh.point(vh);
      p.emplace_back(q[0], q[1], q[2]);
    }
    const Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]);
    inward += normal.dot(p[0] + p[1] + p[2]) <= 0;
  }
  return inward;
}

// Edge-connected components of the faces.
int Components(const TriMesh& mesh) {
  std::vector<int> parent(mesh.n_faces());
  std::iota(parent.begin(), parent.end(), 0);
  std::function<int(int)> find = [&](int x) {
    return parent[x] == x ? x : parent[x] = find(parent[x]);
  };
  for (auto eh : mesh.edges()) {
    const auto h0 = mesh.halfedge_handle(eh, 0), h1 = mesh.halfedge_handle(eh, 1);
    if (mesh.is_boundary(h0) || mesh.is_boundary(h1)) continue;
    parent[find(mesh.face_handle(h0).idx())] = find(mesh.face_handle(h1).idx());
  }
  int roots = 0;
  for (int f = 0; f < static_cast<int>(parent.size()); ++f) roots += find(f) == f;
  return roots;
}

void ExpectClosedSingleOutward(const TriMesh& mesh) {
  std::string why;
  EXPECT_TRUE(IsClosedManifold(mesh, &why)) << why;
  EXPECT_EQ(Components(mesh), 1);
  EXPECT_GT(EnclosedVolume(mesh), 0.0);
}

TEST(ResampleTest, ThinningKeepsOneSamplePerCellAndNormalDirection) {
  // Cells of side 1 from the samples' lowest corner (0.1, 0.1, 0.1): the first cell's centre is
  // (0.6, 0.6, 0.6).
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const std::vector<OrientedPoint> samples = {
      {{0.10, 0.10, 0.10}, up},   // first cell, +z, 0.87 from the centre.
      {{0.40, 0.45, 0.50}, up},   // same cell and direction, 0.27 from the centre: kept.
      {{0.40, 0.45, 0.50}, -up},  // the other side of a thin sheet: kept too.
      {{1.50, 0.50, 0.50}, up},   // the next cell along x.
  };
  const std::vector<OrientedPoint> kept = ThinSamples(samples, 1.0);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0].position, samples[1].position);
  EXPECT_EQ(kept[0].normal, up);
  EXPECT_EQ(kept[1].normal, -up);
  EXPECT_EQ(kept[2].position, samples[3].position);
}

// Bound on the radial deviation from the sphere of a result resampled at spacing h (the views of
// OrbitViews at 96² pixels). The samples are exact ray hits on the input, whose faces lie within
// the chord sag s ≈ R·(Δ/2)² ≈ 0.001·R of the sphere (Δ = 3.75°, the UV sphere's step). The pixel
// footprint at the sphere, (distance − R) / focal ≈ 0.027·R, is finer than every h used here, so
// every cell of side h on the visible surface holds a sample and the Poisson spacing is h, not
// the pixels'. Poisson reconstruction at spacing h smooths the indicator over about h: on a
// surface of curvature 1/R its level set moves by O(h²/R), and the two linear interpolations
// (CGAL's tetrahedra, then the grid) add about h²/(8R) each; with h/R ≈ 0.085 these are ≈ 0.1·h.
// The bound allows 0.25·h, half of the half-voxel error that a level set misplaced by a voxel's
// sign would show. Measured: 0.16·h for the plain sphere.
double DeviationBound(double h) { return 0.001 * kRadius + 0.25 * h; }

TEST(ResampleTest, SphereComesBackClosedAndNearTheSphere) {
  ResampleOptions options;
  options.faces = 4000;
  TriMesh out;
  ResampleReport report;
  const Status status =
      ResampleSurface(PlainSphere(), OrbitViews(12, 96), nullptr, options, &out, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectClosedSingleOutward(out);
  EXPECT_EQ(InwardFaces(out), 0);
  EXPECT_EQ(report.back_face_hits, 0);
  EXPECT_LE(report.faces_after, options.faces);
  const double deviation = MaxRadialDeviation(out);
  RecordProperty("points", report.points);
  RecordProperty("max_deviation_over_h", std::to_string(deviation / report.spacing));
  EXPECT_LT(deviation, DeviationBound(report.spacing));
  // A mean inward shift within the bound changes the volume by at most 3·bound/R.
  const double volume = 4.0 / 3.0 * M_PI * std::pow(kRadius, 3);
  EXPECT_NEAR(EnclosedVolume(out), volume, 3 * DeviationBound(report.spacing) * volume);
}

TEST(ResampleTest, FoldIsRemoved) {
  const TriMesh folded = FoldedSphere();
  ASSERT_GT(InwardFaces(folded), 500);  // the fold is there: ~5 of 48 rows run backwards.
  ResampleOptions options;
  options.faces = 4000;
  TriMesh out;
  ResampleReport report;
  const Status status =
      ResampleSurface(folded, OrbitViews(12, 96), nullptr, options, &out, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_GT(report.back_face_hits, 100);  // the cameras saw the inverted layer.
  ExpectClosedSingleOutward(out);
  EXPECT_EQ(InwardFaces(out), 0);
  const double deviation = MaxRadialDeviation(out);
  RecordProperty("max_deviation_over_h", std::to_string(deviation / report.spacing));
  // The cameras see the inverted layer standing out by up to kFoldBump·R: the result follows it.
  EXPECT_LT(deviation, DeviationBound(report.spacing) + kFoldBump * kRadius);
}

// Largest |z| over the vertices.
double MaxAbsZ(const TriMesh& mesh) {
  double z = 0.0;
  for (auto vh : mesh.vertices()) z = std::max(z, std::abs(mesh.point(vh)[2]));
  return z;
}

TEST(ResampleTest, UnseenPartIsTrimmedToTheVisualHull) {
  // A squat cylinder seen by rays only from a ring of cameras level with its middle: no ray
  // reaches the caps, and Poisson closes the open tube with domes. The masks come from views
  // all around, so the visual hull has (nearly) flat caps.
  constexpr double kHalfHeight = 0.6;
  const TriMesh cylinder = Cylinder(0.7, kHalfHeight, 96, 24);
  std::vector<ViewSetup> ring;
  for (int k = 0; k < 12; ++k) {
    const double phi = 2 * M_PI * k / 12;
    const Eigen::Vector3d eye =
        OrbitDistance(kRadius, kFov, kFill) * Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0);
    ring.push_back(testing::LookAtView(eye, Eigen::Vector3d::Zero(), 96, OrbitFocal(96, kFov)));
  }
  const std::vector<CarvingView> hull = CarvingViewsOf(cylinder, OrbitViews(24, 96));
  ResampleOptions options;
  options.faces = 4000;
  TriMesh untrimmed, trimmed;
  ResampleReport untrimmed_report, trimmed_report;
  Status status = ResampleSurface(cylinder, ring, nullptr, options, &untrimmed, &untrimmed_report);
  ASSERT_TRUE(status.ok()) << status.message();
  status = ResampleSurface(cylinder, ring, &hull, options, &trimmed, &trimmed_report);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectClosedSingleOutward(trimmed);
  EXPECT_EQ(trimmed_report.hull_views, 24);
  EXPECT_GT(trimmed_report.trimmed_voxels, 0);
  const double h = trimmed_report.spacing;
  RecordProperty("untrimmed_cap_over_h", std::to_string((MaxAbsZ(untrimmed) - kHalfHeight) / h));
  RecordProperty("trimmed_cap_over_h", std::to_string((MaxAbsZ(trimmed) - kHalfHeight) / h));
  // Poisson's domes rise well above the caps (about 3.5 h)...
  EXPECT_GT(MaxAbsZ(untrimmed), kHalfHeight + 2 * h);
  // ... and the hull cuts them back to within a voxel: half of the hull's voxel for its level
  // set, the visual hull's own excess over the caps (about 0.3 h from these 24 views) and the
  // grid's interpolation.
  EXPECT_LT(MaxAbsZ(trimmed), kHalfHeight + h);
}

TEST(ResampleTest, NoViewSeeingTheMeshAndOtherBadInputsAreErrors) {
  // Cameras around the sphere looking away from it.
  std::vector<ViewSetup> views;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d eye = 3.0 * FibonacciSphereDirection(k, 4);
    views.push_back(testing::LookAtView(eye, 2.0 * eye, 32, OrbitFocal(32, kFov)));
  }
  TriMesh out;
  ResampleReport report;
  Status status = ResampleSurface(PlainSphere(), views, nullptr, ResampleOptions(), &out, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("no view sees the mesh"), std::string::npos) << status.message();
  EXPECT_GT(report.rays, 0);
  EXPECT_EQ(report.hits, 0);

  status = ResampleSurface(PlainSphere(), {}, nullptr, ResampleOptions(), &out, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("no views"), std::string::npos) << status.message();

  status = ResampleSurface(TriMesh(), OrbitViews(4, 32), nullptr, ResampleOptions(), &out, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("no faces"), std::string::npos) << status.message();

  // A flat quad seen from above: samples that enclose no volume.
  TriMesh quad;
  std::vector<TriMesh::VertexHandle> corners;
  for (const Eigen::Vector3d& p : testing::QuadPositions(0.5)) {
    corners.push_back(quad.add_vertex({p.x(), p.y(), p.z()}));
  }
  for (const Eigen::Vector3i& f : testing::QuadFaces()) {
    quad.add_face(corners[f[0]], corners[f[1]], corners[f[2]]);
  }
  ResampleOptions fine;
  fine.faces = 20000;  // enough cells on the quad for the Poisson solve to be reached.
  status =
      ResampleSurface(quad, {testing::TopDownView(2.0, 64, 64.0)}, nullptr, fine, &out, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("flat"), std::string::npos) << status.message();

  ResampleOptions bad;
  bad.pixel_stride = 0;
  status = ResampleSurface(PlainSphere(), OrbitViews(4, 32), nullptr, bad, &out, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("pixel_stride"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace sft
