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
// video found there are reused (tests/testing/video_road.h; the import always runs, into
// DIR/import_test, so that it does not replace the import and reconstruction that
// video_reconstruct_long_test.cc keeps in DIR/imported and DIR/recon). Otherwise a temporary
// folder is used.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cstdio>
#include <memory>

#include "src/eval/mesh_metrics.h"
#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/video_road.h"

namespace sft {
namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Angle between the imported probe's rotation, carried into the truth's frame, and the truth's.
double ProbeErrorDeg(const Dataset& imported, const Dataset& truth, const testing::PoseFit& fit) {
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

TEST(VideoImportLongTest, SyntheticVideoWithProbeAndAutoMasksToDatasetAndHull) {
  std::unique_ptr<testing::TempDir> tmp;
  std::string dir = testing::KeptVideoRoadDir();
  if (dir.empty()) {
    tmp = std::make_unique<testing::TempDir>();
    dir = tmp->path();
  }
  auto t = std::chrono::steady_clock::now();
  testing::RenderVideoTruth(dir);
  if (HasFatalFailure()) return;
  const double synth_seconds = Seconds(t);
  Dataset truth;
  ASSERT_TRUE(ReadDataset(dir + "/synth", &truth).ok());
  ASSERT_EQ(truth.views.size(), static_cast<size_t>(testing::kVideoFrames));
  const std::string video = dir + "/orbit.avi";
  std::string codec;
  testing::WriteVideo(truth, video, &codec);
  if (HasFatalFailure()) return;

  t = std::chrono::steady_clock::now();
  std::string out;
  ASSERT_EQ(testing::RunSft("import video --overwrite --video " + video + " --frames " +
                                std::to_string(testing::kVideoSelected) + " --masks auto --probe " +
                                testing::StudioProbe() + " --out " + dir + "/import_test",
                            &out),
            0)
      << out;
  const double import_seconds = Seconds(t);
  std::printf("import output (tail): %s\n",
              out.substr(out.size() > 600 ? out.size() - 600 : 0).c_str());
  Dataset imported;
  ASSERT_TRUE(ReadDataset(dir + "/import_test", &imported).ok());
  ASSERT_GE(imported.views.size(),
            static_cast<size_t>(testing::kVideoSelected * 8 / 10));  // --min-registered

  testing::PoseFit fit;
  testing::FitPoses(imported, truth, &fit);
  if (HasFatalFailure()) return;
  const double probe_error = ProbeErrorDeg(imported, truth, fit);
  double iou_mean = 0, iou_min = 0;
  testing::MaskIoUs(imported, truth, fit, &iou_mean, &iou_min);
  if (HasFatalFailure()) return;

  t = std::chrono::steady_clock::now();
  ASSERT_EQ(testing::RunSft("init --quiet --dataset " + dir + "/import_test", &out), 0) << out;
  const double init_seconds = Seconds(t);
  MeshMetrics metrics;
  testing::MetricsInTruthFrame(dir, dir + "/import_test/init/mesh.ply", fit, &metrics);
  if (HasFatalFailure()) return;

  std::printf(
      "video road: codec %s, %d frames rendered (%.1f s); import: %zu views registered of %d "
      "selected (%.1f s); max pose error %.4f deg, %.5f (object diagonal 1); probe: %s, error "
      "%.3f deg; auto masks IoU mean %.4f min %.4f; init %.1f s; hull F1@0.01 %.4f (precision "
      "%.4f, recall %.4f, chamfer %.5f)\n",
      codec.c_str(), testing::kVideoFrames, synth_seconds, imported.views.size(),
      testing::kVideoSelected, import_seconds, fit.max_angle_deg, fit.max_position,
      imported.lighting.c_str(), probe_error, iou_mean, iou_min, init_seconds, metrics.f1,
      metrics.precision, metrics.recall, metrics.chamfer);
  EXPECT_LT(fit.max_angle_deg, 0.5);
  EXPECT_LT(fit.max_position, 0.01);
  EXPECT_LT(probe_error, 2.0);  // issue 12; measured 0.17°.
  // Measured (docs/design-notes.md, "Background consistency for the automatic masks"): IoU mean
  // 0.940, min 0.912, carve F1@0.01 0.858 with three passes (0.961 with synth's masks; 0.833, 0.727
  // and 0.609 with GrabCut from the seeds alone).
  EXPECT_GT(iou_mean, 0.88);
  EXPECT_GT(iou_min, 0.8);
  EXPECT_GT(metrics.f1, 0.72);
}

}  // namespace
}  // namespace sft
