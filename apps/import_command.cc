// sft import: brings captures into the sft-dataset/1 format. `sft import colmap` converts a COLMAP
// sparse model and its images (src/io/colmap_import.h; decisions in docs/import.md).
#include <cstdio>
#include <memory>

#include "apps/commands.h"
#include "src/io/colmap_import.h"

namespace sft {
namespace {

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
    if (report.auto_masks > 0) {
      std::fprintf(stderr, "sft import colmap: %d automatic masks (GrabCut) in masks/\n",
                   report.auto_masks);
    }
    if (report.probe_aligned) {
      const ProbeAlignmentResult& a = report.alignment;
      std::fprintf(stderr,
                   "sft import colmap: probe aligned: rotation %.2f deg; %d inliers of %d "
                   "matches; median residual %.3f deg\n",
                   a.rotation_angle_deg, a.inliers, a.matches, a.median_residual_deg);
    }
  }
  return 0;
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
  colmap->add_flag("!--no-dense", opts->import_dense,
                   "Ignore fused.ply / meshed-*.ply beside the model");
  colmap->add_flag("--overwrite", opts->overwrite, "Replace an existing output folder");
  colmap->add_flag("--quiet", opts->quiet, "No progress or summary line");
  return [opts, colmap]() {
    if (colmap->parsed()) return RunImportColmap(*opts);
    return 2;
  };
}

}  // namespace sft
