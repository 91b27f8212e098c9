// sft export: a reconstruction as files other programs open (docs/export.md).
//
//   sft export --reconstruction REC --out DIR [--format obj|gltf|ply|all] [--texture-size N]
//              [--dataset D] [--gutter 4] [--max-stretch 1.5] [--chart-angle 60]
//
// Writes DIR/model.obj + model.mtl + model_albedo.png + model_roughness.png (obj),
// DIR/model.glb (gltf), DIR/model.ply (ply) and DIR/export.json; prints export.json on stdout and
// each warning as one line on stderr.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/export/export.h"

namespace sft {
namespace {

int RunExportCommand(const ExportOptions& options) {
  nlohmann::json summary;
  const Status status = ExportReconstruction(options, &summary);
  if (!status.ok()) return PrintError("export", status);
  for (const auto& warning : summary["warnings"]) {
    std::fprintf(stderr, "sft export: warning: %s\n", warning.get<std::string>().c_str());
  }
  std::fputs((summary.dump(1) + "\n").c_str(), stdout);
  return 0;
}

}  // namespace

CommandRunner SetupExportCommand(CLI::App* app) {
  auto options = std::make_shared<ExportOptions>();
  app->add_option("--reconstruction", options->reconstruction,
                  "Output folder of sft reconstruct (mesh.ply, material.json); read only")
      ->required();
  app->add_option("--out", options->out, "Output folder (model.obj/.mtl/.glb/.ply, textures)")
      ->required();
  app->add_option("--format", options->format, "obj, gltf, ply or all")->capture_default_str();
  app->add_option("--texture-size", options->texture_size,
                  "Atlas side in texels, [64, 16384]; 0 = from the dataset's pixel footprint "
                  "(1024 without a dataset)")
      ->capture_default_str();
  app->add_option("--dataset", options->dataset,
                  "Dataset for the source frame and cameras (default: the one state.json names)");
  app->add_option("--gutter", options->atlas.gutter_texels,
                  "Texels between charts and to the atlas edge, [1, 64]")
      ->capture_default_str();
  app->add_option("--max-stretch", options->atlas.max_stretch,
                  "Charts with a larger L2 stretch are split, [1.01, 100]")
      ->capture_default_str();
  app->add_option("--chart-angle", options->atlas.charting.max_normal_angle_degrees,
                  "Largest angle between a face's normal and its chart's mean normal, degrees, "
                  "(0, 90]")
      ->capture_default_str();
  return [options]() { return RunExportCommand(*options); };
}

}  // namespace sft
