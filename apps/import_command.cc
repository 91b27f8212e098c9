// sft import: brings captures into the sft-dataset/1 format. `sft import colmap` converts a COLMAP
// sparse model and its images (src/capture/colmap_import.h); `sft import video` selects frames of a
// video and runs COLMAP on them first (src/capture/video_import.h); `nerf`, `idr` and `middlebury`
// are in import_calibrated_command.cc. Decisions in docs/import.md.
#include <cstdio>
#include <memory>

#include "apps/commands.h"
#include "src/capture/colmap_import.h"
#include "src/capture/video_import.h"

namespace sft {
namespace {

// The --masks auto and --probe lines of a summary (nothing when neither ran).
void PrintMasksAndProbe(const char* command, const ColmapImportReport& report) {
  const NormalizationResult& n = report.normalization;
  if (n.plane.found) {
    std::fprintf(stderr, "%s: support plane: %d sparse points on or beyond it left out\n", command,
                 n.plane.off_object);
  }
  if (report.probe_ground_requested && report.probe_ground && report.probe_ground_radius > 0) {
    std::fprintf(stderr,
                 "%s: probe ground: the support, a disc of radius %.2f object diagonals on the "
                 "plane, hides the probe where it blocks the view\n",
                 command, report.probe_ground_radius);
  } else if (report.probe_ground_requested) {
    std::fprintf(stderr, "%s: %s\n", command,
                 report.probe_ground
                     ? "probe ground: the support plane hides the probe below its horizon"
                     : "probe ground: no support plane found, the probe is not hidden");
  }
  if (report.auto_masks > 0) {
    std::fprintf(stderr, "%s: %d automatic masks (GrabCut) in masks/\n", command,
                 report.auto_masks);
  }
  if (report.probe_aligned) {
    const ProbeAlignmentResult& a = report.alignment;
    std::fprintf(stderr,
                 "%s: probe aligned: rotation %.2f deg; %d inliers of %d matches; median "
                 "residual %.3f deg\n",
                 command, a.rotation_angle_deg, a.inliers, a.matches, a.median_residual_deg);
  }
}

int RunImportColmap(const ColmapImportOptions& opts) {
  ColmapImportReport report;
  const Status status = ImportColmap(opts, &report);
  if (!status.ok()) return PrintError("import colmap", status);
  if (!opts.quiet) {
    const NormalizationResult& n = report.normalization;
    std::fprintf(
        stderr,
        "sft import colmap: %d views, %d cameras (%s model); normalised by %s on %d of "
        "%d sparse points (box diagonal %.6g); %s%s%.2f s\n",
        report.views, report.cameras, report.format.c_str(), n.method.c_str(), n.points_used,
        n.points_total, n.diagonal,
        report.dense_mesh.empty() ? "" : ("initial mesh from " + report.dense_mesh + "; ").c_str(),
        report.dense_points.empty() ? ""
                                    : ("dense points from " + report.dense_points + "; ").c_str(),
        report.seconds);
    PrintMasksAndProbe("sft import colmap", report);
  }
  return 0;
}

int RunImportVideo(const VideoImportOptions& opts) {
  VideoImportReport report;
  const Status status = ImportVideo(opts, &report);
  if (!status.ok()) return PrintError("import video", status);
  if (!opts.quiet) {
    std::fprintf(stderr,
                 "sft import video: %d of %d decoded frames selected; COLMAP registered %d (%s, "
                 "%d model(s), mean reprojection error %.3f px); frames %.1f s, features %.1f s, "
                 "matching %.1f s, mapping %.1f s; total %.1f s\n",
                 report.frames_selected, report.frames_decoded, report.registered,
                 report.matcher.c_str(), report.models, report.reprojection_error,
                 report.seconds_frames, report.seconds_features, report.seconds_matching,
                 report.seconds_mapping, report.seconds);
    PrintMasksAndProbe("sft import video", report.import);
  }
  return 0;
}

// --no-support-plane and --plane-distance (src/capture/support_plane.h), for both imports.
void AddSupportPlaneFlags(CLI::App* app, SupportPlaneOptions* plane) {
  app->add_flag("!--no-support-plane", plane->enabled,
                "Without masks: keep the points of a dominant plane (table top, floor) as "
                "object candidates instead of leaving them out");
  app->add_option("--plane-distance", plane->distance,
                  "Support plane band half-width, as a fraction of the median viewing distance, "
                  "(0, 0.2]")
      ->capture_default_str();
  app->add_flag("--probe-ground", plane->hides_probe,
                "With --probe: the support plane, when found, hides the probe below its horizon "
                "(a floor the probe does not show, e.g. a studio or sky panorama taken elsewhere)");
}

// --background-distance (src/capture/auto_masks.h), for both imports.
void AddAutoMaskFlags(CLI::App* app, AutoMaskOptions* masks) {
  app->add_option("--background-distance", masks->background_distance,
                  "With --masks auto: a pixel whose colour differs from what the other views see "
                  "of the background behind it (the support plane, or far away) by less than "
                  "this (display values, [0, 1]) is background; 0 = GrabCut seeded by the sparse "
                  "points alone")
      ->capture_default_str();
}

void SetupImportVideo(CLI::App* video, VideoImportOptions* opts) {
  video->add_option("--video", opts->video, "Input video (any format OpenCV decodes)")->required();
  video->add_option("--out", opts->out, "Output dataset folder")->required();
  video->add_option("--frames", opts->selection.frames, "Frames to select (sharpest per segment)")
      ->capture_default_str();
  video
      ->add_option("--duplicate-threshold", opts->selection.duplicate_threshold,
                   "Mean 32x32 thumbnail difference below which a frame is a near-duplicate")
      ->capture_default_str();
  video->add_option("--probe", opts->probe,
                    "Equirectangular probe (.exr/.hdr linear, or an 8-bit sRGB panorama), added "
                    "as an environment light and aligned to the frames as by `import colmap`");
  video->add_option("--masks", opts->masks,
                    "Folder of masks named like the frames (frame_NNNNNN.png), or auto (GrabCut)");
  video
      ->add_option("--min-registered", opts->min_registered,
                   "Fraction of the selected frames COLMAP must register")
      ->capture_default_str();
  video
      ->add_option("--exhaustive-limit", opts->exhaustive_limit,
                   "Exhaustive matching up to this many frames, sequential beyond")
      ->capture_default_str();
  video->add_option("--camera-model", opts->camera_model, "Shared COLMAP camera model")
      ->capture_default_str();
  video->add_option("--colmap", opts->colmap, "COLMAP executable")->capture_default_str();
  AddSupportPlaneFlags(video, &opts->normalization.plane);
  AddAutoMaskFlags(video, &opts->auto_masks);
  video->add_flag("--overwrite", opts->overwrite, "Replace an existing output folder");
  video->add_flag("--quiet", opts->quiet, "No progress or summary line");
}

}  // namespace

CommandRunner SetupImportCommand(CLI::App* app) {
  app->require_subcommand(1);
  CLI::App* colmap = app->add_subcommand(
      "colmap", "Convert a COLMAP sparse model (binary or text) and its images into a dataset");
  auto opts = std::make_shared<ColmapImportOptions>();
  colmap
      ->add_option("--model", opts->model,
                   "COLMAP sparse model folder (cameras, images, points3D as .bin or .txt)")
      ->required();
  colmap->add_option("--images", opts->images, "Folder the model's image names are relative to")
      ->required();
  colmap->add_option("--masks", opts->masks,
                     "Mask folder: NAME.png (COLMAP's convention) or STEM.png per image, > 127 = "
                     "object; or 'auto' (GrabCut seeded by the sparse points near the object)");
  colmap->add_option("--probe", opts->probe,
                     "Equirectangular probe (.exr/.hdr linear, or an 8-bit sRGB panorama), added "
                     "as an environment light, rotated into the world frame by matching its crops "
                     "against the frames' background (see --no-align-probe)");
  colmap->add_flag("!--no-align-probe", opts->align_probe,
                   "Keep the probe unaligned (world_from_env = identity)");
  colmap->add_option("--out", opts->out, "Output dataset folder")->required();
  colmap
      ->add_option("--axis-cone", opts->normalization.axis_cone,
                   "Without masks: cone around each optical axis, as a fraction of the "
                   "half-image, (0, 1]")
      ->capture_default_str();
  colmap
      ->add_option("--percentile", opts->normalization.percentile,
                   "Without masks: robust bounding-box percentile per axis, [0, 50)")
      ->capture_default_str();
  AddSupportPlaneFlags(colmap, &opts->normalization.plane);
  AddAutoMaskFlags(colmap, &opts->auto_masks);
  colmap->add_flag("!--no-dense", opts->import_dense,
                   "Ignore fused.ply / meshed-*.ply beside the model");
  colmap->add_flag("--overwrite", opts->overwrite, "Replace an existing output folder");
  colmap->add_flag("--quiet", opts->quiet, "No progress or summary line");
  CLI::App* video = app->add_subcommand(
      "video", "Select frames of a video, run COLMAP (CPU) on them and import the result");
  auto video_opts = std::make_shared<VideoImportOptions>();
  SetupImportVideo(video, video_opts.get());
  CommandRunner calibrated = AddCalibratedImportCommands(app);
  return [opts, colmap, video_opts, video, calibrated]() {
    if (colmap->parsed()) return RunImportColmap(*opts);
    if (video->parsed()) return RunImportVideo(*video_opts);
    const int code = calibrated();
    return code >= 0 ? code : 2;
  };
}

}  // namespace sft
