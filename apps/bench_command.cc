// sft bench TARGET: throughput measurements. Targets are CLI11 sub-subcommands so that more can
// be added (e.g. `sft bench gradient`):
//   sft bench render   raw Embree rays/s (intersect1, intersect8, occluded1) on the renderer's own
//                      BVH and ray set vs RenderView's rays/s, and their ratio
//                      (src/eval/throughput.h).
//   sft bench gradient forward-only vs forward + Jacobian rows vs forward + adjoint gradient time
//                      over the views of one scene, and the rows' memory
//                      (src/eval/derivative_cost.h).
//   sft bench reconstruct  one outer iteration of sft reconstruct on a dataset, its time split
//                      (apps/bench_reconstruct_command.cc).
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/eval/derivative_cost.h"
#include "src/eval/throughput.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"

namespace sft {
namespace {

// The default mesh, relative to the working directory (the binary does not know the source tree).
constexpr char kDefaultBenchMesh[] = "data/meshes/bunny_watertight_5k.obj";

struct BenchRenderOptions {
  std::string mesh = kDefaultBenchMesh;  // mesh to trace (OBJ, PLY, OFF).
  std::string json;                      // optional JSON report path.
  ThroughputOptions throughput;          // resolution, spp, threads, repeats.
};

struct BenchGradientOptions {
  std::string mesh = kDefaultBenchMesh;  // mesh to render (OBJ, PLY, OFF).
  std::string dataset;                   // when set: its cameras, lights and views.
  std::string material;                  // with --dataset: JSON file or inline (default grey).
  std::vector<int> dataset_views;        // with --dataset: view indices; empty = all.
  std::string json;                      // optional JSON report path.
  bool quiet = false;                    // no progress lines.
  DerivativeCostOptions cost;            // views, resolution, spp, bounces, threads, keep_rows.
};

// The mesh of --mesh, with errors that name the option.
Status ReadBenchMesh(const std::string& path, TriMesh* mesh) {
  if (!FileExists(path)) {
    if (path == kDefaultBenchMesh) {
      return Status::Error("--mesh: default " + path +
                           " not found in the current directory (run from the source tree or "
                           "pass --mesh)");
    }
    return Status::Error("--mesh: " + path + " not found");
  }
  return ReadMesh(path, mesh);
}

Status RunBenchRender(const BenchRenderOptions& opts) {
  std::string why;
  if (!opts.throughput.Check(&why)) return Status::Error("--" + why);
  if (!opts.json.empty()) {
    SFT_RETURN_IF_ERROR(CheckOutputFile(opts.json, {{}, {opts.mesh}}, "--json"));
  }
  TriMesh mesh;
  SFT_RETURN_IF_ERROR(ReadBenchMesh(opts.mesh, &mesh));
  ThroughputReport report;
  SFT_RETURN_IF_ERROR(MeasureMeshThroughput(mesh, opts.throughput, &report));
  std::printf("sft bench render: %s\n%s", opts.mesh.c_str(), ThroughputReportTable(report).c_str());
  std::fflush(stdout);
  if (!opts.json.empty()) {
    nlohmann::json json = ThroughputReportToJson(report);
    json["mesh"] = opts.mesh;
    SFT_RETURN_IF_ERROR(WriteTextFile(opts.json, json.dump(1) + "\n"));
  }
  return Status::Ok();
}

Status RunBenchGradient(const BenchGradientOptions& opts) {
  std::string why;
  if (!opts.cost.Check(&why)) return Status::Error("--" + why);
  if (!opts.json.empty()) {
    const RunInputs inputs{{opts.dataset}, {opts.mesh, MaterialFile(opts.material)}};
    SFT_RETURN_IF_ERROR(CheckOutputFile(opts.json, inputs, "--json"));
  }
  if (opts.dataset.empty() && (!opts.material.empty() || !opts.dataset_views.empty())) {
    return Status::Error("--material and --dataset-views need --dataset");
  }
  DerivativeCostOptions cost = opts.cost;
  cost.progress = !opts.quiet;
  DerivativeCostReport report;
  TriMesh mesh;
  if (opts.dataset.empty()) {
    SFT_RETURN_IF_ERROR(ReadBenchMesh(opts.mesh, &mesh));
    SFT_RETURN_IF_ERROR(MeasureDerivativeCost(cost, mesh, &report));
  } else {
    Dataset dataset;
    SFT_RETURN_IF_ERROR(ReadDataset(opts.dataset, &dataset));
    // Without --mesh, the dataset's ground-truth mesh.
    if (opts.mesh != kDefaultBenchMesh) {
      SFT_RETURN_IF_ERROR(ReadBenchMesh(opts.mesh, &mesh));
    } else if (!dataset.gt_mesh.empty()) {
      SFT_RETURN_IF_ERROR(ReadMesh(JoinPath(opts.dataset, dataset.gt_mesh), &mesh));
    } else {
      return Status::Error(
          "--mesh: required with --dataset (the dataset has no ground-truth mesh)");
    }
    Material material;
    SFT_RETURN_IF_ERROR(LoadMaterial(
        opts.material.empty() ? R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5})" : opts.material,
        mesh, &material));
    SFT_RETURN_IF_ERROR(
        MeasureDatasetDerivativeCost(cost, dataset, opts.dataset_views, mesh, material, &report));
  }
  const std::string& what = opts.dataset.empty() ? opts.mesh : opts.dataset;
  std::printf("sft bench gradient: %s\n%s", what.c_str(),
              DerivativeCostReportTable(report).c_str());
  std::fflush(stdout);
  if (!opts.json.empty()) {
    nlohmann::json json = DerivativeCostReportToJson(report);
    json["mesh"] = opts.mesh;
    if (!opts.dataset.empty()) json["dataset"] = opts.dataset;
    SFT_RETURN_IF_ERROR(WriteTextFile(opts.json, json.dump(1) + "\n"));
  }
  return Status::Ok();
}

}  // namespace

CommandRunner SetupBenchCommand(CLI::App* app) {
  app->require_subcommand(1);
  CLI::App* render = app->add_subcommand(
      "render",
      "Raw Embree rays/s (intersect1, intersect8, occluded1) vs the renderer's rays/s on one "
      "mesh and view");
  auto render_opts = std::make_shared<BenchRenderOptions>();
  render
      ->add_option("--mesh", render_opts->mesh,
                   "Mesh (OBJ, PLY, OFF); the default is relative to the working directory")
      ->capture_default_str();
  render->add_option("--res", render_opts->throughput.resolution, "Image width = height, pixels")
      ->capture_default_str();
  render->add_option("--spp", render_opts->throughput.spp, "Camera rays per pixel")
      ->capture_default_str();
  render
      ->add_option("--threads", render_opts->throughput.threads,
                   "Tracing threads for Embree and the renderer (0 = all cores)")
      ->capture_default_str();
  render
      ->add_option("--repeats", render_opts->throughput.repeats,
                   "Runs per measurement; the fastest is kept")
      ->capture_default_str();
  render->add_option("--json", render_opts->json, "Also write the results to this JSON file");

  CLI::App* gradient = app->add_subcommand(
      "gradient",
      "Forward-only vs forward + Jacobian rows vs forward + adjoint gradient time over the views "
      "of one scene, and the Jacobian rows' memory");
  auto gradient_opts = std::make_shared<BenchGradientOptions>();
  gradient
      ->add_option("--mesh", gradient_opts->mesh,
                   "Mesh (OBJ, PLY, OFF); the default is relative to the working directory")
      ->capture_default_str();
  gradient->add_option("--views", gradient_opts->cost.views, "Cameras on the Fibonacci sphere")
      ->capture_default_str();
  gradient->add_option("--dataset", gradient_opts->dataset,
                       "Measure on this dataset's cameras, lights and views instead (--mesh "
                       "defaults to its ground truth; --views and --res do not apply)");
  gradient->add_option("--material", gradient_opts->material,
                       "With --dataset: material JSON file or inline (default albedo 0.5, "
                       "roughness 0.5)");
  gradient
      ->add_option("--dataset-views", gradient_opts->dataset_views,
                   "With --dataset: only these view indices (comma-separated)")
      ->delimiter(',');
  gradient->add_option("--res", gradient_opts->cost.resolution, "Image width = height, pixels")
      ->capture_default_str();
  gradient->add_option("--spp", gradient_opts->cost.spp, "Samples per pixel of every pass")
      ->capture_default_str();
  gradient
      ->add_option("--bounces", gradient_opts->cost.bounces,
                   "Path segments: 1 = direct light only, 2 = one indirect bounce")
      ->capture_default_str();
  gradient->add_option("--threads", gradient_opts->cost.threads, "Renderer threads (0 = all cores)")
      ->capture_default_str();
  gradient->add_option("--seed", gradient_opts->cost.seed, "Sample seed")->capture_default_str();
  gradient->add_flag("--keep-rows", gradient_opts->cost.keep_rows,
                     "Hold every view's Jacobian rows until the end of the pass (default: one "
                     "view's at a time) and report the total resident memory");
  gradient
      ->add_option("--noise-seeds", gradient_opts->cost.noise_seeds,
                   "Also repeat the adjoint pass with this many render seeds (0 = off, or 2..64) "
                   "and report the vertex gradient's seed-to-seed noise and cost x variance")
      ->capture_default_str();
  AddEdgeBudgetOptions(gradient, &gradient_opts->cost.derivatives);
  gradient->add_option("--json", gradient_opts->json, "Also write the results to this JSON file");
  gradient->add_flag("--quiet", gradient_opts->quiet, "No progress lines");
  CommandRunner reconstruct = AddBenchReconstructCommand(app);
  return [render, render_opts, gradient, gradient_opts, reconstruct]() {
    if (render->parsed()) {
      const Status status = RunBenchRender(*render_opts);
      return status.ok() ? 0 : PrintError("bench render", status);
    }
    if (gradient->parsed()) {
      const Status status = RunBenchGradient(*gradient_opts);
      return status.ok() ? 0 : PrintError("bench gradient", status);
    }
    const int code = reconstruct();
    return code >= 0 ? code : 2;
  };
}

}  // namespace sft
