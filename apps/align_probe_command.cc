// sft align-probe: finds the rotation of a dataset's environment light (a 360° probe) from the
// frames' background (src/capture/probe_alignment.h) and writes a copy of the dataset with it
// stored as the light's world_from_env. `sft import colmap --probe` runs the same alignment itself;
// this command is for datasets imported with --no-align-probe or made elsewhere. Decisions in
// docs/import.md "Probe alignment".
#include <cstdio>
#include <filesystem>
#include <memory>

#include "apps/commands.h"
#include "src/capture/probe_alignment.h"
#include "src/core/file_util.h"
#include "src/io/dataset.h"

namespace sft {
namespace {

namespace fs = std::filesystem;

struct AlignProbeCommandOptions {
  std::string dataset;          // input dataset folder (read only).
  std::string out;              // output dataset folder (a copy with the aligned light).
  std::string light;            // environment light id; empty = the first environment light.
  ProbeAlignmentOptions align;  // alignment settings.
  bool overwrite = false;       // replace an existing, non-empty output folder.
};

Status FindLight(const Dataset& dataset, const std::string& id, int* index) {
  for (size_t i = 0; i < dataset.lights.size(); ++i) {
    const LightSpec& light = dataset.lights[i];
    if (light.type == LightType::kEnvironment && (id.empty() || light.id == id)) {
      *index = static_cast<int>(i);
      return Status::Ok();
    }
  }
  return Status::Error(JoinPath(dataset.root, "scene.json") + ": no environment light" +
                       (id.empty() ? std::string() : " with id \"" + id + "\""));
}

// Copies the dataset to OUT.partial, stores the rotation there, renames to OUT.
Status AlignInto(const AlignProbeCommandOptions& opts, ProbeAlignmentResult* result) {
  const RunInputs inputs{{opts.dataset}, {}};
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(opts.out, inputs, "--out"));
  const std::string partial = opts.out + ".partial";
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(partial, inputs, "--out (OUT.partial)"));
  std::error_code ec;
  if (fs::exists(opts.out, ec) && !fs::is_empty(opts.out, ec) && !opts.overwrite) {
    return Status::Error(opts.out + ": output exists and is not empty (use --overwrite)");
  }
  Dataset dataset;
  SFT_RETURN_IF_ERROR(ReadDataset(opts.dataset, &dataset));
  int light = -1;
  SFT_RETURN_IF_ERROR(FindLight(dataset, opts.light, &light));
  SFT_RETURN_IF_ERROR(AlignProbe(dataset, light, opts.align, result));
  dataset.lights[light].world_from_env = result->world_from_env;
  dataset.lighting = AlignedProbeLighting(*result);
  fs::remove_all(partial, ec);
  fs::copy(opts.dataset, partial, fs::copy_options::recursive, ec);
  Status status = ec ? Status::Error(partial + ": cannot copy the dataset (" + ec.message() + ")")
                     : WriteSceneJson(dataset, partial);
  if (status.ok()) {
    if (fs::exists(opts.out, ec)) fs::remove_all(opts.out, ec);
    fs::rename(partial, opts.out, ec);
    if (ec)
      status =
          Status::Error(opts.out + ": cannot move the dataset in place (" + ec.message() + ")");
  }
  if (!status.ok()) fs::remove_all(partial, ec);
  return status;
}

int RunAlignProbe(const AlignProbeCommandOptions& opts) {
  ProbeAlignmentResult result;
  const Status status = AlignInto(opts, &result);
  if (!status.ok()) return PrintError("align-probe", status);
  if (!opts.align.quiet) {
    std::fprintf(stderr,
                 "sft align-probe: rotation %.2f deg; %d inliers of %d matches (%d views, %d "
                 "crops); median residual %.3f deg\n",
                 result.rotation_angle_deg, result.inliers, result.matches, result.views_used,
                 result.crops, result.median_residual_deg);
  }
  return 0;
}

}  // namespace

CommandRunner SetupAlignProbeCommand(CLI::App* app) {
  auto opts = std::make_shared<AlignProbeCommandOptions>();
  app->add_option("--dataset", opts->dataset, "Dataset with an environment light (read only)")
      ->required();
  app->add_option("--out", opts->out, "Output dataset folder (a copy with the aligned probe)")
      ->required();
  app->add_option("--light", opts->light, "Environment light id (default: the first one)");
  app->add_option("--max-views", opts->align.max_views, "Frames used, evenly spaced, [1, 10000]")
      ->capture_default_str();
  app->add_option("--crops", opts->align.crops, "Probe crops (0 = cover the sphere), [6, 500]")
      ->capture_default_str();
  app->add_option("--crop-fov", opts->align.crop_fov_deg,
                  "Crop field of view in degrees (0 = the cameras' mean), [20, 120]")
      ->capture_default_str();
  app->add_option("--ratio", opts->align.ratio, "Lowe ratio test threshold, (0, 1]")
      ->capture_default_str();
  app->add_option("--inlier-angle", opts->align.inlier_angle_deg,
                  "RANSAC inlier threshold in degrees, (0, 20]")
      ->capture_default_str();
  app->add_option("--min-inliers", opts->align.min_inliers,
                  "Fewer consistent matches is an error, >= 3")
      ->capture_default_str();
  app->add_flag("--overwrite", opts->overwrite, "Replace an existing output folder");
  app->add_flag("--quiet", opts->align.quiet, "No progress or summary line");
  return [opts]() { return RunAlignProbe(*opts); };
}

}  // namespace sft
