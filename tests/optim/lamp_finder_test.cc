// Finding a lamp with no guess (src/optim/lamp_finder.h): the lobe of a map and the lamp it
// gives, against values worked out by hand from the env convention; maps with no lobe; the
// object's centre in a camera frame; the config keys; and the map staying the last light when a
// found lamp joins a prepared dataset. The fit that finds a lamp in a rendered scene is in
// tests/optim/estimated_lights_test.cc (EstimatedLampFitTest.LampFoundWithNoGuess).
#include "src/optim/lamp_finder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "src/optim/fitted_environment.h"
#include "src/optim/schedule_config.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

// The env frame's direction at texel (x, y)'s centre of a W × H map, written out from the
// convention u = 0.5 − atan2(y, x)/(2π), v = acos(z)/π.
Eigen::Vector3d Direction(double x, double y, int width, int height) {
  const double theta = M_PI * (y + 0.5) / height;
  const double phi = 2.0 * M_PI * (0.5 - (x + 0.5) / width);
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// Row y's texel solid angle: 2π/W · (cos θ_top − cos θ_bottom).
double SolidAngle(int y, int width, int height) {
  return 2.0 * M_PI / width * (std::cos(M_PI * y / height) - std::cos(M_PI * (y + 1) / height));
}

Image Room(int width, int height, float level) {
  Image map(width, height, 3);
  for (float& value : map.data) value = level;
  return map;
}

void SetTexel(Image* map, int x, int y, const Eigen::Vector3d& rgb) {
  for (int c = 0; c < 3; ++c) map->at(x, y, c) = static_cast<float>(rgb[c]);
}

// One bright texel on a grey room: the lamp lies along that texel's direction (turned by the
// map's frame), at the given distance, with the texel's excess radiance × solid angle × d² as its
// intensity, per channel.
TEST(LampFromEnvironmentTest, OneTexelLobe) {
  Image map = Room(16, 8, 0.2f);
  SetTexel(&map, 3, 2, Eigen::Vector3d(5.2, 4.2, 3.2));  // excess (5, 4, 3), luminance 4.2.
  const Eigen::Vector3d centre(0.1, -0.2, 0.3);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).matrix();
  LampSearch search;
  ASSERT_TRUE(LampFromEnvironment(map, turn, LightFrame::kWorld, centre, 2.0, &search).ok());
  ASSERT_TRUE(search.found);
  EXPECT_NEAR(search.contrast, 4.2 / 0.2, 1e-5);
  EXPECT_EQ(search.lobe_texels, 1);
  const Eigen::Vector3d omega = turn * Direction(3, 2, 16, 8);
  EXPECT_LT((search.direction - omega).norm(), 1e-12);
  EXPECT_EQ(search.lamp.id, kFoundLampId);
  EXPECT_EQ(search.lamp.type, LightType::kPoint);
  EXPECT_EQ(search.lamp.frame, LightFrame::kWorld);
  EXPECT_LT((search.lamp.position - (centre + 2.0 * omega)).norm(), 1e-12);
  const Eigen::Vector3d expected = Eigen::Vector3d(5, 4, 3) * SolidAngle(2, 16, 8) * 4.0;
  EXPECT_LT((search.lamp.intensity - expected).norm(), 1e-5 * expected.norm());
  EXPECT_THAT(search.Describe(), HasSubstr("found_lamp starts at"));
}

// The lobe is the bright texels connected to the brightest one, across the u seam; a bright texel
// elsewhere does not pull its direction, and texels below half the peak's excess stay out.
TEST(LampFromEnvironmentTest, ConnectedLobeAcrossTheSeam) {
  Image map = Room(16, 8, 0.2f);
  SetTexel(&map, 0, 3, Eigen::Vector3d::Constant(5.2));   // the peak, excess 5.
  SetTexel(&map, 15, 3, Eigen::Vector3d::Constant(3.2));  // its neighbour across u = 0.
  SetTexel(&map, 1, 4, Eigen::Vector3d::Constant(2.0));   // excess 1.8 < 2.5: out.
  SetTexel(&map, 8, 6, Eigen::Vector3d::Constant(4.0));   // bright, not connected: out.
  LampSearch search;
  ASSERT_TRUE(LampFromEnvironment(map, Eigen::Matrix3d::Identity(), LightFrame::kCamera,
                                  Eigen::Vector3d::Zero(), 1.0, &search)
                  .ok());
  ASSERT_TRUE(search.found);
  EXPECT_EQ(search.lobe_texels, 2);
  const double omega3 = SolidAngle(3, 16, 8);
  const Eigen::Vector3d omega =
      (5.0 * omega3 * Direction(0, 3, 16, 8) + 3.0 * omega3 * Direction(15, 3, 16, 8)).normalized();
  EXPECT_LT((search.direction - omega).norm(), 1e-6);  // float texels.
  EXPECT_EQ(search.lamp.frame, LightFrame::kCamera);
  // Irradiance on a surface facing ω: each texel's excess × its solid angle × its cosine to ω.
  const double e = 5.0 * omega3 * omega.dot(Direction(0, 3, 16, 8)) +
                   3.0 * omega3 * omega.dot(Direction(15, 3, 16, 8));
  EXPECT_NEAR(search.lamp.intensity.x(), e, 1e-5 * e);
}

// No lamp where nothing stands out: an even room, a sky brighter than the ground by 2.5×, a black
// map; a map without RGB is an error.
TEST(LampFromEnvironmentTest, NoLobeNoLamp) {
  LampSearch search;
  ASSERT_TRUE(LampFromEnvironment(Room(8, 4, 0.3f), Eigen::Matrix3d::Identity(), LightFrame::kWorld,
                                  Eigen::Vector3d::Zero(), 1.0, &search)
                  .ok());
  EXPECT_FALSE(search.found);
  EXPECT_NEAR(search.contrast, 1.0, 1e-6);
  EXPECT_THAT(search.Describe(), HasSubstr("no bright lobe"));
  Image sky = Room(8, 4, 0.2f);
  for (int x = 0; x < 8; ++x) SetTexel(&sky, x, 0, Eigen::Vector3d::Constant(0.5));
  ASSERT_TRUE(LampFromEnvironment(sky, Eigen::Matrix3d::Identity(), LightFrame::kWorld,
                                  Eigen::Vector3d::Zero(), 1.0, &search)
                  .ok());
  EXPECT_FALSE(search.found);
  EXPECT_NEAR(search.contrast, 2.5, 1e-6);
  ASSERT_TRUE(LampFromEnvironment(Room(8, 4, 0.0f), Eigen::Matrix3d::Identity(), LightFrame::kWorld,
                                  Eigen::Vector3d::Zero(), 1.0, &search)
                  .ok());
  EXPECT_FALSE(search.found);
  EXPECT_FALSE(LampFromEnvironment(Image(8, 4, 1), Eigen::Matrix3d::Identity(), LightFrame::kWorld,
                                   Eigen::Vector3d::Zero(), 1.0, &search)
                   .ok());
}

// The object's centre: its bounding box's centre in the world; in a camera frame, that point's
// mean position in the chosen views' cameras.
TEST(LampFinderTest, ObjectCentreInFrame) {
  TriMesh mesh;
  mesh.add_vertex(TriMesh::Point(0, 0, 0));
  mesh.add_vertex(TriMesh::Point(2, 0, 0));
  mesh.add_vertex(TriMesh::Point(0, 4, 6));
  mesh.add_face(TriMesh::VertexHandle(0), TriMesh::VertexHandle(1), TriMesh::VertexHandle(2));
  Dataset dataset;
  dataset.views.resize(3);
  dataset.views[0].cam_from_world.translation = Eigen::Vector3d(0, 0, 5);
  dataset.views[1].cam_from_world.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));
  dataset.views[2].cam_from_world.translation = Eigen::Vector3d(100, 0, 0);
  const Eigen::Vector3d world(1, 2, 3);
  EXPECT_LT((ObjectCentreInFrame(mesh, dataset, {}, LightFrame::kWorld) - world).norm(), 1e-12);
  // View 0 sees it at (1, 2, 8), view 1 at (−1, 2, −3): the mean is (0, 2, 2.5).
  EXPECT_LT(
      (ObjectCentreInFrame(mesh, dataset, {0, 1}, LightFrame::kCamera) - Eigen::Vector3d(0, 2, 2.5))
          .norm(),
      1e-12);
}

// find_lamp and lamp_distance: checked values, exclusive with estimate_lights in either order,
// and the environment stage fits the lamp's intensity and place.
TEST(LampFinderTest, ConfigKeys) {
  ScheduleConfig config;
  ASSERT_TRUE(
      MergeScheduleConfig({{"find_lamp", true}, {"lamp_distance", 3}}, "c.json", &config).ok());
  EXPECT_TRUE(config.environment.find_lamp);
  EXPECT_EQ(config.environment.lamp_distance, 3.0);
  EXPECT_TRUE(config.environment_given);
  StageOptions stage;
  ASSERT_TRUE(EnvironmentStage(config, StageOptions(), &stage).ok());
  EXPECT_TRUE(stage.fit.fit_lights);
  EXPECT_TRUE(stage.fit.fit_light_positions);
  EXPECT_TRUE(stage.fit.fit_environment);

  const std::vector<std::pair<nlohmann::json, std::string>> bad = {
      {{{"find_lamp", 1}}, "c.json: find_lamp: expected true or false"},
      {{{"lamp_distance", 0.1}}, "c.json: lamp_distance: must be in [0.5, 1000]"},
      {{{"lamp_distance", "far"}}, "c.json: lamp_distance: expected a number"}};
  for (const auto& [keys, expected] : bad) {
    ScheduleConfig c;
    const Status status = MergeScheduleConfig(keys, "c.json", &c);
    ASSERT_FALSE(status.ok()) << keys;
    EXPECT_THAT(status.message(), HasSubstr(expected)) << keys;
  }
  // find_lamp first, then lights (the file is not read); lights first, then find_lamp.
  ScheduleConfig finding;
  ASSERT_TRUE(MergeScheduleConfig({{"find_lamp", true}}, "c.json", &finding).ok());
  EXPECT_THAT(MergeScheduleConfig({{"estimate_lights", "lamp.json"}}, "d.json", &finding).message(),
              HasSubstr("d.json: estimate_lights: find_lamp is on"));
  ScheduleConfig given;
  LightSpec lamp;
  lamp.id = "lamp";
  lamp.type = LightType::kPoint;
  lamp.intensity = Eigen::Vector3d::Ones();
  given.environment.lights = {lamp};
  const Status status = MergeScheduleConfig({{"find_lamp", true}}, "c.json", &given);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("c.json: find_lamp: looks for a lamp when none"));
}

// A found lamp joins a dataset whose map is already there: the map stays the last light in the
// dataset and in every view, with its texels and frame.
TEST(LampFinderTest, FoundLampJoinsBeforeTheMap) {
  Dataset dataset;
  dataset.views.resize(2);
  Image texels = Room(4, 2, 0.7f);
  ASSERT_TRUE(AddFittedEnvironment(texels, LightFrame::kCamera, &dataset).ok());
  LightSpec lamp;
  lamp.id = kFoundLampId;
  lamp.type = LightType::kPoint;
  lamp.intensity = Eigen::Vector3d::Ones();
  ASSERT_TRUE(AddEstimatedLights({lamp}, &dataset).ok());
  ASSERT_EQ(dataset.lights.size(), 2u);
  EXPECT_EQ(dataset.lights[0].id, kFoundLampId);
  EXPECT_EQ(FittedEnvironmentLight(dataset), 1);
  EXPECT_EQ(dataset.lights[1].frame, LightFrame::kCamera);
  EXPECT_EQ(dataset.lights[1].pixels.data, texels.data);
  for (const ViewSpec& view : dataset.views) {
    EXPECT_EQ(view.lights, std::vector<int>({0, 1}));
    EXPECT_EQ(view.light_ids, std::vector<std::string>({kFoundLampId, kFittedEnvironmentId}));
  }
  EXPECT_EQ(EstimatedLights(dataset).size(), 1u);
}

}  // namespace
}  // namespace sft
