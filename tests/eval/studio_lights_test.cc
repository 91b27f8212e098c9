// The studio lights of report.html's relit rows (src/eval/studio_lights.h) against closed forms on
// a convex object, a unit sphere (a 1280-face icosphere, smooth shading) of albedo 0.5 seen from
// 3 units away: under "ambient" every pixel on the sphere shows its albedo (a/π · 1 · π), and
// under "key" a pixel with normal n shows a·(0.2 + 0.8·max(0, n·l)) with l towards the light
// (the camera's upper right), so the image's upper-right half is the brighter one.
#include "src/eval/studio_lights.h"

#include <gtest/gtest.h>

#include <cmath>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/scene_setup.h"
#include "src/render/render.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

constexpr int kSize = 48;        // image width and height, pixels; focal length kSize.
constexpr double kAlbedo = 0.5;  // grey, diffuse only.

Dataset OneView() {
  const char* kScene = R"({"format": "sft-dataset/1",
    "cameras": [{"id": "c", "model": "PINHOLE", "width": 48, "height": 48,
                 "params": [48, 48, 24, 24]}],
    "lights": [],
    "views": [{"image": "a.exr", "camera": "c", "lights": [],
               "cam_from_world": {"rotation": [0, 1, 0, 0], "translation": [0, 0, 3]}}]})";
  Dataset dataset;
  EXPECT_TRUE(ParseSceneJson(kScene, "ds", &dataset).ok());
  return dataset;
}

// Renders the sphere under `condition`; RGB.
Image RenderUnder(const RelightCondition& condition) {
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_1280f.obj", &mesh).ok());
  const RenderScene scene(mesh);
  const Material material = ConstantMaterial(static_cast<int>(mesh.n_faces()),
                                             Eigen::Vector3d::Constant(kAlbedo), 0.5, 0.0);
  DatasetViews views;
  EXPECT_TRUE(MakeDatasetViews(RelitDataset(OneView(), condition), &views).ok());
  RenderOptions options;
  options.spp = 64;
  options.bounces = 2;
  options.shading = Shading::kSmooth;
  Image image;
  RenderView(scene, material, views.views[0], options, &image);
  return ToRgb(image);
}

// The unit normal, in the camera frame, where pixel (x, y)'s centre ray meets a sphere of radius
// r about (0, 0, 3); false when it misses.
bool SphereNormal(int x, int y, double r, Eigen::Vector3d* n) {
  const Eigen::Vector3d d =
      Eigen::Vector3d((x + 0.5 - kSize / 2.0) / kSize, (y + 0.5 - kSize / 2.0) / kSize, 1.0)
          .normalized();
  const Eigen::Vector3d c(0, 0, 3);
  const double b = d.dot(c), disc = b * b - (c.squaredNorm() - r * r);
  if (disc < 0) return false;
  *n = ((b - std::sqrt(disc)) * d - c).normalized();
  return true;
}

TEST(StudioLights, AmbientShowsTheAlbedo) {
  const std::vector<RelightCondition> conditions = StudioConditions();
  ASSERT_EQ(conditions.size(), 2u);
  ASSERT_EQ(conditions[1].name, "ambient");
  const Image image = RenderUnder(conditions[1]);
  int count = 0;
  double sum = 0, worst = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      Eigen::Vector3d n;
      if (!SphereNormal(x, y, 0.9, &n)) continue;  // inside the silhouette, off its edge pixels.
      const double v = image.at(x, y, 1);
      sum += v;
      worst = std::max(worst, std::abs(v - kAlbedo));
      ++count;
    }
  }
  ASSERT_GT(count, 300);
  EXPECT_NEAR(sum / count, kAlbedo, 0.01);
  EXPECT_LT(worst, 0.05);  // per pixel at 64 spp.
}

TEST(StudioLights, KeyLightsFromTheUpperRight) {
  const RelightCondition key = StudioConditions()[0];
  ASSERT_EQ(key.name, "key");
  const Image image = RenderUnder(key);
  const Eigen::Vector3d to_light = Eigen::Vector3d(1, -1, -1).normalized();  // camera frame.
  int count = 0;
  double error = 0, upper_right = 0, lower_left = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      Eigen::Vector3d n;
      if (!SphereNormal(x, y, 0.9, &n)) continue;
      const double v = image.at(x, y, 0);
      const double expected = kAlbedo * (kStudioFill + kStudioKey * std::max(0.0, n.dot(to_light)));
      error += std::abs(v - expected);
      ++count;
      if (x > y) upper_right += v;  // right of and above the image diagonal.
      if (x < y) lower_left += v;
    }
  }
  ASSERT_GT(count, 300);
  EXPECT_LT(error / count, 0.02);            // mean absolute error against a·(0.2 + 0.8·cos).
  EXPECT_GT(upper_right, 1.5 * lower_left);  // 1.9× by the closed form.
}

}  // namespace
}  // namespace sft
