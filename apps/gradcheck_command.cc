// sft gradcheck: compares the renderer's analytic derivatives with central finite differences of
// the expected image for one parameter kind (see src/eval/gradcheck.h). Exit 0 when the overall
// relative error is within --tolerance (and the adjoint gradient agrees with the Jacobian rows),
// 1 otherwise or on bad input. Vertices need many samples for the finite differences: e.g.
// `sft gradcheck --param vertices --spp 64`.
#include <cstdio>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/eval/derivative_consistency.h"
#include "src/eval/gradcheck.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"

namespace sft {
namespace {

// The command-line values of `sft gradcheck`; validated by GradcheckOptions::Check and the
// loaders.
struct GradcheckCommandOptions {
  std::string dataset;           // dataset directory: cameras, lights, views.
  std::string mesh;              // mesh (OBJ, PLY, OFF).
  std::string material;          // material JSON file or inline JSON; "" = default material.
  std::string param;             // a ParameterKindName but "environment".
  std::string effects = "all";   // enabled effects (Effects::Parse).
  std::string shading = "auto";  // "auto" (the dataset's, DatasetShading), "flat" or "smooth".
  std::string json;              // optional JSON report path.
  GradcheckOptions check;        // spp, bounces, views, step, block, tolerance, seeds.
  int consistency_seeds = 0;     // > 0: measure seed-to-seed consistency instead, [2, 64].
};

// --consistency-seeds: the derivative image at K seeds against itself
// (src/eval/derivative_consistency.h). Informative: exit 0 unless the input is bad.
int RunConsistency(const GradcheckCommandOptions& opts, const GradcheckOptions& check,
                   const Dataset& dataset, const TriMesh& mesh, const Material& material) {
  ConsistencyResult result;
  const Status status =
      MeasureDerivativeConsistency(dataset, mesh, material, check, opts.consistency_seeds, &result);
  if (!status.ok()) return PrintError("gradcheck", status);
  nlohmann::json per_view = nlohmann::json::array();
  for (const ConsistencyViewResult& v : result.views) {
    std::printf(
        "view %3d: seed-to-seed correlation %.3f per pixel, %.3f on %dx%d blocks; "
        "noise/signal %.3f\n",
        v.view, v.pixel_correlation, v.block_correlation, result.block, result.block,
        v.noise_to_signal);
    per_view.push_back({{"view", v.view},
                        {"pixel_correlation", v.pixel_correlation},
                        {"block_correlation", v.block_correlation},
                        {"noise_to_signal", v.noise_to_signal}});
  }
  std::printf(
      "consistency %s over %zu views, %d seeds at %d spp: correlation %.3f per pixel, "
      "%.3f on %dx%d blocks; noise/signal %.3f\n",
      opts.param.c_str(), result.views.size(), result.seeds, check.render.spp,
      result.pixel_correlation, result.block_correlation, result.block, result.block,
      result.noise_to_signal);
  if (opts.json.empty()) return 0;
  const nlohmann::json report = {{"param", opts.param},
                                 {"spp", check.render.spp},
                                 {"bounces", check.render.bounces},
                                 {"effects", check.render.effects.ToString()},
                                 {"seeds", result.seeds},
                                 {"block", result.block},
                                 {"views", per_view},
                                 {"pixel_correlation", result.pixel_correlation},
                                 {"block_correlation", result.block_correlation},
                                 {"noise_to_signal", result.noise_to_signal}};
  const Status written = WriteTextFile(opts.json, report.dump(1) + "\n");
  return written.ok() ? 0 : PrintError("gradcheck", written);
}

int RunGradcheckCommand(const GradcheckCommandOptions& opts) {
  GradcheckOptions check = opts.check;
  if (!ParameterKindFromName(opts.param, &check.kind) ||
      check.kind == ParameterKind::kEnvironment) {
    // A fitted environment exists in a fit only (its finite-difference test is in tests/render/).
    return PrintError("gradcheck", Status::Error("--param: unknown parameter kind '" + opts.param +
                                                 "' (vertices, albedo, roughness, specular, "
                                                 "light, light_position, light_direction, "
                                                 "environment_rotation)"));
  }
  std::string why;
  if (!Effects::Parse(opts.effects, &check.render.effects, &why)) {
    return PrintError("gradcheck", Status::Error("--" + why));
  }
  if (!check.Check(&why)) return PrintError("gradcheck", Status::Error("--" + why));
  const RunInputs inputs{{opts.dataset}, {opts.mesh, MaterialFile(opts.material)}};
  Status status = Status::Ok();
  if (!check.image_dir.empty()) status = CheckOutputDirectory(check.image_dir, inputs, "--images");
  if (status.ok() && !opts.json.empty()) status = CheckOutputFile(opts.json, inputs, "--json");
  if (!status.ok()) return PrintError("gradcheck", status);
  Dataset dataset;
  status = ReadDataset(opts.dataset, &dataset);
  if (!status.ok()) return PrintError("gradcheck", status);
  if (!ResolveShading(opts.shading, dataset, &check.render.shading)) {
    return PrintError("gradcheck", Status::Error("--shading: expected auto, flat or smooth, got '" +
                                                 opts.shading + "'"));
  }
  TriMesh mesh;
  status = ReadMesh(opts.mesh, &mesh);
  if (!status.ok()) return PrintError("gradcheck", status);
  Material material;
  status = LoadMaterial(opts.material, mesh, &material, MaterialUse::kRender);
  if (!status.ok()) return PrintError("gradcheck", status);
  if (opts.consistency_seeds > 0) return RunConsistency(opts, check, dataset, mesh, material);
  GradcheckResult result;
  status = RunGradcheck(dataset, mesh, material, check, &result);
  if (!status.ok()) return PrintError("gradcheck", status);

  // Vertices (or any explicit block > 1) add the block, pixel and projection errors to the
  // lines; other kinds keep the per-pixel lines.
  const bool blocks = check.kind == ParameterKind::kVertex || result.block > 1;
  nlohmann::json report;
  report["param"] = result.kind;
  report["tolerance"] = check.tolerance;
  report["spp"] = check.render.spp;
  report["bounces"] = check.render.bounces;
  report["effects"] = check.render.effects.ToString();
  report["shading"] = ShadingName(check.render.shading);
  report["step"] = result.step;
  report["block"] = result.block;
  nlohmann::json per_view = nlohmann::json::array();
  for (const GradcheckViewResult& v : result.views) {
    if (blocks) {
      std::printf(
          "view %3d: relative error %.3e (%dx%d blocks)  pixel %.3e  projections %.3e  |fd| %.4g  "
          "adjoint mismatch %.1e  entries %zu\n",
          v.view, v.relative_error, result.block, result.block, v.pixel_relative_error,
          v.projection_error, v.fd_norm, v.adjoint_mismatch, v.jacobian_entries);
    } else {
      std::printf("view %3d: relative error %.3e  |fd| %.4g  adjoint mismatch %.1e  entries %zu\n",
                  v.view, v.relative_error, v.fd_norm, v.adjoint_mismatch, v.jacobian_entries);
    }
    nlohmann::json projections = nlohmann::json::array();
    for (const GradcheckProjection& p : v.projections) {
      projections.push_back({{"weight", p.weight}, {"analytic", p.analytic}, {"fd", p.fd}});
    }
    per_view.push_back({{"view", v.view},
                        {"relative_error", v.relative_error},
                        {"pixel_relative_error", v.pixel_relative_error},
                        {"projection_error", v.projection_error},
                        {"projections", projections},
                        {"fd_norm", v.fd_norm},
                        {"adjoint_mismatch", v.adjoint_mismatch},
                        {"jacobian_entries", v.jacobian_entries},
                        {"nonfinite_samples", v.nonfinite_samples},
                        {"nonfinite_outputs", v.nonfinite_outputs}});
    if (v.nonfinite_samples > 0 || v.nonfinite_outputs > 0) {
      std::printf("view %3d: %lld samples dropped as not finite, %lld output values not finite\n",
                  v.view, static_cast<long long>(v.nonfinite_samples),
                  static_cast<long long>(v.nonfinite_outputs));
    }
  }
  report["views"] = per_view;
  report["relative_error"] = result.relative_error;
  report["pixel_relative_error"] = result.pixel_relative_error;
  report["projection_error"] = result.projection_error;
  report["passed"] = result.passed;
  report["nonfinite_samples"] = result.nonfinite_samples;
  report["nonfinite_outputs"] = result.nonfinite_outputs;
  if (blocks) {
    std::printf(
        "gradcheck %s: relative error %.3e on %dx%d blocks (pixels %.3e, projections %.3e) over "
        "%zu views (tolerance %.3g): %s\n",
        result.kind.c_str(), result.relative_error, result.block, result.block,
        result.pixel_relative_error, result.projection_error, result.views.size(), check.tolerance,
        result.passed ? "PASS" : "FAIL");
  } else {
    std::printf("gradcheck %s: relative error %.3e over %zu views (tolerance %.3g): %s\n",
                result.kind.c_str(), result.relative_error, result.views.size(), check.tolerance,
                result.passed ? "PASS" : "FAIL");
  }
  if (!opts.json.empty()) {
    status = WriteTextFile(opts.json, report.dump(1) + "\n");
    if (!status.ok()) return PrintError("gradcheck", status);
  }
  return result.passed ? 0 : 1;
}

}  // namespace

CommandRunner SetupGradcheckCommand(CLI::App* app) {
  auto opts = std::make_shared<GradcheckCommandOptions>();
  opts->check.render.spp = 4;
  opts->check.render.bounces = 2;
  app->add_option("--dataset", opts->dataset, "Dataset directory (cameras, lights, views)")
      ->required();
  app->add_option("--mesh", opts->mesh, "Mesh (OBJ, PLY, OFF)")->required();
  app->add_option("--material", opts->material, "Material JSON file or inline JSON");
  app->add_option(
         "--param", opts->param,
         "Parameter kind: vertices | albedo | roughness | specular | light | light_position | "
         "light_direction | environment_rotation")
      ->required();
  app->add_option("--spp", opts->check.render.spp,
                  "Samples per pixel (vertices: finite differences of moving edges need many: "
                  "64+ for Lambertian direct light, 1024+ with a glossy lobe or bounces)")
      ->capture_default_str();
  app->add_option("--bounces", opts->check.render.bounces,
                  "Path segments: 1 = direct light only, 2 = one indirect bounce")
      ->capture_default_str();
  app->add_option("--shading", opts->shading,
                  "auto (the dataset's ground_truth.shading, else smooth), flat or smooth")
      ->capture_default_str();
  app->add_option("--effects", opts->effects, "Enabled effects (see sft render --help)")
      ->capture_default_str();
  app->add_option("--views", opts->check.views, "View indices (comma-separated; default all)")
      ->delimiter(',');
  app->add_option("--tolerance", opts->check.tolerance,
                  "Maximum relative L2 error (of the block sums, see --block)")
      ->capture_default_str();
  app->add_option(
         "--step", opts->check.step,
         "Finite-difference step (0 = automatic: 1e-3, roughness 1e-4·r, vertices "
         "5e-3 × bounding-box diagonal along a displacement field of max length 1, shorter for "
         "glossy lobes)")
      ->capture_default_str();
  app->add_option("--block", opts->check.block,
                  "Compare sums over BxB pixel blocks (0 = automatic: 8 for vertices, whose edge "
                  "derivatives are Monte Carlo estimates at random pixels; 1 otherwise)")
      ->capture_default_str();
  app->add_option("--seed", opts->check.render.seed, "Sample seed")->capture_default_str();
  app->add_option("--direction-seed", opts->check.direction_seed,
                  "Seed of the random perturbation direction")
      ->capture_default_str();
  app->add_option("--threads", opts->check.render.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
  AddEdgeBudgetOptions(app, &opts->check.derivatives);
  app->add_option("--images", opts->check.image_dir,
                  "Write per-view analytic/finite-difference derivative images (EXR) and a "
                  "comparison PNG into this directory");
  app->add_option("--json", opts->json, "Write the results as JSON to this file");
  app->add_option("--consistency-seeds", opts->consistency_seeds,
                  "Instead of finite differences: render the derivative image at K seeds and "
                  "report how alike they are (correlation, noise/signal), [2, 64]; 0 = off")
      ->capture_default_str();
  return [opts]() { return RunGradcheckCommand(*opts); };
}

}  // namespace sft
