// The synthetic video road of issue 12, shared by the long tests that walk it
// (tests/apps/video_import_long_test.cc: import and hull; video_reconstruct_long_test.cc: the
// reconstruction scored against the truth): `sft synth` renders a textured spot on a textured
// ground plane along an orbit under the studio probe (visible behind), the frames become a video
// (OpenCV VideoWriter), and `sft import video --probe --masks auto` brings it back as a dataset.
// The imported world is the truth's up to a similarity, fitted on the camera centres.
#ifndef SFT_TESTS_TESTING_VIDEO_ROAD_H_
#define SFT_TESTS_TESTING_VIDEO_ROAD_H_

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "src/eval/mesh_metrics.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"

namespace sft {
namespace testing {

constexpr int kVideoFrames = 60;    // rendered frames (the video's length).
constexpr int kVideoSelected = 40;  // frames `sft import video` selects.
constexpr int kVideoSize = 480;     // frame width and height, pixels.

// data/'s studio probe (the truth's lighting and the import's --probe).
std::string StudioProbe();

// The road's folder: $SFT_VIDEO_ROAD_DIR when set (kept, and what is found there is reused:
// synth/, orbit.avi, imported/; delete it after changing the scene), else "" (use a temporary
// folder).
std::string KeptVideoRoadDir();

// Renders the truth into DIR/synth unless DIR/synth/scene.json exists. Fatal failures on error.
void RenderVideoTruth(const std::string& dir);

// Encodes the truth's views as VIDEO (lossless FFV1 when OpenCV's backend has it, else MJPG)
// unless VIDEO exists (then *codec = "(reused)").
void WriteVideo(const Dataset& truth, const std::string& video, std::string* codec);

// The imported world mapped onto the truth's: p_truth = scale · align · p + shift, fitted
// (Umeyama) on the camera centres; the largest rotation and centre errors of the views after it.
struct PoseFit {
  double scale = 1;
  Eigen::Matrix3d align = Eigen::Matrix3d::Identity();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  std::vector<int> frame;  // imported view → truth view.
  double max_angle_deg = 0, max_position = 0;

  Eigen::Vector3d Map(const Eigen::Vector3d& p) const { return scale * align * p + shift; }
  Eigen::Vector3d Unmap(const Eigen::Vector3d& q) const {
    return align.transpose() * (q - shift) / scale;
  }
};
void FitPoses(const Dataset& imported, const Dataset& truth, PoseFit* fit);

// `mesh` with every vertex passed through `map` (e.g. PoseFit::Map or Unmap).
TriMesh MapMesh(const TriMesh& mesh,
                const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& map);

// F1, Chamfer etc. (200k samples, tolerance 0.01) of the mesh file `path` of the imported world,
// mapped into the truth's frame, against DIR/synth/gt/mesh.ply.
void MetricsInTruthFrame(const std::string& dir, const std::string& path, const PoseFit& fit,
                         MeshMetrics* metrics);

// IoU of each imported view's mask against the truth's mask of the same frame: the mean and the
// smallest. Fatal failures when a mask does not load.
void MaskIoUs(const Dataset& imported, const Dataset& truth, const PoseFit& fit, double* mean,
              double* min);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_VIDEO_ROAD_H_
