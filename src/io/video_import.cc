#include "src/io/video_import.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"
#include "src/io/colmap_model.h"
#include "src/io/colmap_runner.h"

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
  const std::string log = JoinPath(work, "log.txt");
  const std::string database = JoinPath(work, "database.db");
  const std::string images = JoinPath(work, "frames");
  const bool progress = !opts.quiet;
  SFT_RETURN_IF_ERROR(RunColmapStage(
      opts.colmap, "feature_extractor",
      {"--database_path", database, "--image_path", images, "--ImageReader.single_camera", "1",
       "--ImageReader.camera_model", opts.camera_model, "--SiftExtraction.use_gpu", "0"},
      log, frames, progress, &report->seconds_features));
  report->matcher = frames <= opts.exhaustive_limit ? "exhaustive_matcher" : "sequential_matcher";
  // Exhaustive matching in blocks of 10 images (COLMAP's default 50 reports a single block for a
  // small video, so the progress line would not move).
  std::vector<std::string> match_args = {"--database_path", database, "--SiftMatching.use_gpu",
                                         "0"};
  if (report->matcher == "exhaustive_matcher") {
    match_args.insert(match_args.end(), {"--ExhaustiveMatching.block_size", "10"});
  }
  SFT_RETURN_IF_ERROR(RunColmapStage(opts.colmap, report->matcher, match_args, log, frames,
                                     progress, &report->seconds_matching));
  const std::string sparse = JoinPath(work, "sparse");
  SFT_RETURN_IF_ERROR(MakeDirectories(sparse));
  return RunColmapStage(
      opts.colmap, "mapper",
      {"--database_path", database, "--image_path", images, "--output_path", sparse}, log, frames,
      progress, &report->seconds_mapping);
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

Status ImportVideo(const VideoImportOptions& opts, VideoImportReport* report) {
  const auto start = std::chrono::steady_clock::now();
  *report = VideoImportReport();
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
  const std::string work = opts.out + ".video-work";
  const RunInputs inputs{{mask_folder ? opts.masks : std::string()}, {opts.video, opts.probe}};
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(opts.out, inputs, "--out"));
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(work, inputs, "--out (OUT.video-work)"));
  if (fs::exists(opts.out, ec) && !fs::is_empty(opts.out, ec) && !opts.overwrite) {
    return Status::Error(opts.out + ": output exists and is not empty (use --overwrite)");
  }

  // 1. Frames.
  auto t0 = std::chrono::steady_clock::now();
  std::vector<FrameScore> scores;
  int width = 0, height = 0;
  SFT_RETURN_IF_ERROR(ScoreVideoFrames(opts.video, &scores, &width, &height, !opts.quiet));
  report->frames_decoded = static_cast<int>(scores.size());
  const std::vector<int> picked = SelectFrames(scores, opts.selection);
  if (picked.size() < 2) {
    return Status::Error("--video: " + opts.video + ": fewer than 2 distinct frames (" +
                         std::to_string(scores.size()) + " decoded)");
  }
  std::vector<int> frame_numbers;
  for (int i : picked) frame_numbers.push_back(scores[i].index);
  report->frames_selected = static_cast<int>(frame_numbers.size());
  fs::remove_all(work, ec);
  SFT_RETURN_IF_ERROR(MakeDirectories(work));
  std::vector<std::string> names;
  SFT_RETURN_IF_ERROR(
      WriteVideoFrames(opts.video, frame_numbers, JoinPath(work, "frames"), &names));
  report->seconds_frames =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // 2. COLMAP.
  SFT_RETURN_IF_ERROR(RunColmap(opts, work, report->frames_selected, report));
  std::string model_dir;
  ColmapModel model;
  SFT_RETURN_IF_ERROR(LargestModel(JoinPath(work, "sparse"), &model_dir, &model, &report->models));
  report->registered = static_cast<int>(model.images.size());
  report->reprojection_error = MeanReprojectionError(model);
  const double fraction = static_cast<double>(report->registered) / report->frames_selected;
  if (model_dir.empty() || fraction < opts.min_registered) {
    char text[512];
    std::snprintf(text, sizeof(text),
                  "COLMAP registered %d of %d frames (%.0f%%, --min-registered %.0f%%); try a "
                  "scene with more texture near the object, more frames (--frames), or slower "
                  "camera motion (log: %s)",
                  report->registered, report->frames_selected, 100 * fraction,
                  100 * opts.min_registered, JoinPath(work, "log.txt").c_str());
    return Status::Error(text);
  }

  // 3. Import as `sft import colmap`.
  ColmapImportOptions import;
  import.model = model_dir;
  import.images = JoinPath(work, "frames");
  import.masks = opts.masks;
  import.probe = opts.probe;
  import.out = opts.out;
  import.normalization = opts.normalization;
  import.import_dense = false;
  import.overwrite = opts.overwrite;
  import.quiet = opts.quiet;
  SFT_RETURN_IF_ERROR(ImportColmap(import, &report->import));

  nlohmann::json frames = nlohmann::json::object();
  frames["video"] = opts.video;
  frames["frames_decoded"] = report->frames_decoded;
  frames["width"] = width;
  frames["height"] = height;
  nlohmann::json list = nlohmann::json::array();
  for (int i : picked) {
    list.push_back({{"frame", scores[i].index},
                    {"image", VideoFrameName(scores[i].index)},
                    {"sharpness", scores[i].sharpness}});
  }
  frames["selected"] = list;
  frames["matcher"] = report->matcher;
  frames["registered"] = report->registered;
  frames["reprojection_error_px"] = report->reprojection_error;
  const std::string colmap_dir = JoinPath(opts.out, "colmap");
  SFT_RETURN_IF_ERROR(MakeDirectories(colmap_dir));
  SFT_RETURN_IF_ERROR(WriteTextFile(JoinPath(colmap_dir, "frames.json"), frames.dump(2) + "\n"));
  fs::copy_file(JoinPath(work, "log.txt"), JoinPath(colmap_dir, "log.txt"),
                fs::copy_options::overwrite_existing, ec);
  if (ec) return Status::Error(JoinPath(colmap_dir, "log.txt") + ": cannot write");
  fs::remove_all(work, ec);
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace sft
