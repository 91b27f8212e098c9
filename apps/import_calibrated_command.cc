// sft import nerf | idr | middlebury: calibrated captures (cameras known, no sparse points) into
// the sft-dataset/1 format through src/capture/calibrated_import.h. Decisions in docs/import.md
// "Calibrated formats".
#include <cstdio>
#include <memory>

#include "apps/commands.h"
#include "src/capture/idr_import.h"
#include "src/capture/middlebury_import.h"
#include "src/capture/nerf_import.h"

namespace sft {
namespace {

// The flags every calibrated importer shares: output, masks, normalisation.
void AddCalibratedFlags(CLI::App* app, CalibratedImportOptions* opts, const char* masks_help) {
  app->add_option("--out", opts->out, "Output dataset folder")->required();
  app->add_option("--masks", opts->masks, masks_help);
  app->add_option("--threshold", opts->threshold.threshold,
                  "--masks threshold: brightest channel (stored values, 0..1) above this is "
                  "object, [0, 1)")
      ->capture_default_str();
  app->add_option("--dilate", opts->threshold.dilate,
                  "--masks threshold: dilation radius (pixels) after thresholding, [0, 1000]")
      ->capture_default_str();
  app->add_option("--erode", opts->threshold.erode,
                  "--masks threshold: erosion radius (pixels) after the dilation, [0, 1000]")
      ->capture_default_str();
  app->add_flag("!--no-fill-holes", opts->threshold.fill_holes,
                "--masks threshold: keep background regions enclosed by the object (holes)");
  app->add_option("--axis-cone", opts->box.axis_cone,
                  "Without masks (or a bounding sphere): the object is assumed to fill this "
                  "central fraction of the images, (0, 1]")
      ->capture_default_str();
  app->add_flag("--overwrite", opts->overwrite, "Replace an existing output folder");
  app->add_flag("--quiet", opts->quiet, "No progress or summary line (warnings still print)");
}

// The summary line and the warnings every calibrated import shares.
void PrintSummary(const char* command, const std::string& what, const CalibratedImportReport& r,
                  bool quiet) {
  if (r.empty_masks > 0) {
    std::fprintf(stderr,
                 "sft %s: warning: %d views left out: their mask has no object pixel (first: "
                 "%s)\n",
                 command, r.empty_masks, r.first_empty_mask.c_str());
  }
  if (r.box.touches_search_border) {
    std::fprintf(stderr,
                 "sft %s: warning: the masks' visual hull reaches the border of the search cube "
                 "(± the median camera distance); check the masks and the cameras\n",
                 command);
  }
  if (quiet) return;
  std::fprintf(stderr,
               "sft %s: %s; %d views, %d camera(s); masks: %s; object box from the %s: diagonal "
               "%.6g (source units); fill ratio %.2f x %.2f x %.2f (x, y, z) of the working box "
               "[-0.5, 0.5]^3; %.1f s\n",
               command, what.c_str(), r.views, r.cameras, r.masks.c_str(), r.box.method.c_str(),
               r.diagonal, r.fill.x(), r.fill.y(), r.fill.z(), r.seconds);
}

constexpr char kMasksByName[] =
    "Masks: a folder (NAME.png or STEM.png per image, > 127 = object), 'threshold' (brightness "
    "threshold, then dilate and erode) or 'alpha' (the images' alpha channel)";

}  // namespace

CommandRunner AddCalibratedImportCommands(CLI::App* import) {
  CLI::App* nerf = import->add_subcommand(
      "nerf",
      "Convert a NeRF transforms.json (Blender scenes, instant-ngp, nerfstudio) and its "
      "images into a dataset");
  auto nerf_opts = std::make_shared<NerfImportOptions>();
  nerf->add_option("--transforms", nerf_opts->transforms,
                   "transforms.json; frames' file_path relative to its folder")
      ->required();
  AddCalibratedFlags(nerf, &nerf_opts->import, kMasksByName);

  CLI::App* idr = import->add_subcommand(
      "idr",
      "Convert an IDR/NeuS dataset (cameras.npz: world_mat_i = K[R|t], scale_mat_i) "
      "into a dataset");
  auto idr_opts = std::make_shared<IdrImportOptions>();
  idr->add_option("--cameras", idr_opts->cameras, "cameras.npz (NumPy archive)")->required();
  idr->add_option("--images", idr_opts->images,
                  "Image folder; the i-th image in sorted order has world_mat_i (default: "
                  "CAMERAS_FOLDER/image)");
  AddCalibratedFlags(idr, &idr_opts->import,
                     "Masks: a folder paired with the images in sorted order (> 127 = object), "
                     "'threshold' or 'alpha'");

  CLI::App* middlebury = import->add_subcommand(
      "middlebury",
      "Convert a Middlebury multi-view set (X_par.txt: K, R, t per image) into a "
      "dataset");
  auto mb_opts = std::make_shared<MiddleburyImportOptions>();
  middlebury->add_option("--par", mb_opts->par, "The X_par.txt camera file")->required();
  middlebury->add_option("--images", mb_opts->images,
                         "Folder the image names are relative to (default: the par file's)");
  AddCalibratedFlags(middlebury, &mb_opts->import, kMasksByName);

  return [nerf, nerf_opts, idr, idr_opts, middlebury, mb_opts]() {
    if (nerf->parsed()) {
      NerfImportReport report;
      const Status status = ImportNerf(*nerf_opts, &report);
      if (!status.ok()) return PrintError("import nerf", status);
      PrintSummary("import nerf", std::to_string(report.frames) + " frames", report.import,
                   nerf_opts->import.quiet);
      return 0;
    }
    if (idr->parsed()) {
      IdrImportReport report;
      const Status status = ImportIdr(*idr_opts, &report);
      if (!status.ok()) return PrintError("import idr", status);
      PrintSummary("import idr",
                   std::to_string(report.cameras) + " cameras" +
                       (report.has_sphere ? " and a bounding sphere" : ""),
                   report.import, idr_opts->import.quiet);
      return 0;
    }
    if (middlebury->parsed()) {
      MiddleburyImportReport report;
      const Status status = ImportMiddlebury(*mb_opts, &report);
      if (!status.ok()) return PrintError("import middlebury", status);
      if (report.missing_images > 0) {
        std::fprintf(stderr,
                     "sft import middlebury: warning: %d of %d entries have no image file and "
                     "were skipped (first: %s)\n",
                     report.missing_images, report.entries, report.first_missing.c_str());
      }
      PrintSummary("import middlebury", std::to_string(report.entries) + " entries", report.import,
                   mb_opts->import.quiet);
      return 0;
    }
    return -1;
  };
}

}  // namespace sft
