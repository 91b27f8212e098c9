// Stereo points (src/init/stereo_points.h) on an analytic scene with a known surface: a textured
// unit sphere with a shallow spherical dent that a ring of silhouettes cannot see. The points lie
// on the surface with its normals, the Poisson surface of them gives the dent back where the
// visual hull fills it, and bad inputs are clear errors.
#include "src/init/stereo_points.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "src/init/initial_mesh.h"
#include "src/init/resample.h"
#include "src/render/scene.h"
#include "tests/testing/views.h"

namespace sft {
namespace {

// The dent: the unit sphere minus the ball of radius kDentRadius around (kDentCentre, 0, 0). Its
// bottom is at x = kDentCentre − kDentRadius = 0.8; its rim at x ≈ 0.9, |y| ≈ 0.43 (z = 0).
constexpr double kDentCentre = 1.8;
constexpr double kDentRadius = 1.0;
constexpr double kDentBottom = kDentCentre - kDentRadius;
constexpr int kRes = 160;
constexpr double kFocal = 220.0;     // pixels: the sphere fills about 60% of the image at 4.
constexpr double kDistance = 4.0;    // the cameras' distance from the centre.
constexpr int kRingViews = 36;       // 10° apart.
constexpr double kElevation = 0.15;  // radians above the equator.

// The first hit of the ray o + t·d (|d| = 1) on the dented sphere; false when it misses.
bool HitDentedSphere(const Eigen::Vector3d& o, const Eigen::Vector3d& d, Eigen::Vector3d* hit,
                     Eigen::Vector3d* normal) {
  const auto interval = [&](const Eigen::Vector3d& c, double r, double* t0, double* t1) {
    const Eigen::Vector3d oc = o - c;
    const double b = oc.dot(d), disc = b * b - (oc.squaredNorm() - r * r);
    if (disc <= 0) return false;
    *t0 = -b - std::sqrt(disc);
    *t1 = -b + std::sqrt(disc);
    return true;
  };
  const Eigen::Vector3d dent(kDentCentre, 0, 0);
  double a0, a1, b0 = 0, b1 = -1;
  if (!interval(Eigen::Vector3d::Zero(), 1.0, &a0, &a1)) return false;
  const bool through_dent = interval(dent, kDentRadius, &b0, &b1);
  if (!through_dent || a0 < b0 || a0 > b1) {  // enters the sphere outside the dent's ball.
    *hit = o + a0 * d;
    *normal = hit->normalized();
    return true;
  }
  if (b1 >= a1) return false;  // the ball holds the whole chord.
  *hit = o + b1 * d;           // leaves the ball inside the sphere: the dent's wall.
  *normal = (dent - *hit).normalized();
  return true;
}

// Signed distance (approximately, exact away from the rim) to the dented sphere.
double DentedDistance(const Eigen::Vector3d& p) {
  return std::max(p.norm() - 1.0, kDentRadius - (p - Eigen::Vector3d(kDentCentre, 0, 0)).norm());
}

// A texture on the surface (world position), with detail at several scales for the matching.
double Texture(const Eigen::Vector3d& p) {
  return 0.45 +
         0.2 * std::sin(9 * p.x() + 1) * std::sin(11 * p.y() + 2) * std::sin(13 * p.z() + 3) +
         0.15 * std::sin(23 * p.x() + 29 * p.y() + 31 * p.z()) +
         0.1 * std::sin(41 * p.y() - 37 * p.z() + 0.5);
}

std::vector<StereoView> RingViews() {
  std::vector<StereoView> views;
  for (int k = 0; k < kRingViews; ++k) {
    const double phi = 2 * M_PI * k / kRingViews;
    const Eigen::Vector3d eye =
        kDistance * Eigen::Vector3d(std::cos(kElevation) * std::cos(phi),
                                    std::cos(kElevation) * std::sin(phi), std::sin(kElevation));
    const ViewSetup setup = testing::LookAtView(eye, Eigen::Vector3d::Zero(), kRes, kFocal);
    StereoView view;
    view.name = "view " + std::to_string(k);
    view.camera = setup.camera;
    view.cam_from_world = setup.cam_from_world;
    view.image = Image(kRes, kRes, 3);
    view.mask = Image(kRes, kRes, 1);
    const Rigid3d world_from_cam = setup.cam_from_world.Inverse();
    for (int y = 0; y < kRes; ++y) {
      for (int x = 0; x < kRes; ++x) {
        const Eigen::Vector3d ray =
            world_from_cam.rotation * setup.camera.CamFromImage(Eigen::Vector2d(x + 0.5, y + 0.5));
        Eigen::Vector3d hit, normal;
        if (!HitDentedSphere(eye, ray.normalized(), &hit, &normal)) continue;
        view.mask.at(x, y) = 1.0f;
        for (int c = 0; c < 3; ++c) view.image.at(x, y, c) = static_cast<float>(Texture(hit));
      }
    }
    views.push_back(std::move(view));
  }
  return views;
}

Eigen::AlignedBox3d UnitBox() {
  return Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1.1), Eigen::Vector3d::Constant(1.1));
}

double Quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * (values.size() - 1))];
}

TEST(StereoPointsTest, PointsLieOnTheSurfaceWithItsNormals) {
  const std::vector<StereoView> views = RingViews();
  std::vector<OrientedPoint> points;
  StereoReport report;
  const Status status = ComputeStereoPoints(views, UnitBox(), StereoOptions(), &points, &report);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(report.views, kRingViews);
  EXPECT_EQ(report.pairs, 2 * kRingViews);  // the two neighbours, 10° away, of every view.
  EXPECT_EQ(report.views_without_pair, 0);
  // Each view's mask covers about π(0.6·80)² ≈ 7200 pixels; most keep a depth.
  EXPECT_GT(report.points, kRingViews * 4000);
  std::vector<double> distance, angle;
  for (const OrientedPoint& p : points) {
    distance.push_back(std::abs(DentedDistance(p.position)));
    const bool on_dent = (p.position - Eigen::Vector3d(kDentCentre, 0, 0)).norm() <
                         kDentRadius + 1e-3 + std::abs(p.position.norm() - 1.0);
    const Eigen::Vector3d truth =
        on_dent ? (Eigen::Vector3d(kDentCentre, 0, 0) - p.position).normalized()
                : p.position.normalized();
    angle.push_back(std::acos(std::clamp(truth.dot(p.normal), -1.0, 1.0)) * 180 / M_PI);
  }
  // Depth resolution: a 1/16-pixel disparity step at 4 units with a 0.69 baseline and f = 220 is
  // 4² / (220 · 0.69) / 16 = 0.0066 units; a pixel is 0.018 wide at the surface. Measured: median
  // 0.0072, 90% 0.016, and a signed median of -0.0044 (0.04 pixel of disparity: semi-global
  // matching's sub-pixel fit, not a convention error, which would be half a pixel, 0.05 units).
  std::vector<double> signed_distance;
  for (const OrientedPoint& p : points) signed_distance.push_back(DentedDistance(p.position));
  EXPECT_LT(Quantile(distance, 0.5), 0.01);
  EXPECT_LT(Quantile(distance, 0.9), 0.025);
  EXPECT_NEAR(Quantile(signed_distance, 0.5), 0.0, 0.008);
  // Normals from central differences of those depths: noisy (measured median 6.8°, 90% 14°), but
  // centred on the truth.
  EXPECT_LT(Quantile(angle, 0.5), 10.0);
  EXPECT_LT(Quantile(angle, 0.9), 20.0);
}

TEST(StereoPointsTest, ThePoissonSurfaceGivesBackTheDentTheHullFills) {
  const std::vector<StereoView> views = RingViews();
  std::vector<CarvingView> carving(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    ASSERT_TRUE(MakeCarvingView(views[v].name, views[v].camera, views[v].cam_from_world,
                                views[v].mask, &carving[v])
                    .ok());
  }
  InitialMeshOptions hull_options;
  hull_options.progress = false;
  hull_options.faces = 8000;
  TriMesh hull;
  InitialMeshReport hull_report;
  ASSERT_TRUE(MakeInitialMesh(carving, hull_options, {}, &hull, &hull_report).ok());

  std::vector<OrientedPoint> points;
  StereoReport report;
  ASSERT_TRUE(ComputeStereoPoints(views, UnitBox(), StereoOptions(), &points, &report).ok());
  ResampleOptions surface_options;
  surface_options.faces = 8000;
  TriMesh stereo;
  ResampleReport surface_report;
  const Status status =
      SurfaceFromSamples(points, 0.03, &carving, surface_options, &stereo, &surface_report);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(surface_report.hull_views, kRingViews);

  // Along the dent's axis from outside: the hull closes the dent near its rim (x ≈ 0.9), the
  // stereo surface finds its bottom (0.8). At the sphere's other side both find x = −1.
  const auto first_x = [](const TriMesh& mesh, const Eigen::Vector3d& from,
                          const Eigen::Vector3d& direction) {
    const RenderScene scene(mesh);
    const auto hit = scene.Intersect(from, direction, 0.0, 1e30);
    EXPECT_TRUE(hit.hit);
    return (from + hit.t * direction).x();
  };
  const Eigen::Vector3d right(3, 0, 0), left(-3, 0, 0);
  EXPECT_GT(first_x(hull, right, -Eigen::Vector3d::UnitX()), kDentBottom + 0.08);
  EXPECT_NEAR(first_x(stereo, right, -Eigen::Vector3d::UnitX()), kDentBottom, 0.03);
  EXPECT_NEAR(first_x(stereo, left, Eigen::Vector3d::UnitX()), -1.0, 0.03);
}

TEST(StereoPointsTest, BadInputsAreErrors) {
  std::vector<StereoView> views = RingViews();
  std::vector<OrientedPoint> points;
  StereoReport report;
  StereoOptions options;
  options.block_size = 4;
  Status status = ComputeStereoPoints(views, UnitBox(), options, &points, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("block_size"), std::string::npos) << status.message();

  std::vector<StereoView> two(views.begin(), views.begin() + 2);
  status = ComputeStereoPoints(two, UnitBox(), StereoOptions(), &points, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("at least 3 views"), std::string::npos) << status.message();

  status = ComputeStereoPoints(views, Eigen::AlignedBox3d(), StereoOptions(), &points, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("box"), std::string::npos) << status.message();

  views[5].image = Image(kRes / 2, kRes, 3);
  status = ComputeStereoPoints(views, UnitBox(), StereoOptions(), &points, &report);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("view 5"), std::string::npos) << status.message();
  EXPECT_TRUE(points.empty());
}

}  // namespace
}  // namespace sft
