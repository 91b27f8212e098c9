// `sft import video`: a video of an object becomes an sft-dataset/1 (docs/import.md "Video").
// Steps: frame selection (src/io/video_frames.h), COLMAP's CPU pipeline through its command line
// (src/capture/colmap_runner.h: feature_extractor with one shared camera, exhaustive_matcher up to
// `exhaustive_limit` frames else sequential_matcher, mapper), then the largest model is imported
// by ImportColmap (src/capture/colmap_import.h). The COLMAP workspace (frames, database, models)
// lives in OUT.video-work, beside OUT; COLMAP's output goes to OUT/colmap/log.txt and the selected
// frames to OUT/colmap/frames.json. On success OUT.video-work is removed; when COLMAP fails it is
// kept for inspection and the error names its log.
#ifndef SFT_CAPTURE_VIDEO_IMPORT_H_
#define SFT_CAPTURE_VIDEO_IMPORT_H_

#include <string>
#include <vector>

#include "src/capture/colmap_import.h"
#include "src/core/status.h"
#include "src/io/video_frames.h"

namespace sft {

struct VideoImportOptions {
  std::string video;                // input video (anything OpenCV's VideoCapture decodes).
  std::string out;                  // output dataset folder.
  FrameSelectionOptions selection;  // how many frames, duplicate rule.
  std::string probe;                // optional equirectangular probe (as `sft import colmap`).
  std::string masks;                // "" (none), "auto" (GrabCut) or a folder of frame masks.
  double min_registered = 0.8;      // fraction of the selected frames COLMAP must register, [0, 1].
  int exhaustive_limit = 150;       // exhaustive matching up to this many frames, [2, 10000].
  std::string camera_model = "SIMPLE_RADIAL";  // shared COLMAP camera model sft supports.
  std::string colmap = "colmap";               // COLMAP executable.
  NormalizationOptions normalization;          // as `sft import colmap`.
  AutoMaskOptions auto_masks;                  // how --masks auto segments (as `import colmap`).
  bool overwrite = false;                      // replace an existing, non-empty output folder.
  bool quiet = false;                          // no progress or summary line.

  bool Check(std::string* why) const;
};

struct VideoImportReport {
  int frames_decoded = 0;         // frames in the video.
  int frames_selected = 0;        // frames given to COLMAP.
  int registered = 0;             // images in the largest model.
  int models = 0;                 // models COLMAP's mapper wrote.
  double reprojection_error = 0;  // mean over the largest model's points, pixels.
  std::string matcher;            // "exhaustive_matcher" or "sequential_matcher".
  double seconds_frames = 0, seconds_features = 0, seconds_matching = 0, seconds_mapping = 0;
  ColmapImportReport import;  // the model import.
  double seconds = 0;         // wall time, all steps.
};

Status ImportVideo(const VideoImportOptions& options, VideoImportReport* report);

// One COLMAP program run: `colmap name args...`.
struct ColmapStage {
  std::string name;  // feature_extractor, exhaustive_matcher, sequential_matcher or mapper.
  std::vector<std::string> args;
};

// The COLMAP runs for `frames` selected frames in workspace `work` (frames in WORK/frames, the
// database WORK/database.db, models under WORK/sparse): feature extraction with one shared camera
// of options.camera_model; exhaustive matching when frames <= options.exhaustive_limit (in blocks
// of 10 images, so its progress line moves), else sequential matching (no vocabulary tree offline,
// so no loop detection); mapping. GPU off everywhere (COLMAP aborts headless otherwise).
std::vector<ColmapStage> PlanColmapStages(const VideoImportOptions& options,
                                          const std::string& work, int frames);

// The --min-registered rule: an error when COLMAP wrote no model or registered fewer than
// min_registered × selected frames. The one-line message says how many registered, of how many,
// the threshold, what to try and where COLMAP's log is.
Status CheckRegistered(int registered, int selected, bool has_model, double min_registered,
                       const std::string& log_path);

}  // namespace sft

#endif  // SFT_CAPTURE_VIDEO_IMPORT_H_
