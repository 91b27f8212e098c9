// The support plane (src/capture/support_plane.h) on synthetic points: an object (a small ball of
// points) on a textured floor (a disc of points) seen by an orbit of cameras above it; and the
// normalisation without masks, which leaves the floor out of the object's box.
#include "src/capture/support_plane.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "src/capture/import_normalization.h"
#include "src/render/camera_rig.h"

namespace sft {
namespace {

// A floor through `floor_point` with normal `up`, a ball of radius 0.3 resting on it, cameras on
// an orbit 2.5 away at 30° elevation. Points in a rotated, shifted frame, as COLMAP's is arbitrary.
struct Scene {
  std::vector<Eigen::Vector3d> floor, ball, cameras;
};

Scene MakeScene(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& shift) {
  Scene scene;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.002);
  while (scene.floor.size() < 1500) {
    // One draw per statement (a constructor's arguments have no defined evaluation order).
    const double x = 2.5 * u(rng);
    const double y = 2.5 * u(rng);
    const Eigen::Vector3d p(x, y, noise(rng));
    if (p.head<2>().norm() > 0.35) scene.floor.push_back(rotation * p + shift);
  }
  while (scene.ball.size() < 400) {
    const Eigen::Vector3d d = Eigen::Vector3d::NullaryExpr([&](Eigen::Index) { return u(rng); });
    if (d.norm() < 0.2 || d.norm() > 1) continue;
    scene.ball.push_back(rotation * (Eigen::Vector3d(0, 0, 0.3) + 0.3 * d.normalized()) + shift);
  }
  for (int k = 0; k < 24; ++k) {
    const double a = 2 * M_PI * k / 24, e = M_PI / 6;
    const Eigen::Vector3d c(2.5 * std::cos(e) * std::cos(a), 2.5 * std::cos(e) * std::sin(a),
                            0.3 + 2.5 * std::sin(e));
    scene.cameras.push_back(rotation * c + shift);
  }
  return scene;
}

const Eigen::Matrix3d kRotation =
    Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
const Eigen::Vector3d kShift(4, -1, 2);

TEST(SupportPlaneTest, FindsTheFloorUnderTheObject) {
  const Scene scene = MakeScene(kRotation, kShift);
  std::vector<Eigen::Vector3d> points = scene.floor;
  points.insert(points.end(), scene.ball.begin(), scene.ball.end());
  const SupportPlane plane = FindSupportPlane(points, scene.cameras, SupportPlaneOptions());
  ASSERT_TRUE(plane.found);
  // The normal points up (towards the cameras), the floor is at distance 0.
  EXPECT_GT(plane.normal.dot(kRotation * Eigen::Vector3d::UnitZ()), 0.999);
  EXPECT_NEAR(plane.SignedDistance(kShift), 0.0, 0.01);
  int floor_off = 0, ball_off = 0;
  for (const Eigen::Vector3d& p : scene.floor) floor_off += plane.OffObject(p);
  for (const Eigen::Vector3d& p : scene.ball) ball_off += plane.OffObject(p);
  EXPECT_EQ(floor_off, static_cast<int>(scene.floor.size()));
  // The band (2% of the ~2.6 viewing distance, 0.05) takes only the ball's lowest cap: a cap of
  // height h holds h / (2 r) ≈ 9% of a sphere's points (measured 36 of 400).
  EXPECT_LT(ball_off, static_cast<int>(scene.ball.size()) / 8);
  EXPECT_EQ(plane.off_object, floor_off + ball_off);
}

// The support as a disc (--probe-ground): a round table of radius 1.8 under the ball. Its points
// are uniform over the disc, so the 0.99 quantile of their distances from the centre is
// 1.8·√0.99 = 1.791 (the ball's ~36 points in the band barely move it; the quantile's sampling
// error over 1500 points is about 0.003). The centre is the ball's centre dropped onto the plane.
TEST(SupportPlaneTest, DiscOfARoundTableIsItsRadiusUnderTheObject) {
  const Scene scene = MakeScene(kRotation, kShift);
  std::vector<Eigen::Vector3d> points = scene.ball;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int table = 0;
  while (table < 1500) {
    const double x = 1.8 * u(rng);
    const double y = 1.8 * u(rng);
    if (std::hypot(x, y) > 1.8 || std::hypot(x, y) < 0.35) continue;
    points.push_back(kRotation * Eigen::Vector3d(x, y, 0) + kShift);
    ++table;
  }
  const SupportPlane plane = FindSupportPlane(points, scene.cameras, SupportPlaneOptions());
  ASSERT_TRUE(plane.found);
  const Eigen::Vector3d ball_centre = kRotation * Eigen::Vector3d(0, 0, 0.3) + kShift;
  Eigen::Vector3d centre;
  double radius = 0;
  ASSERT_TRUE(FindSupportDisc(plane, points, ball_centre, 0.99, &centre, &radius));
  EXPECT_LT((centre - kShift).norm(), 0.01);
  EXPECT_NEAR(radius, 1.8 * std::sqrt(0.99), 0.02);
  // No plane, no disc.
  EXPECT_FALSE(FindSupportDisc(SupportPlane(), points, ball_centre, 0.99, &centre, &radius));
}

TEST(SupportPlaneTest, NoPlaneWithoutOneOrWithCamerasOnBothSides) {
  const Scene scene = MakeScene(kRotation, kShift);
  // The ball alone: no plane holds 20% of its points.
  EXPECT_FALSE(FindSupportPlane(scene.ball, scene.cameras, SupportPlaneOptions()).found);
  // Cameras above and below the floor (a turntable seen from all around): not a support.
  std::vector<Eigen::Vector3d> cameras = scene.cameras;
  for (const Eigen::Vector3d& c : scene.cameras) {
    const Eigen::Vector3d local = kRotation.transpose() * (c - kShift);
    cameras.push_back(kRotation * Eigen::Vector3d(local.x(), local.y(), -local.z()) + kShift);
  }
  std::vector<Eigen::Vector3d> points = scene.floor;
  points.insert(points.end(), scene.ball.begin(), scene.ball.end());
  EXPECT_FALSE(FindSupportPlane(points, cameras, SupportPlaneOptions()).found);
  SupportPlaneOptions off;
  off.enabled = false;
  EXPECT_FALSE(FindSupportPlane(points, scene.cameras, off).found);
  std::string why;
  off.distance = 0;
  EXPECT_FALSE(off.Check(&why));
  EXPECT_NE(why.find("--plane-distance"), std::string::npos) << why;
}

// ComputeNormalization without masks on a COLMAP-like model of the scene: with the plane the box
// is the ball's; without it the floor's points near the optical axes count as the object.
TEST(SupportPlaneTest, NormalizationLeavesTheFloorOut) {
  const Scene scene = MakeScene(kRotation, kShift);
  ColmapModel model;
  std::unordered_map<uint32_t, ObservingView> views;
  for (size_t k = 0; k < scene.cameras.size(); ++k) {
    ObservingView& view = views[static_cast<uint32_t>(k + 1)];
    view.camera.model = CameraModel::kPinhole;
    view.camera.width = view.camera.height = 480;
    view.camera.params = {580, 580, 240, 240};
    view.cam_from_world = LookAt(scene.cameras[k], kShift + kRotation * Eigen::Vector3d(0, 0, 0.3),
                                 kRotation * Eigen::Vector3d::UnitZ());
  }
  for (const auto* set : {&scene.floor, &scene.ball}) {
    for (const Eigen::Vector3d& p : *set) {
      ColmapPoint3D point;
      point.xyz = p;
      for (uint32_t id = 1; id <= scene.cameras.size(); ++id) point.track.push_back({id, 0});
      model.points.push_back(point);
    }
  }
  NormalizationResult with, without;
  ASSERT_TRUE(ComputeNormalization(model, views, NormalizationOptions(), &with).ok());
  NormalizationOptions no_plane;
  no_plane.plane.enabled = false;
  ASSERT_TRUE(ComputeNormalization(model, views, no_plane, &without).ok());
  ASSERT_TRUE(with.plane.found);
  EXPECT_FALSE(without.plane.found);
  // The ball's box diagonal is 0.6·√3 ≈ 1.04; its centre is 0.3 above the floor's centre.
  EXPECT_NEAR(with.diagonal, 0.6 * std::sqrt(3.0), 0.1);
  EXPECT_LT((with.centre - (kShift + kRotation * Eigen::Vector3d(0, 0, 0.3))).norm(), 0.05);
  // The floor points near the optical axes count as the object only without the plane.
  int floor_with = 0, floor_without = 0;
  for (size_t i = 0; i < scene.floor.size(); ++i) {
    floor_with += with.used[i];
    floor_without += without.used[i];
  }
  EXPECT_EQ(floor_with, 0);
  EXPECT_GT(floor_without, 10);  // measured 25.
}

}  // namespace
}  // namespace sft
