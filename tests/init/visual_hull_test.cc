// Visual-hull carving (src/init): a sphere seen through exact masks (known answer), a bunny
// rendered by `sft synth` (F1 against the true mesh), and the surface clean-up.
#include "src/init/visual_hull.h"

#include <gtest/gtest.h>

#include <cmath>

#include "src/eval/mesh_metrics.h"
#include "src/init/initial_mesh.h"
#include "src/init/surface_cleanup.h"
#include "src/io/dataset.h"
#include "src/render/camera_rig.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

constexpr double kRadius = 0.3;

// A view of the sphere of kRadius at the origin from direction k of n, with an exact mask: a
// pixel is object when the ray through its centre hits the sphere. Odd views use SIMPLE_RADIAL
// with a barrel distortion so that carving must project through the distortion model.
CarvingView SphereView(int k, int n, int res) {
  Camera camera;
  camera.width = camera.height = res;
  const double f = OrbitFocal(res, 40.0);
  if (k % 2 == 0) {
    camera.model = CameraModel::kPinhole;
    camera.params = {f, f, 0.5 * res, 0.5 * res};
  } else {
    camera.model = CameraModel::kSimpleRadial;
    camera.params = {f, 0.5 * res, 0.5 * res, -0.08};
  }
  const Eigen::Vector3d eye = OrbitDistance(kRadius, 40.0, 0.6) * FibonacciSphereDirection(k, n);
  const Rigid3d cam_from_world = LookAt(eye, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  Image mask(res, res, 1);
  for (int y = 0; y < res; ++y) {
    for (int x = 0; x < res; ++x) {
      const Eigen::Vector3d ray = camera.CamFromImage(Eigen::Vector2d(x + 0.5, y + 0.5));
      if (ray.isZero()) continue;
      const Eigen::Vector3d d = (world_from_cam.rotation * ray).normalized();
      const Eigen::Vector3d o = world_from_cam.translation;
      const double b = o.dot(d);
      mask.at(x, y) = (b * b - (o.squaredNorm() - kRadius * kRadius)) > 0 ? 1.f : 0.f;
    }
  }
  CarvingView view;
  const Status status =
      MakeCarvingView("sphere view " + std::to_string(k), camera, cam_from_world, mask, &view);
  EXPECT_TRUE(status.ok()) << status.message();
  return view;
}

std::vector<CarvingView> SphereViews(int n, int res) {
  std::vector<CarvingView> views;
  for (int k = 0; k < n; ++k) views.push_back(SphereView(k, n, res));
  return views;
}

// The hull's surface as a closed mesh (OpenVDB extraction and the clean-up).
TriMesh HullMesh(const VisualHull& hull, SurfaceCleanupReport* report) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> triangles;
  EXPECT_TRUE(ExtractHullSurface(hull, &points, &triangles).ok());
  TriMesh mesh;
  EXPECT_TRUE(BuildClosedSurface(points, triangles, &mesh, report).ok());
  return mesh;
}

double HullVolume(const VisualHull& hull) {
  SurfaceCleanupReport report;
  return EnclosedVolume(HullMesh(hull, &report));
}

TEST(VisualHullTest, SphereFromManyViewsIsTheSphere) {
  const std::vector<CarvingView> views = SphereViews(60, 160);
  VisualHullOptions options;
  options.resolution = 64;
  VisualHull hull;
  const Status status = CarveVisualHull(views, options, nullptr, &hull);
  ASSERT_TRUE(status.ok()) << status.message();
  const double h = hull.box.voxel_size;
  // The box hugs the sphere: its side is the diameter plus at most ~3 coarse voxels.
  EXPECT_GT(h * hull.box.dims.maxCoeff(), 2 * kRadius);
  EXPECT_LT(h * hull.box.dims.maxCoeff(), 2 * kRadius + 4 * (2.0 / kCoarseResolution));
  SurfaceCleanupReport report;
  const TriMesh mesh = HullMesh(hull, &report);
  EXPECT_EQ(report.components, 1);
  double max_error = 0, sum_error = 0;
  for (auto vh : mesh.vertices()) {
    const double r = mesh.point(vh).norm();
    max_error = std::max(max_error, std::abs(r - kRadius));
    sum_error += r - kRadius;
  }
  const double mean_error = sum_error / mesh.n_vertices();
  RecordProperty("max_error_voxels", std::to_string(max_error / h));
  RecordProperty("mean_error_voxels", std::to_string(mean_error / h));
  // Measured: max 0.24 voxels, mean −0.09 voxels (docs/init.md).
  EXPECT_LT(max_error, 0.5 * h);
  EXPECT_LT(std::abs(mean_error), 0.2 * h);
  // Volume of the ball within 3%.
  const double volume = 4.0 / 3.0 * M_PI * std::pow(kRadius, 3);
  EXPECT_NEAR(EnclosedVolume(mesh), volume, 0.03 * volume);
  // Points: the centre is deep inside, a point 3 voxels out is outside.
  EXPECT_LT(SampleHull(hull, Eigen::Vector3d::Zero()), -2 * h);
  EXPECT_GT(SampleHull(hull, Eigen::Vector3d(kRadius + 3 * h, 0, 0)), h);
  EXPECT_NEAR(SampleHull(hull, Eigen::Vector3d(0, kRadius, 0)), 0.0, 0.5 * h);
}

// One wrong mask (a disc through the sphere's middle cut away, as a shadow thresholded to
// background would be) tunnels through the exact visual hull; overruling one view restores the
// sphere, and on correct masks costs little.
TEST(VisualHullTest, OverrulingOneViewKeepsWhatOneWrongMaskCutAway) {
  const int n = 24, res = 96;
  std::vector<CarvingView> views = SphereViews(n, res);
  const double volume = 4.0 / 3.0 * M_PI * std::pow(kRadius, 3);
  VisualHullOptions options;
  options.resolution = 64;
  VisualHull exact;
  ASSERT_TRUE(CarveVisualHull(views, options, nullptr, &exact).ok());
  // View 0 looks at the origin through its image centre: cut a disc of 8 pixels there (the
  // sphere spans about 40 pixels across).
  CarvingView& wrong = views[0];
  for (int y = 0; y < res; ++y) {
    for (int x = 0; x < res; ++x) {
      if (std::hypot(x + 0.5 - 0.5 * res, y + 0.5 - 0.5 * res) < 8.0) {
        wrong.distance[static_cast<size_t>(y) * res + x] = 1.0f;  // background, 1 pixel out.
      }
    }
  }
  VisualHull tunnelled, overruled;
  ASSERT_TRUE(CarveVisualHull(views, options, nullptr, &tunnelled).ok());
  options.outlier_views = 1;
  ASSERT_TRUE(CarveVisualHull(views, options, nullptr, &overruled).ok());
  const double h = overruled.box.voxel_size;
  EXPECT_GT(SampleHull(tunnelled, Eigen::Vector3d::Zero()), 0.0);  // the centre is carved.
  EXPECT_LT(SampleHull(overruled, Eigen::Vector3d::Zero()), -2 * h);
  // The tunnel's volume (about π·r²·2R for a tunnel of radius r ≈ 0.06) is gone; the overruled
  // hull is the sphere within 2% (the exact hull of correct masks: within 3%, test above).
  const double exact_volume = HullVolume(exact), tunnelled_volume = HullVolume(tunnelled),
               overruled_volume = HullVolume(overruled);
  RecordProperty("volumes", std::to_string(exact_volume / volume) + " " +
                                std::to_string(tunnelled_volume / volume) + " " +
                                std::to_string(overruled_volume / volume));
  EXPECT_LT(tunnelled_volume, 0.92 * volume);            // measured 0.887 of the ball.
  EXPECT_NEAR(overruled_volume, volume, 0.02 * volume);  // measured 0.998.
  EXPECT_NEAR(exact_volume, volume, 0.03 * volume);
  // A point must be seen by the overruled view plus two that agree.
  options.outlier_views = 2;
  options.min_view_fraction = 0.01;
  VisualHull two;
  ASSERT_TRUE(CarveVisualHull(views, options, nullptr, &two).ok());
  EXPECT_EQ(two.min_views, 4);
}

// The support (known answers on the sphere of kRadius at the origin, exact masks from 60 views).
// A plane through the centre cuts the hull to the upper half ball. A plane 0.05 below the sphere
// (as if the masks had cut off the object's lowest 0.05) with a contact band of 0.1: the band
// z ∈ [-0.35, -0.25) takes the cross-section at z = -0.25 (radius √(0.09 − 0.0625) = 0.166) down
// to the plane, so the hull is the ball plus that cylinder less the cap it holds:
// 4/3·π·0.3³ + π·0.166²·0.1 − π·0.05²·(0.9 − 0.05)/3 = 0.11310 + 0.00864 − 0.00223 = 0.11951.
TEST(VisualHullTest, TheSupportCutsAndItsContactBandReachesIt) {
  const std::vector<CarvingView> views = SphereViews(60, 160);
  const double ball = 4.0 / 3.0 * M_PI * std::pow(kRadius, 3);
  VisualHullOptions options;
  options.resolution = 64;
  VisualHull whole;
  ASSERT_TRUE(CarveVisualHull(views, options, nullptr, &whole).ok());
  options.has_support = true;
  options.support_point = Eigen::Vector3d::Zero();
  VisualHull half;
  ASSERT_TRUE(CarveVisualHull(views, options, nullptr, &half).ok());
  const double h = half.box.voxel_size;
  // The box shrinks to the upper half; the volume halves (the whole hull's own error cancels).
  EXPECT_LT(h * half.box.dims.z(), 0.5 * h * whole.box.dims.z() + 4 * (2.0 / kCoarseResolution));
  const double half_ratio = HullVolume(half) / HullVolume(whole);
  RecordProperty("half_over_whole", std::to_string(half_ratio));
  EXPECT_NEAR(half_ratio, 0.5, 0.005);  // measured 0.4993.
  EXPECT_GT(SampleHull(half, Eigen::Vector3d(0, 0, -0.05)), 0.0);
  EXPECT_LT(SampleHull(half, Eigen::Vector3d(0, 0, 0.05)), 0.0);

  options.support_point = Eigen::Vector3d(0, 0, -0.35);
  options.support_contact = 0.1;
  VisualHull banded;
  ASSERT_TRUE(CarveVisualHull(views, options, nullptr, &banded).ok());
  const double expected = ball + M_PI * (0.09 - 0.0625) * 0.1 - M_PI * 0.0025 * 0.85 / 3;
  // The whole hull is the ball within 3% (SphereFromManyViewsIsTheSphere); scaled by its own
  // volume, the band's volume is known to its voxelisation (the band is about 10 voxels high).
  // Measured 1.0548 against 1.0567; without the band the ratio is about 1.
  const double ratio = HullVolume(banded) / HullVolume(whole);
  RecordProperty("banded_over_whole", std::to_string(ratio));
  EXPECT_NEAR(ratio, expected / ball, 0.005);
  const double hb = banded.box.voxel_size;
  EXPECT_LT(SampleHull(banded, Eigen::Vector3d(0, 0, -0.32)), -hb);     // under the ball.
  EXPECT_LT(SampleHull(banded, Eigen::Vector3d(0.12, 0, -0.33)), 0.0);  // inside the cylinder.
  EXPECT_GT(SampleHull(banded, Eigen::Vector3d(0.22, 0, -0.32)), 0.0);  // beside it.
  EXPECT_GT(SampleHull(banded, Eigen::Vector3d(0, 0, -0.37)), 0.0);     // below the plane.

  std::string why;
  options.support_contact = -0.1;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("support_contact"), std::string::npos) << why;
  options.support_contact = 0.1;
  options.support_normal = Eigen::Vector3d(0, 0, 2);
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("support"), std::string::npos) << why;
}

TEST(VisualHullTest, EmptyMaskIsAnErrorNamingTheView) {
  Camera camera;
  camera.width = camera.height = 8;
  camera.params = {8, 8, 4, 4};
  CarvingView view;
  const Status status =
      MakeCarvingView("views[3] (masks/003.png)", camera, Rigid3d(), Image(8, 8, 1, 0.f), &view);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("views[3] (masks/003.png): the mask is empty"), std::string::npos)
      << status.message();
}

TEST(VisualHullTest, MasksThatAgreeOnNothingGiveAnEmptyHullError) {
  // Every view's mask is one pixel in a corner: their cones do not meet inside the box.
  std::vector<CarvingView> views;
  for (int k = 0; k < 8; ++k) {
    Camera camera;
    camera.width = camera.height = 32;
    const double f = OrbitFocal(32, 40.0);
    camera.params = {f, f, 16, 16};
    Image mask(32, 32, 1);
    mask.at(k % 2 ? 0 : 31, 0) = 1.f;
    const Rigid3d pose = LookAt(2.0 * FibonacciSphereDirection(k, 8), Eigen::Vector3d::Zero(),
                                Eigen::Vector3d::UnitZ());
    views.emplace_back();
    ASSERT_TRUE(MakeCarvingView("v", camera, pose, mask, &views.back()).ok());
  }
  VisualHull hull;
  const Status status = CarveVisualHull(views, VisualHullOptions(), nullptr, &hull);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("visual hull is empty"), std::string::npos) << status.message();
}

TEST(VisualHullTest, OptionsAreChecked) {
  std::string why;
  VisualHullOptions options;
  EXPECT_TRUE(options.Check(&why));
  options.resolution = 15;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "resolution: must be in [16, 1024], got 15");
  options.resolution = 1025;
  EXPECT_FALSE(options.Check(&why));
  options.resolution = 128;
  options.outlier_views = 9;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "outlier_views: must be in [0, 8], got 9");
  InitialMeshOptions mesh_options;
  mesh_options.faces = 99;
  EXPECT_FALSE(mesh_options.Check(&why));
  EXPECT_EQ(why, "faces: must be in [100, 50000000], got 99");
}

// A tetrahedron's 4 triangles over vertices base..base+3, outward when `outward`.
void AddTetrahedron(int base, bool outward, std::vector<Eigen::Vector3i>* triangles) {
  const Eigen::Vector3i faces[4] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  for (Eigen::Vector3i t : faces) {
    if (!outward) std::swap(t[1], t[2]);
    triangles->push_back(t + Eigen::Vector3i::Constant(base));
  }
}

TEST(SurfaceCleanupTest, KeepsTheLargestComponentAndOrientsItOutwards) {
  // An inward-facing octahedron (8 triangles), a separate small tetrahedron (4) and a degenerate
  // triangle.
  std::vector<Eigen::Vector3d> points = {{1, 0, 0},   {0, 1, 0},  {-1, 0, 0}, {0, -1, 0},
                                         {0, 0, 1},   {0, 0, -1}, {5, 5, 5},  {5.1, 5, 5},
                                         {5, 5.1, 5}, {5, 5, 5.1}};
  std::vector<Eigen::Vector3i> triangles;
  for (int i = 0; i < 4; ++i) {
    const int a = i, b = (i + 1) % 4;
    triangles.push_back({a, 4, b});  // inward (clockwise seen from outside).
    triangles.push_back({b, 5, a});
  }
  AddTetrahedron(6, true, &triangles);
  triangles.push_back({0, 0, 1});
  TriMesh mesh;
  SurfaceCleanupReport report;
  const Status status = BuildClosedSurface(points, triangles, &mesh, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(report.input_triangles, 13);
  EXPECT_EQ(report.degenerate_triangles, 1);
  EXPECT_EQ(report.components, 2);
  EXPECT_EQ(report.dropped_triangles, 4);
  EXPECT_TRUE(report.flipped);
  EXPECT_EQ(mesh.n_faces(), 8u);
  EXPECT_EQ(mesh.n_vertices(), 6u);
  EXPECT_NEAR(EnclosedVolume(mesh), 4.0 / 3.0, 1e-12);
  std::string why;
  EXPECT_TRUE(IsClosedManifold(mesh, &why)) << why;
}

TEST(SurfaceCleanupTest, SplitsPinchedVertices) {
  // A 6 × 4 torus grid (closed, manifold) whose vertices (0, 0) and (3, 2) are merged into one:
  // they have no common neighbour, so the merged vertex carries two fans of triangles that share
  // no edge, inside one edge-connected component.
  const int nu = 6, nv = 4;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
      points.emplace_back((1 + 0.4 * std::cos(v)) * std::cos(u),
                          (1 + 0.4 * std::cos(v)) * std::sin(u), 0.4 * std::sin(v));
    }
  }
  auto index = [&](int i, int j) {
    const int n = ((i + nu) % nu) * nv + (j + nv) % nv;
    return n == 3 * nv + 2 ? 0 : n;  // (3, 2) merged into (0, 0).
  };
  std::vector<Eigen::Vector3i> triangles;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  }
  TriMesh mesh;
  SurfaceCleanupReport report;
  const Status status = BuildClosedSurface(points, triangles, &mesh, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(report.components, 1);
  EXPECT_EQ(report.split_vertices, 1);
  EXPECT_EQ(mesh.n_vertices(), static_cast<size_t>(nu * nv));
  EXPECT_EQ(mesh.n_faces(), static_cast<size_t>(2 * nu * nv));
  std::string why;
  EXPECT_TRUE(IsClosedManifold(mesh, &why)) << why;
}

TEST(SurfaceCleanupTest, OpenSurfaceIsAnError) {
  std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<Eigen::Vector3i> triangles;
  AddTetrahedron(0, true, &triangles);
  triangles.pop_back();
  TriMesh mesh;
  SurfaceCleanupReport report;
  const Status status = BuildClosedSurface(points, triangles, &mesh, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("not closed: 3 open"), std::string::npos) << status.message();
}

TEST(SurfaceCleanupTest, DecimationKeepsAClosedManifoldAtTheTarget) {
  const std::vector<CarvingView> views = SphereViews(24, 96);
  VisualHullOptions options;
  options.resolution = 48;
  VisualHull hull;
  ASSERT_TRUE(CarveVisualHull(views, options, nullptr, &hull).ok());
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> triangles;
  ASSERT_TRUE(ExtractHullSurface(hull, &points, &triangles).ok());
  TriMesh mesh;
  SurfaceCleanupReport report;
  ASSERT_TRUE(BuildClosedSurface(points, triangles, &mesh, &report).ok());
  ASSERT_GT(mesh.n_faces(), 2000u);
  const double volume = EnclosedVolume(mesh);
  DecimateMesh(500, &mesh);
  EXPECT_LE(mesh.n_faces(), 500u);
  EXPECT_GE(mesh.n_faces(), 450u);
  std::string why;
  EXPECT_TRUE(IsClosedManifold(mesh, &why)) << why;
  EXPECT_NEAR(EnclosedVolume(mesh), volume, 0.03 * volume);
}

// The bunny rendered by `sft synth` (24 views, 96², masks from pixel coverage), carved at 96
// voxels, against the true mesh with the metrics of `sft eval --reference`.
TEST(InitialMeshTest, BunnyHullAgainstTheTrueMesh) {
  testing::TempDir tmp;
  const std::string dataset_dir = tmp.Join("bunny");
  std::string output;
  ASSERT_EQ(testing::RunCommand(testing::SftBinary() + " synth --quiet --mesh " +
                                    testing::DataDir() + "/meshes/bunny_watertight_5k.obj --out " +
                                    dataset_dir + " --cameras 24 --zooms 1 --res 96 --spp 4",
                                &output),
            0)
      << output;
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dataset_dir, &dataset).ok());
  std::vector<CarvingView> views;
  Status status = LoadCarvingViews(dataset, &views);
  ASSERT_TRUE(status.ok()) << status.message();
  InitialMeshOptions options;
  options.hull.resolution = 96;
  options.faces = 5000;
  options.progress = false;
  TriMesh mesh;
  InitialMeshReport report;
  status = MakeInitialMesh(views, options, {}, &mesh, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_LE(report.faces, 5000);
  std::string why;
  EXPECT_TRUE(IsClosedManifold(mesh, &why)) << why;
  // Every edge has exactly two faces, counted directly.
  for (auto eh : mesh.edges()) ASSERT_FALSE(mesh.is_boundary(eh));
  TriMesh truth;
  ASSERT_TRUE(ReadMesh(dataset_dir + "/gt/mesh.ply", &truth).ok());
  MeshMetricsOptions metrics_options;
  metrics_options.samples = 200000;
  MeshMetrics metrics;
  ASSERT_TRUE(ComputeMeshMetrics(truth, mesh, metrics_options, &metrics).ok());
  RecordProperty("f1", std::to_string(metrics.f1));
  RecordProperty("chamfer", std::to_string(metrics.chamfer));
  // Measured: F1 0.906 (precision 0.914, recall 0.898), Chamfer 0.0054 (docs/init.md). The hull
  // over-estimates the bunny where silhouettes cannot see (concavities) and between the views;
  // the bounds leave room for sampling and platform noise, and fail for a hull off by a voxel.
  EXPECT_GT(metrics.f1, 0.88);
  EXPECT_LT(metrics.chamfer, 0.0065);
}

}  // namespace
}  // namespace sft
