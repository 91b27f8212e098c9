// The whole synthetic-video road of issue 12: `sft synth` (textured spot on a textured ground
// plane, orbit path, studio probe behind) → OpenCV VideoWriter → `sft import video --probe
// --masks auto` (COLMAP on CPU, probe alignment, GrabCut masks) → `sft init`. Checks the recovered
// poses after a similarity fit to the truth (0.5°, 1% of the object's bounding-box diagonal), the
// aligned probe's rotation against the truth (2°), the automatic masks' IoU against synth's masks
// and the hull's F1@0.01 against the true mesh. Thresholds sit below the values measured in
// docs/design-notes.md ("Synthetic video through `sft import video`").
// Long (minutes: rendering and COLMAP), so labelled `long` by its name.
//
// With SFT_VIDEO_ROAD_DIR set, the road's files go there and are kept, and a rendered truth and
// video found there are reused (for iterating on the import; delete the folder after changing the
// scene). Otherwise a temporary folder is used.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "src/eval/mesh_metrics.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/auto_masks.h"
#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {
namespace fs = std::filesystem;

constexpr int kFrames = 60;    // rendered frames (the video's length).
constexpr int kSelected = 40;  // frames `sft import video` selects.
constexpr int kSize = 480;     // frame width and height, pixels.

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

std::string StudioProbe() {
  return testing::DataDir() + "/cycles/sphere_env_studio/probes/studio.exr";
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

// Renders the truth into DIR/synth (textured spot over the ground, orbit, studio probe behind).
void RenderTruth(const std::string& dir) {
  const std::string spot = testing::DataDir() + "/cycles/spot_textured_point/gt";
  std::string out;
  ASSERT_EQ(testing::RunSft("synth --quiet --overwrite --mesh " + spot +
                                "/mesh_uv.obj --material '{\"albedo_texture\": \"" + spot +
                                "/texture.png\", \"colorspace\": \"srgb\", \"roughness\": 0.6}' " +
                                "--envmap " + StudioProbe() +
                                " --background-environment --ground --path orbit " +
                                "--elevation 20,45 --cameras " + std::to_string(kFrames) +
                                " --zooms 1 --res " + std::to_string(kSize) +
                                " --fov 45 --fill 0.5 --spp 16 --bounces 1 --out " + dir + "/synth",
                            &out),
            0)
      << out;
}

// Encodes the truth's views as VIDEO (lossless FFV1 when OpenCV's backend has it, else MJPG).
void WriteVideo(const Dataset& truth, const std::string& video, std::string* codec) {
  *codec = "FFV1";
  cv::VideoWriter writer(video, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 10,
                         cv::Size(kSize, kSize));
  if (!writer.isOpened()) {
    *codec = "MJPG";
    writer.open(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, cv::Size(kSize, kSize));
  }
  ASSERT_TRUE(writer.isOpened());
  for (int v = 0; v < kFrames; ++v) {
    Image image;
    ASSERT_TRUE(LoadViewImage(truth, v, &image).ok());
    writer.write(ToFrame(image));
  }
  writer.release();
}

// The imported world mapped onto the truth's: p_truth = scale · align · p + shift, fitted
// (Umeyama) on the camera centres; the largest rotation and centre errors of the views after it.
struct PoseFit {
  double scale = 1;
  Eigen::Matrix3d align = Eigen::Matrix3d::Identity();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  std::vector<int> frame;  // imported view → truth view.
  double max_angle_deg = 0, max_position = 0;

  Eigen::Vector3d Map(const Eigen::Vector3d& p) const { return scale * align * p + shift; }
};

void FitPoses(const Dataset& imported, const Dataset& truth, PoseFit* fit) {
  const int n = static_cast<int>(imported.views.size());
  Eigen::Matrix3Xd source(3, n), target(3, n);
  fit->frame.resize(n);
  for (int i = 0; i < n; ++i) {
    fit->frame[i] = FrameNumber(imported.views[i].image);
    ASSERT_LT(fit->frame[i], kFrames);
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

// Angle between the imported probe's rotation, carried into the truth's frame, and the truth's.
double ProbeErrorDeg(const Dataset& imported, const Dataset& truth, const PoseFit& fit) {
  const LightSpec* estimated = nullptr;
  const LightSpec* actual = nullptr;
  for (const LightSpec& l : imported.lights) {
    if (l.type == LightType::kEnvironment) estimated = &l;
  }
  for (const LightSpec& l : truth.lights) {
    if (l.type == LightType::kEnvironment) actual = &l;
  }
  if (estimated == nullptr || actual == nullptr) return 180;
  const Eigen::AngleAxisd error(fit.align * estimated->world_from_env *
                                actual->world_from_env.transpose());
  return error.angle() * 180 / M_PI;
}

// IoU of each imported view's automatic mask against synth's mask of the same frame.
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

// F1@0.01 etc. of the imported dataset's init/mesh.ply, mapped into the truth's frame.
void HullMetrics(const std::string& dir, const PoseFit& fit, MeshMetrics* metrics) {
  TriMesh hull, gt;
  ASSERT_TRUE(ReadMesh(dir + "/imported/init/mesh.ply", &hull).ok());
  ASSERT_TRUE(ReadMesh(dir + "/synth/gt/mesh.ply", &gt).ok());
  for (auto vh : hull.vertices()) {
    const auto p = hull.point(vh);
    const Eigen::Vector3d q = fit.Map(Eigen::Vector3d(p[0], p[1], p[2]));
    hull.set_point(vh, TriMesh::Point(q.x(), q.y(), q.z()));
  }
  MeshMetricsOptions metric_options;
  metric_options.samples = 200000;
  ASSERT_TRUE(ComputeMeshMetrics(gt, hull, metric_options, metrics).ok());
}

TEST(VideoImportLongTest, SyntheticVideoWithProbeAndAutoMasksToDatasetAndHull) {
  std::unique_ptr<testing::TempDir> tmp;
  std::string dir;
  if (const char* keep = std::getenv("SFT_VIDEO_ROAD_DIR"); keep != nullptr && *keep != 0) {
    dir = keep;
    fs::create_directories(dir);
  } else {
    tmp = std::make_unique<testing::TempDir>();
    dir = tmp->path();
  }
  auto t = std::chrono::steady_clock::now();
  if (!fs::exists(dir + "/synth/scene.json")) RenderTruth(dir);
  if (HasFatalFailure()) return;
  const double synth_seconds = Seconds(t);
  Dataset truth;
  ASSERT_TRUE(ReadDataset(dir + "/synth", &truth).ok());
  ASSERT_EQ(truth.views.size(), static_cast<size_t>(kFrames));
  const std::string video = dir + "/orbit.avi";
  std::string codec = "(reused)";
  if (!fs::exists(video)) WriteVideo(truth, video, &codec);
  if (HasFatalFailure()) return;

  t = std::chrono::steady_clock::now();
  std::string out;
  ASSERT_EQ(testing::RunSft("import video --overwrite --video " + video + " --frames " +
                                std::to_string(kSelected) + " --masks auto --probe " +
                                StudioProbe() + " --out " + dir + "/imported",
                            &out),
            0)
      << out;
  const double import_seconds = Seconds(t);
  std::printf("import output (tail): %s\n",
              out.substr(out.size() > 600 ? out.size() - 600 : 0).c_str());
  Dataset imported;
  ASSERT_TRUE(ReadDataset(dir + "/imported", &imported).ok());
  ASSERT_GE(imported.views.size(), static_cast<size_t>(kSelected * 8 / 10));  // --min-registered

  PoseFit fit;
  FitPoses(imported, truth, &fit);
  if (HasFatalFailure()) return;
  const double probe_error = ProbeErrorDeg(imported, truth, fit);
  double iou_mean = 0, iou_min = 0;
  MaskIoUs(imported, truth, fit, &iou_mean, &iou_min);
  if (HasFatalFailure()) return;

  t = std::chrono::steady_clock::now();
  ASSERT_EQ(testing::RunSft("init --quiet --dataset " + dir + "/imported", &out), 0) << out;
  const double init_seconds = Seconds(t);
  MeshMetrics metrics;
  HullMetrics(dir, fit, &metrics);
  if (HasFatalFailure()) return;

  std::printf(
      "video road: codec %s, %d frames rendered (%.1f s); import: %zu views registered of %d "
      "selected (%.1f s); max pose error %.4f deg, %.5f (object diagonal 1); probe: %s, error "
      "%.3f deg; auto masks IoU mean %.4f min %.4f; init %.1f s; hull F1@0.01 %.4f (precision "
      "%.4f, recall %.4f, chamfer %.5f)\n",
      codec.c_str(), kFrames, synth_seconds, imported.views.size(), kSelected, import_seconds,
      fit.max_angle_deg, fit.max_position, imported.lighting.c_str(), probe_error, iou_mean,
      iou_min, init_seconds, metrics.f1, metrics.precision, metrics.recall, metrics.chamfer);
  EXPECT_LT(fit.max_angle_deg, 0.5);
  EXPECT_LT(fit.max_position, 0.01);
  EXPECT_LT(probe_error, 2.0);  // issue 12; measured 0.17°.
  // Measured (docs/design-notes.md): IoU mean 0.833, min 0.727; F1@0.01 0.609 (0.961 with
  // synth's masks: the automatic masks' errors carve the hull).
  EXPECT_GT(iou_mean, 0.75);
  EXPECT_GT(iou_min, 0.6);
  EXPECT_GT(metrics.f1, 0.5);
}

}  // namespace
}  // namespace sft
