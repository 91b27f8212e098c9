#include "src/capture/video_import.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "src/capture/colmap_runner.h"
#include "src/core/file_util.h"
#include "src/io/colmap_model.h"

namespace sft {
namespace {
namespace fs = std::filesystem;

// The model folder under `sparse` with the most registered images; "" when there is none.
Status LargestModel(const std::string& sparse, std::string* best_dir, ColmapModel* best,
                    int* models) {
  best_dir->clear();
  *models = 0;
  std::error_code ec;
  if (!fs::is_directory(sparse, ec)) return Status::Ok();
  for (const auto& entry : fs::directory_iterator(sparse, ec)) {
    if (!entry.is_directory()) continue;
    ColmapModel model;
    if (!ReadColmapModel(entry.path().string(), &model).ok()) continue;
    ++*models;
    if (best_dir->empty() || model.images.size() > best->images.size()) {
      *best_dir = entry.path().string();
      *best = std::move(model);
    }
  }
  return Status::Ok();
}

double MeanReprojectionError(const ColmapModel& model) {
  double sum = 0;
  int count = 0;
  for (const ColmapPoint3D& p : model.points) {
    if (p.error >= 0) {
      sum += p.error;
      ++count;
    }
  }
  return count > 0 ? sum / count : -1;
}

Status RunColmap(const VideoImportOptions& opts, const std::string& work, int frames,
                 VideoImportReport* report) {
  const std::vector<ColmapStage> stages = PlanColmapStages(opts, work, frames);
  report->matcher = stages[1].name;
  SFT_RETURN_IF_ERROR(MakeDirectories(JoinPath(work, "sparse")));
  double* seconds[] = {&report->seconds_features, &report->seconds_matching,
                       &report->seconds_mapping};
  for (size_t i = 0; i < stages.size(); ++i) {
    SFT_RETURN_IF_ERROR(RunColmapStage(opts.colmap, stages[i].name, stages[i].args,
                                       JoinPath(work, "log.txt"), frames, !opts.quiet, seconds[i]));
  }
  return Status::Ok();
}

// Checks the inputs and the output folders before anything is written.
Status CheckInputsAndOutputs(const VideoImportOptions& opts, const std::string& work) {
  std::string why;
  if (!opts.Check(&why)) return Status::Error(why);
  // "auto": GrabCut masks from the imported sparse points, as `sft import colmap --masks auto`.
  const bool mask_folder = !opts.masks.empty() && opts.masks != "auto";
  std::error_code ec;
  if (mask_folder && !fs::is_directory(opts.masks, ec)) {
    return Status::Error("--masks: " + opts.masks + ": folder not found");
  }
  if (!opts.probe.empty() && !FileExists(opts.probe)) {
    return Status::Error("--probe: " + opts.probe + ": file not found");
  }
  const RunInputs inputs{{mask_folder ? opts.masks : std::string()}, {opts.video, opts.probe}};
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(opts.out, inputs, "--out"));
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(work, inputs, "--out (OUT.video-work)"));
  if (fs::exists(opts.out, ec) && !fs::is_empty(opts.out, ec) && !opts.overwrite) {
    return Status::Error(opts.out + ": output exists and is not empty (use --overwrite)");
  }
  return Status::Ok();
}

// The frames picked from the video (step 1).
struct SelectedFrames {
  std::vector<FrameScore> scores;  // every decoded frame.
  std::vector<int> picked;         // indices into scores.
  int width = 0, height = 0;       // frame size, pixels.
};

// Scores the video's frames, selects them and writes them to WORK/frames (a fresh WORK).
Status SelectAndWriteFrames(const VideoImportOptions& opts, const std::string& work,
                            SelectedFrames* frames, VideoImportReport* report) {
  const auto start = std::chrono::steady_clock::now();
  SFT_RETURN_IF_ERROR(
      ScoreVideoFrames(opts.video, &frames->scores, &frames->width, &frames->height, !opts.quiet));
  report->frames_decoded = static_cast<int>(frames->scores.size());
  frames->picked = SelectFrames(frames->scores, opts.selection);
  if (frames->picked.size() < 2) {
    return Status::Error("--video: " + opts.video + ": fewer than 2 distinct frames (" +
                         std::to_string(frames->scores.size()) + " decoded)");
  }
  std::vector<int> frame_numbers;
  for (int i : frames->picked) frame_numbers.push_back(frames->scores[i].index);
  report->frames_selected = static_cast<int>(frame_numbers.size());
  std::error_code ec;
  fs::remove_all(work, ec);
  SFT_RETURN_IF_ERROR(MakeDirectories(work));
  std::vector<std::string> names;
  SFT_RETURN_IF_ERROR(
      WriteVideoFrames(opts.video, frame_numbers, JoinPath(work, "frames"), &names));
  report->seconds_frames =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

// Imports COLMAP's model `model_dir` as `sft import colmap` would (step 3).
Status ImportModel(const VideoImportOptions& opts, const std::string& work,
                   const std::string& model_dir, VideoImportReport* report) {
  ColmapImportOptions import;
  import.model = model_dir;
  import.images = JoinPath(work, "frames");
  import.masks = opts.masks;
  import.probe = opts.probe;
  import.out = opts.out;
  import.normalization = opts.normalization;
  import.auto_masks = opts.auto_masks;
  import.import_dense = false;
  import.overwrite = opts.overwrite;
  import.quiet = opts.quiet;
  return ImportColmap(import, &report->import);
}

// OUT/colmap/frames.json (the selection and COLMAP's summary) and OUT/colmap/log.txt.
Status WriteFramesRecord(const VideoImportOptions& opts, const std::string& work,
                         const SelectedFrames& selected, const VideoImportReport& report) {
  nlohmann::json frames = nlohmann::json::object();
  frames["video"] = opts.video;
  frames["frames_decoded"] = report.frames_decoded;
  frames["width"] = selected.width;
  frames["height"] = selected.height;
  nlohmann::json list = nlohmann::json::array();
  for (int i : selected.picked) {
    const FrameScore& score = selected.scores[i];
    list.push_back({{"frame", score.index},
                    {"image", VideoFrameName(score.index)},
                    {"sharpness", score.sharpness}});
  }
  frames["selected"] = list;
  frames["matcher"] = report.matcher;
  frames["registered"] = report.registered;
  frames["reprojection_error_px"] = report.reprojection_error;
  const std::string colmap_dir = JoinPath(opts.out, "colmap");
  SFT_RETURN_IF_ERROR(MakeDirectories(colmap_dir));
  SFT_RETURN_IF_ERROR(WriteTextFile(JoinPath(colmap_dir, "frames.json"), frames.dump(2) + "\n"));
  std::error_code ec;
  fs::copy_file(JoinPath(work, "log.txt"), JoinPath(colmap_dir, "log.txt"),
                fs::copy_options::overwrite_existing, ec);
  if (ec) return Status::Error(JoinPath(colmap_dir, "log.txt") + ": cannot write");
  return Status::Ok();
}

}  // namespace

bool VideoImportOptions::Check(std::string* why) const {
  if (video.empty()) {
    *why = "--video: required";
  } else if (out.empty()) {
    *why = "--out: required";
  } else if (!selection.Check(why)) {
    return false;
  } else if (!(min_registered >= 0 && min_registered <= 1)) {
    *why = "--min-registered: must be in [0, 1]";
  } else if (exhaustive_limit < 2 || exhaustive_limit > 10000) {
    *why = "--exhaustive-limit: must be in [2, 10000]";
  } else if (camera_model != "SIMPLE_PINHOLE" && camera_model != "PINHOLE" &&
             camera_model != "SIMPLE_RADIAL" && camera_model != "RADIAL" &&
             camera_model != "OPENCV") {
    *why = "--camera-model: must be SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL or OPENCV";
  } else if (!normalization.Check(why)) {
    return false;
  } else {
    return true;
  }
  return false;
}

std::vector<ColmapStage> PlanColmapStages(const VideoImportOptions& opts, const std::string& work,
                                          int frames) {
  const std::string database = JoinPath(work, "database.db");
  const std::string images = JoinPath(work, "frames");
  std::vector<ColmapStage> stages;
  stages.push_back(
      {"feature_extractor",
       {"--database_path", database, "--image_path", images, "--ImageReader.single_camera", "1",
        "--ImageReader.camera_model", opts.camera_model, "--SiftExtraction.use_gpu", "0"}});
  ColmapStage match{frames <= opts.exhaustive_limit ? "exhaustive_matcher" : "sequential_matcher",
                    {"--database_path", database, "--SiftMatching.use_gpu", "0"}};
  // COLMAP's default block of 50 images reports a single block for a small video, so the
  // progress line would not move.
  if (match.name == "exhaustive_matcher") {
    match.args.insert(match.args.end(), {"--ExhaustiveMatching.block_size", "10"});
  }
  stages.push_back(match);
  stages.push_back({"mapper",
                    {"--database_path", database, "--image_path", images, "--output_path",
                     JoinPath(work, "sparse")}});
  return stages;
}

Status CheckRegistered(int registered, int selected, bool has_model, double min_registered,
                       const std::string& log_path) {
  const double fraction = selected > 0 ? static_cast<double>(registered) / selected : 0.0;
  if (has_model && fraction >= min_registered) return Status::Ok();
  char text[512];
  std::snprintf(text, sizeof(text),
                "COLMAP registered %d of %d frames (%.0f%%, --min-registered %.0f%%); try a "
                "scene with more texture near the object, more frames (--frames), or slower "
                "camera motion (log: %s)",
                has_model ? registered : 0, selected, has_model ? 100 * fraction : 0.0,
                100 * min_registered, log_path.c_str());
  return Status::Error(text);
}

Status ImportVideo(const VideoImportOptions& opts, VideoImportReport* report) {
  const auto start = std::chrono::steady_clock::now();
  *report = VideoImportReport();
  const std::string work = opts.out + ".video-work";
  SFT_RETURN_IF_ERROR(CheckInputsAndOutputs(opts, work));
  // 1. Frames.
  SelectedFrames selected;
  SFT_RETURN_IF_ERROR(SelectAndWriteFrames(opts, work, &selected, report));
  // 2. COLMAP, then the --min-registered rule on its largest model.
  SFT_RETURN_IF_ERROR(RunColmap(opts, work, report->frames_selected, report));
  std::string model_dir;
  ColmapModel model;
  SFT_RETURN_IF_ERROR(LargestModel(JoinPath(work, "sparse"), &model_dir, &model, &report->models));
  report->registered = static_cast<int>(model.images.size());
  report->reprojection_error = MeanReprojectionError(model);
  SFT_RETURN_IF_ERROR(CheckRegistered(report->registered, report->frames_selected,
                                      !model_dir.empty(), opts.min_registered,
                                      JoinPath(work, "log.txt")));
  // 3. Import as `sft import colmap`, then the record of the selection and COLMAP's log.
  SFT_RETURN_IF_ERROR(ImportModel(opts, work, model_dir, report));
  SFT_RETURN_IF_ERROR(WriteFramesRecord(opts, work, selected, *report));
  std::error_code ec;
  fs::remove_all(work, ec);
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace sft
