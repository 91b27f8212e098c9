// sft eval: accuracy of a reconstruction against ground truth, printed as JSON on stdout (and
// written to --json when given).
//
// Modes, chosen by the options present:
//   mesh   --reference GT --mesh M [--tolerance 0.01] [--samples N] [--seed S]
//          F1 at the tolerance, precision, recall and the Chamfer distance in units of the
//          reference's bounding-box diagonal (src/eval/mesh_metrics.h).
//   reconstruction   --dataset D --reconstruction O [--spp 64] [--bounces 2] [--views ...]
//          [--mesh M] [--material SPEC] [--relight SPEC ...] [--out DIR] [--held-out]
//          PSNR and SSIM of re-renders of O against D's images and true albedo/roughness
//          (src/eval/reconstruction_eval.h); with --relight, of O against D's true object under
//          other lights (src/eval/relight_eval.h), the renders written under --out.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/eval/mesh_metrics.h"
#include "src/eval/reconstruction_eval.h"
#include "src/geometry/mesh.h"

namespace sft {
namespace {

// Options of the mesh mode.
struct MeshEvalOptions {
  std::string reference;       // ground-truth mesh (OBJ, PLY, OFF).
  std::string mesh;            // mesh to evaluate (OBJ, PLY, OFF).
  MeshMetricsOptions metrics;  // tolerance, samples, seed.
};

struct EvalCommandOptions {
  MeshEvalOptions mesh;
  std::string dataset;               // reconstruction mode: the dataset.
  std::string reconstruction;        // reconstruction mode: sft reconstruct's output folder.
  ReconstructionEvalOptions images;  // reconstruction mode: re-render settings.
  std::string json;                  // optional copy of the printed JSON.
};

// The files the reconstruction mode reads (for the --json and --out location checks).
RunInputs ReconstructionInputs(const EvalCommandOptions& opts) {
  RunInputs inputs{{opts.dataset, opts.reconstruction},
                   {opts.mesh.mesh, opts.images.true_environment}};
  // An inline JSON material is no file.
  if (!opts.images.material.empty() && opts.images.material.front() != '{') {
    inputs.files.push_back(opts.images.material);
  }
  for (const std::string& spec : opts.images.relight) {
    if (spec == "side") continue;
    const std::string probe = "probe:";
    inputs.files.push_back(spec.rfind(probe, 0) == 0 ? spec.substr(probe.size()) : spec);
  }
  return inputs;
}

Status RunMeshEval(const MeshEvalOptions& opts, nlohmann::json* report) {
  std::string why;
  if (!opts.metrics.Check(&why)) return Status::Error("--" + why);
  TriMesh reference, mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(opts.reference, &reference));
  SFT_RETURN_IF_ERROR(ReadMesh(opts.mesh, &mesh));
  MeshMetrics m;
  SFT_RETURN_IF_ERROR(
      ComputeMeshMetrics(reference, mesh, opts.metrics, &m, opts.reference, opts.mesh));
  *report = {
      {"mode", "mesh"},
      {"reference", opts.reference},
      {"mesh", opts.mesh},
      {"units", "fraction of the reference's bounding-box diagonal"},
      {"reference_diagonal", m.reference_diagonal},
      {"tolerance", m.tolerance},
      {"precision", m.precision},
      {"recall", m.recall},
      {"f1", m.f1},
      {"chamfer", m.chamfer},
      {"chamfer_definition",
       "(mean_mesh_to_reference + mean_reference_to_mesh) / 2, unsquared point-to-surface "
       "distances"},
      {"mean_mesh_to_reference", m.mean_mesh_to_reference},
      {"mean_reference_to_mesh", m.mean_reference_to_mesh},
      {"samples", m.samples},
      {"seed", opts.metrics.seed},
  };
  return Status::Ok();
}

int RunEvalCommand(const EvalCommandOptions& opts) {
  const bool images = !opts.dataset.empty() || !opts.reconstruction.empty();
  if (images && (opts.dataset.empty() || opts.reconstruction.empty())) {
    return PrintError("eval", Status::Error("--dataset and --reconstruction go together"));
  }
  if (!images && (opts.mesh.reference.empty() || opts.mesh.mesh.empty())) {
    return PrintError("eval", Status::Error("--reference and --mesh are both required (or "
                                            "--dataset and --reconstruction)"));
  }
  if (!images && (!opts.images.relight.empty() || !opts.images.out.empty() ||
                  !opts.images.material.empty() || opts.images.held_out)) {
    return PrintError("eval", Status::Error("--relight, --out, --material and --held-out need "
                                            "--dataset and --reconstruction"));
  }
  if (images && !opts.images.out.empty() && opts.images.relight.empty()) {
    return PrintError("eval", Status::Error("--out holds the --relight renders: give --relight"));
  }
  RunInputs inputs = ReconstructionInputs(opts);
  inputs.files.push_back(opts.mesh.reference);
  if (!opts.json.empty()) {
    const Status where = CheckOutputFile(opts.json, inputs, "--json");
    if (!where.ok()) return PrintError("eval", where);
  }
  if (!opts.images.out.empty()) {
    const Status where = CheckOutputDirectory(opts.images.out, inputs, "--out");
    if (!where.ok()) return PrintError("eval", where);
  }
  nlohmann::json report;
  ReconstructionEvalOptions image_options = opts.images;
  image_options.mesh = opts.mesh.mesh;  // --mesh: in this mode, the mesh to render.
  Status status =
      images ? EvaluateReconstruction(opts.dataset, opts.reconstruction, image_options, &report)
             : RunMeshEval(opts.mesh, &report);
  if (!status.ok()) return PrintError("eval", status);
  const std::string text = report.dump(1) + "\n";
  if (!opts.json.empty()) {
    status = WriteTextFile(opts.json, text);
    if (!status.ok()) return PrintError("eval", status.Prefixed("--json"));
  }
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace

CommandRunner SetupEvalCommand(CLI::App* app) {
  auto opts = std::make_shared<EvalCommandOptions>();
  app->add_option("--reference", opts->mesh.reference, "Ground-truth mesh (OBJ, PLY, OFF)");
  app->add_option("--mesh", opts->mesh.mesh,
                  "Mesh to evaluate (OBJ, PLY, OFF); reconstruction mode: render it instead of "
                  "O/mesh.ply (e.g. an export's model.obj)");
  app->add_option("--tolerance", opts->mesh.metrics.tolerance,
                  "F1 distance threshold, fraction of the reference's bounding-box diagonal, "
                  "(0, 1]")
      ->capture_default_str();
  app->add_option("--samples", opts->mesh.metrics.samples,
                  "Surface samples per mesh, [" + std::to_string(MeshMetricsOptions::kMinSamples) +
                      ", " + std::to_string(MeshMetricsOptions::kMaxSamples) + "]")
      ->capture_default_str();
  app->add_option("--seed", opts->mesh.metrics.seed, "Sampling seed")->capture_default_str();
  app->add_option("--dataset", opts->dataset, "Reconstruction mode: the dataset");
  app->add_option("--reconstruction", opts->reconstruction,
                  "Reconstruction mode: the output folder of sft reconstruct");
  app->add_option("--spp", opts->images.spp, "Reconstruction mode: samples per pixel")
      ->capture_default_str();
  app->add_option("--bounces", opts->images.bounces, "Reconstruction mode: path segments")
      ->capture_default_str();
  app->add_option("--views", opts->images.views, "Reconstruction mode: only these views")
      ->delimiter(',');
  app->add_flag("--held-out", opts->images.held_out,
                "Reconstruction mode: score the views sft reconstruct --holdout kept out of the "
                "fit (after the median fitted exposure gain, and after a per-view gain fit)");
  app->add_option("--material", opts->images.material,
                  "Reconstruction mode: material instead of O/material.json (JSON file, inline "
                  "JSON or an export's model.mtl)");
  app->add_option("--relight", opts->images.relight,
                  "Reconstruction mode: also score O against the dataset's true object under "
                  "these lights: LIGHTS.json (scene.json's light format, one condition per "
                  "light), probe:PATH.exr, or side (capture point lights turned 90 degrees); "
                  "repeatable")
      ->expected(1)
      ->take_all();
  app->add_option("--true-environment", opts->images.true_environment,
                  "Reconstruction mode, estimated lighting: the true environment (EXR, world "
                  "frame); reports the fitted map's relative error after the albedo's gauge");
  app->add_option("--out", opts->images.out,
                  "Reconstruction mode: write the --relight renders under DIR/relight/");
  app->add_option("--json", opts->json, "Also write the JSON to this file");
  return [opts]() { return RunEvalCommand(*opts); };
}

}  // namespace sft
