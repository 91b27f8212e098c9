// sft gradcheck: compares the renderer's analytic derivatives with central finite differences of
// the expected image for one parameter kind (see src/eval/gradcheck.h). Exit 0 when the overall
// relative error is within --tolerance (and the adjoint gradient agrees with the Jacobian rows),
// 1 otherwise or on bad input.
#include <cstdio>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/eval/gradcheck.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"

namespace sft {
namespace {

// The command-line values of `sft gradcheck`; validated by GradcheckOptions::Check and the
// loaders.
struct GradcheckCommandOptions {
  std::string dataset;          // dataset directory: cameras, lights, views.
  std::string mesh;             // mesh (OBJ, PLY, OFF).
  std::string material;         // material JSON file or inline JSON; "" = default material.
  std::string param;            // vertices | albedo | roughness | specular | light.
  std::string effects = "all";  // enabled effects (Effects::Parse).
  std::string json;             // optional JSON report path.
  GradcheckOptions check;       // spp, bounces, views, step, tolerance, seeds.
};

int RunGradcheckCommand(const GradcheckCommandOptions& opts) {
  GradcheckOptions check = opts.check;
  if (!ParameterKindFromName(opts.param, &check.kind)) {
    return PrintError("gradcheck", Status::Error("--param: unknown parameter kind '" + opts.param +
                                                 "' (vertices, albedo, roughness, specular, "
                                                 "light)"));
  }
  std::string why;
  if (!Effects::Parse(opts.effects, &check.render.effects, &why)) {
    return PrintError("gradcheck", Status::Error("--" + why));
  }
  if (!check.Check(&why)) return PrintError("gradcheck", Status::Error("--" + why));
  Dataset dataset;
  Status status = ReadDataset(opts.dataset, &dataset);
  if (!status.ok()) return PrintError("gradcheck", status);
  TriMesh mesh;
  status = ReadMesh(opts.mesh, &mesh);
  if (!status.ok()) return PrintError("gradcheck", status);
  Material material;
  status = LoadMaterial(opts.material, mesh, &material);
  if (!status.ok()) return PrintError("gradcheck", status);
  GradcheckResult result;
  status = RunGradcheck(dataset, mesh, material, check, &result);
  if (!status.ok()) return PrintError("gradcheck", status);

  nlohmann::json report;
  report["param"] = result.kind;
  report["tolerance"] = check.tolerance;
  report["spp"] = check.render.spp;
  report["bounces"] = check.render.bounces;
  report["effects"] = check.render.effects.ToString();
  nlohmann::json per_view = nlohmann::json::array();
  for (const GradcheckViewResult& v : result.views) {
    std::printf("view %3d: relative error %.3e  |fd| %.4g  adjoint mismatch %.1e  entries %zu\n",
                v.view, v.relative_error, v.fd_norm, v.adjoint_mismatch, v.jacobian_entries);
    per_view.push_back({{"view", v.view},
                        {"relative_error", v.relative_error},
                        {"fd_norm", v.fd_norm},
                        {"adjoint_mismatch", v.adjoint_mismatch},
                        {"jacobian_entries", v.jacobian_entries}});
  }
  report["views"] = per_view;
  report["relative_error"] = result.relative_error;
  report["passed"] = result.passed;
  std::printf("gradcheck %s: relative error %.3e over %zu views (tolerance %.3g): %s\n",
              result.kind.c_str(), result.relative_error, result.views.size(), check.tolerance,
              result.passed ? "PASS" : "FAIL");
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
  app->add_option("--param", opts->param,
                  "Parameter kind: vertices | albedo | roughness | specular | light")
      ->required();
  app->add_option("--spp", opts->check.render.spp, "Samples per pixel")->capture_default_str();
  app->add_option("--bounces", opts->check.render.bounces,
                  "Path segments: 1 = direct light only, 2 = one indirect bounce")
      ->capture_default_str();
  app->add_option("--effects", opts->effects, "Enabled effects (see sft render --help)")
      ->capture_default_str();
  app->add_option("--views", opts->check.views, "View indices (comma-separated; default all)")
      ->delimiter(',');
  app->add_option("--tolerance", opts->check.tolerance, "Maximum relative L2 error")
      ->capture_default_str();
  app->add_option("--step", opts->check.step,
                  "Finite-difference step (0 = automatic: 1e-3, roughness 1e-4·r)")
      ->capture_default_str();
  app->add_option("--seed", opts->check.render.seed, "Sample seed")->capture_default_str();
  app->add_option("--direction-seed", opts->check.direction_seed,
                  "Seed of the random perturbation direction")
      ->capture_default_str();
  app->add_option("--threads", opts->check.render.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
  app->add_option("--json", opts->json, "Write the results as JSON to this file");
  return [opts]() { return RunGradcheckCommand(*opts); };
}

}  // namespace sft
