// sft bench TARGET: throughput measurements. Targets are CLI11 sub-subcommands so that more can
// be added (e.g. `sft bench gradient`):
//   sft bench render   raw Embree rays/s (intersect1, intersect8, occluded1) on the renderer's own
//                      BVH and ray set vs RenderView's rays/s, and their ratio
//                      (src/eval/throughput.h).
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/eval/throughput.h"
#include "src/geometry/mesh.h"

namespace sft {
namespace {

// The default mesh, relative to the working directory (the binary does not know the source tree).
constexpr char kDefaultBenchMesh[] = "data/meshes/bunny_watertight_5k.obj";

struct BenchRenderOptions {
  std::string mesh = kDefaultBenchMesh;  // mesh to trace (OBJ, PLY, OFF).
  std::string json;                      // optional JSON report path.
  ThroughputOptions throughput;          // resolution, spp, threads, repeats.
};

Status RunBenchRender(const BenchRenderOptions& opts) {
  std::string why;
  if (!opts.throughput.Check(&why)) return Status::Error("--" + why);
  if (!FileExists(opts.mesh)) {
    if (opts.mesh == kDefaultBenchMesh) {
      return Status::Error("--mesh: default " + opts.mesh +
                           " not found in the current directory (run from the source tree or "
                           "pass --mesh)");
    }
    return Status::Error("--mesh: " + opts.mesh + " not found");
  }
  TriMesh mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(opts.mesh, &mesh));
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
  return [render, render_opts]() {
    if (render->parsed()) {
      const Status status = RunBenchRender(*render_opts);
      return status.ok() ? 0 : PrintError("bench render", status);
    }
    return 2;
  };
}

}  // namespace sft
