// The whole synthetic-video road of issue 12: `sft synth` (textured spot on a textured ground
// plane, orbit path, environment behind) → OpenCV VideoWriter → `sft import video` (COLMAP on
// CPU) → `sft init`. Checks the recovered poses after a similarity fit to the truth (0.5°, 1% of
// the object's bounding-box diagonal) and reports the hull's F1@0.01 against the true mesh.
// Long (minutes: rendering and COLMAP), so labelled `long` by its name.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "src/eval/mesh_metrics.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/image_io.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {
namespace fs = std::filesystem;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Linear RGB image → 8-bit sRGB BGR frame.
cv::Mat ToFrame(const Image& image) {
  cv::Mat frame(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = LinearToSrgb(std::clamp(image.at(x, y, c), 0.0f, 1.0f));
        frame.at<cv::Vec3b>(y, x)[2 - c] = static_cast<uint8_t>(std::lround(255 * v));
      }
    }
  }
  return frame;
}

// Frame number of an imported view's image "images/frame_000123.png".
int FrameNumber(const std::string& image) {
  const std::string stem = fs::path(image).stem().string();
  return std::stoi(stem.substr(stem.find('_') + 1));
}

TEST(VideoImportLongTest, SyntheticVideoToDatasetAndHull) {
  testing::TempDir tmp;
  const std::string spot = testing::DataDir() + "/cycles/spot_textured_point/gt";
  const std::string probe = testing::DataDir() + "/cycles/sphere_env_studio/probes/studio.exr";
  const int kFrames = 60;
  std::string out;
  auto t = std::chrono::steady_clock::now();
  ASSERT_EQ(
      testing::RunSft("synth --quiet --mesh " + spot +
                          "/mesh_uv.obj --material '{\"albedo_texture\": \"" + spot +
                          "/texture.png\", \"colorspace\": \"srgb\", \"roughness\": 0.6}' " +
                          "--envmap " + probe + " --background-environment --ground --path orbit " +
                          "--elevation 20,45 --cameras " + std::to_string(kFrames) +
                          " --zooms 1 --res 480 --fov 45 --fill 0.5 --spp 16 --bounces 1 --out " +
                          tmp.Join("synth"),
                      &out),
      0)
      << out;
  const double synth_seconds = Seconds(t);
  Dataset truth;
  ASSERT_TRUE(ReadDataset(tmp.Join("synth"), &truth).ok());
  ASSERT_EQ(truth.views.size(), static_cast<size_t>(kFrames));

  // Video (lossless FFV1 when OpenCV's backend has it, else MJPG) and frame-named masks.
  t = std::chrono::steady_clock::now();
  std::string video = tmp.Join("orbit.avi");
  std::string codec = "FFV1";
  cv::VideoWriter writer(video, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 10,
                         cv::Size(480, 480));
  if (!writer.isOpened()) {
    codec = "MJPG";
    writer.open(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, cv::Size(480, 480));
  }
  ASSERT_TRUE(writer.isOpened());
  fs::create_directories(tmp.Join("masks"));
  for (int v = 0; v < kFrames; ++v) {
    Image image;
    ASSERT_TRUE(LoadViewImage(truth, v, &image).ok());
    writer.write(ToFrame(image));
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%06d.png", v);
    fs::copy_file(tmp.Join("synth/" + truth.views[v].mask), tmp.Join(std::string("masks/") + name));
  }
  writer.release();
  const double video_seconds = Seconds(t);

  t = std::chrono::steady_clock::now();
  ASSERT_EQ(testing::RunSft("import video --video " + video + " --frames 40 --masks " +
                                tmp.Join("masks") + " --out " + tmp.Join("imported"),
                            &out),
            0)
      << out;
  const double import_seconds = Seconds(t);
  std::printf("import output (tail): %s\n",
              out.substr(out.size() > 600 ? out.size() - 600 : 0).c_str());
  Dataset imported;
  ASSERT_TRUE(ReadDataset(tmp.Join("imported"), &imported).ok());
  EXPECT_EQ(imported.lighting, "unknown");
  ASSERT_GE(imported.views.size(), 32u);  // --min-registered 0.8 of 40

  // Similarity (Umeyama) from the imported world to the truth's, on camera centres.
  const int n = static_cast<int>(imported.views.size());
  Eigen::Matrix3Xd source(3, n), target(3, n);
  std::vector<int> frame(n);
  for (int i = 0; i < n; ++i) {
    frame[i] = FrameNumber(imported.views[i].image);
    ASSERT_LT(frame[i], kFrames);
    source.col(i) = imported.views[i].cam_from_world.Inverse().translation;
    target.col(i) = truth.views[frame[i]].cam_from_world.Inverse().translation;
  }
  const Eigen::Matrix4d sim = Eigen::umeyama(source, target, true);
  const double scale = sim.block<3, 3>(0, 0).col(0).norm();
  const Eigen::Matrix3d align = sim.block<3, 3>(0, 0) / scale;
  double max_angle = 0, max_position = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d centre = scale * align * source.col(i) + sim.block<3, 1>(0, 3);
    max_position = std::max(max_position, (centre - target.col(i)).norm());
    const Eigen::Matrix3d r_est = imported.views[i].cam_from_world.rotation.toRotationMatrix();
    const Eigen::Matrix3d r_true = truth.views[frame[i]].cam_from_world.rotation.toRotationMatrix();
    const Eigen::AngleAxisd error(r_true * (align * r_est.transpose()));
    max_angle = std::max(max_angle, error.angle() * 180 / M_PI);
  }

  t = std::chrono::steady_clock::now();
  ASSERT_EQ(testing::RunSft("init --quiet --dataset " + tmp.Join("imported"), &out), 0) << out;
  const double init_seconds = Seconds(t);
  TriMesh hull, gt;
  ASSERT_TRUE(ReadMesh(tmp.Join("imported/init/mesh.ply"), &hull).ok());
  ASSERT_TRUE(ReadMesh(tmp.Join("synth/gt/mesh.ply"), &gt).ok());
  for (auto vh : hull.vertices()) {
    const auto p = hull.point(vh);
    const Eigen::Vector3d q =
        scale * align * Eigen::Vector3d(p[0], p[1], p[2]) + sim.block<3, 1>(0, 3);
    hull.set_point(vh, TriMesh::Point(q.x(), q.y(), q.z()));
  }
  MeshMetricsOptions metric_options;
  metric_options.samples = 200000;
  MeshMetrics metrics;
  ASSERT_TRUE(ComputeMeshMetrics(gt, hull, metric_options, &metrics).ok());

  std::printf(
      "video road: codec %s, %d frames rendered (%.1f s), video %.1f s; import: %d views "
      "registered of 40 selected (%.1f s); max pose error %.4f deg, %.5f (object diagonal 1); "
      "init %.1f s; hull F1@0.01 %.4f (precision %.4f, recall %.4f, chamfer %.5f)\n",
      codec.c_str(), kFrames, synth_seconds, video_seconds, n, import_seconds, max_angle,
      max_position, init_seconds, metrics.f1, metrics.precision, metrics.recall, metrics.chamfer);
  EXPECT_LT(max_angle, 0.5);
  EXPECT_LT(max_position, 0.01);
  EXPECT_GT(metrics.f1, 0.0);
}

}  // namespace
}  // namespace sft
