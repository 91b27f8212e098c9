#include "tests/testing/video_road.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "src/capture/auto_masks.h"
#include "src/image/image_io.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace testing {
namespace {

namespace fs = std::filesystem;

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

}  // namespace

std::string StudioProbe() { return DataDir() + "/cycles/sphere_env_studio/probes/studio.exr"; }

std::string KeptVideoRoadDir() {
  const char* keep = std::getenv("SFT_VIDEO_ROAD_DIR");
  if (keep == nullptr || *keep == 0) return "";
  fs::create_directories(keep);
  return keep;
}

void RenderVideoTruth(const std::string& dir) {
  if (fs::exists(dir + "/synth/scene.json")) return;
  const std::string spot = DataDir() + "/cycles/spot_textured_point/gt";
  std::string out;
  ASSERT_EQ(
      RunSft("synth --quiet --overwrite --mesh " + spot +
                 "/mesh_uv.obj --material '{\"albedo_texture\": \"" + spot +
                 "/texture.png\", \"colorspace\": \"srgb\", \"roughness\": 0.6}' " + "--envmap " +
                 StudioProbe() + " --background-environment --ground --path orbit " +
                 "--elevation 20,45 --cameras " + std::to_string(kVideoFrames) +
                 " --zooms 1 --res " + std::to_string(kVideoSize) +
                 " --fov 45 --fill 0.5 --spp 16 --bounces 1 --out " + dir + "/synth",
             &out),
      0)
      << out;
}

void WriteVideo(const Dataset& truth, const std::string& video, std::string* codec) {
  if (fs::exists(video)) {
    *codec = "(reused)";
    return;
  }
  *codec = "FFV1";
  cv::VideoWriter writer(video, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 10,
                         cv::Size(kVideoSize, kVideoSize));
  if (!writer.isOpened()) {
    *codec = "MJPG";
    writer.open(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                cv::Size(kVideoSize, kVideoSize));
  }
  ASSERT_TRUE(writer.isOpened());
  for (int v = 0; v < kVideoFrames; ++v) {
    Image image;
    ASSERT_TRUE(LoadViewImage(truth, v, &image).ok());
    writer.write(ToFrame(image));
  }
  writer.release();
}

void FitPoses(const Dataset& imported, const Dataset& truth, PoseFit* fit) {
  const int n = static_cast<int>(imported.views.size());
  Eigen::Matrix3Xd source(3, n), target(3, n);
  fit->frame.resize(n);
  for (int i = 0; i < n; ++i) {
    fit->frame[i] = FrameNumber(imported.views[i].image);
    ASSERT_LT(fit->frame[i], kVideoFrames);
    source.col(i) = imported.views[i].cam_from_world.Inverse().translation;
    target.col(i) = truth.views[fit->frame[i]].cam_from_world.Inverse().translation;
  }
  const Eigen::Matrix4d sim = Eigen::umeyama(source, target, true);
  fit->scale = sim.block<3, 3>(0, 0).col(0).norm();
  fit->align = sim.block<3, 3>(0, 0) / fit->scale;
  fit->shift = sim.block<3, 1>(0, 3);
  for (int i = 0; i < n; ++i) {
    fit->max_position =
        std::max(fit->max_position, (fit->Map(source.col(i)) - target.col(i)).norm());
    const Eigen::Matrix3d r_est = imported.views[i].cam_from_world.rotation.toRotationMatrix();
    const Eigen::Matrix3d r_true =
        truth.views[fit->frame[i]].cam_from_world.rotation.toRotationMatrix();
    const Eigen::AngleAxisd error(r_true * (fit->align * r_est.transpose()));
    fit->max_angle_deg = std::max(fit->max_angle_deg, error.angle() * 180 / M_PI);
  }
}

TriMesh MapMesh(const TriMesh& mesh,
                const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& map) {
  TriMesh mapped = mesh;
  for (auto vh : mapped.vertices()) {
    const auto p = mapped.point(vh);
    const Eigen::Vector3d q = map(Eigen::Vector3d(p[0], p[1], p[2]));
    mapped.set_point(vh, TriMesh::Point(q.x(), q.y(), q.z()));
  }
  return mapped;
}

void MetricsInTruthFrame(const std::string& dir, const std::string& path, const PoseFit& fit,
                         MeshMetrics* metrics) {
  TriMesh mesh, gt;
  ASSERT_TRUE(ReadMesh(path, &mesh).ok());
  ASSERT_TRUE(ReadMesh(dir + "/synth/gt/mesh.ply", &gt).ok());
  const TriMesh mapped = MapMesh(mesh, [&](const Eigen::Vector3d& p) { return fit.Map(p); });
  MeshMetricsOptions metric_options;
  metric_options.samples = 200000;
  ASSERT_TRUE(ComputeMeshMetrics(gt, mapped, metric_options, metrics).ok());
}

void MaskIoUs(const Dataset& imported, const Dataset& truth, const PoseFit& fit, double* mean,
              double* min) {
  double sum = 0;
  *min = 1;
  for (size_t i = 0; i < imported.views.size(); ++i) {
    Image automatic, actual;
    ASSERT_TRUE(LoadViewMask(imported, static_cast<int>(i), &automatic).ok());
    ASSERT_TRUE(LoadViewMask(truth, fit.frame[i], &actual).ok());
    const double iou = MaskIoU(automatic, actual);
    sum += iou;
    *min = std::min(*min, iou);
  }
  *mean = sum / std::max<size_t>(1, imported.views.size());
}

}  // namespace testing
}  // namespace sft
