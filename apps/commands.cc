#include "apps/commands.h"

#include <cstdio>
#include <vector>

namespace sft {
namespace {

const CommandEntry kCommands[] = {
    {"synth", "Render a synthetic dataset (sft-dataset/1) of a mesh from Fibonacci-sphere cameras",
     &SetupSynthCommand},
    {"render", "Render every view of a dataset with a given mesh and material",
     &SetupRenderCommand},
    {"gradcheck",
     "Compare the renderer's derivatives with finite differences for one parameter kind",
     &SetupGradcheckCommand},
    {"reconstruct",
     "Refine a mesh and its material until path-traced renders match a dataset (Ceres)",
     &SetupReconstructCommand},
    {"init",
     "Carve an initial mesh from a dataset's masks (visual hull) into D/init/mesh.ply or --out",
     &SetupInitCommand},
    {"perturb", "Displace a mesh by a smooth random field (starting meshes for tests)",
     &SetupPerturbCommand},
    {"compare", "Cost, Chamfer and F1 against wall time over several reconstruct runs (CSV, HTML)",
     &SetupCompareCommand},
    {"sweep",
     "Reconstruct over a grid of settings and chart accuracy against wall time (Pareto fronts)",
     &SetupSweepCommand},
    {"import",
     "Bring captures into the dataset format (colmap, video; calibrated: nerf, idr, middlebury)",
     &SetupImportCommand},
    {"align-probe",
     "Find a dataset's 360-degree probe rotation from the frames' background (SIFT + RANSAC)",
     &SetupAlignProbeCommand},
    {"export",
     "Write a reconstruction as OBJ + MTL + PNG textures, glTF binary and coloured PLY (UV atlas)",
     &SetupExportCommand},
    {"bench", "Measure throughput against the limit (raw Embree rays/s)", &SetupBenchCommand},
    {"eval", "Measure a reconstructed mesh against a reference mesh (F1, Chamfer) as JSON",
     &SetupEvalCommand},
};

}  // namespace

void AddEdgeBudgetOptions(CLI::App* app, DerivativeRequest* request) {
  app->add_option("--primary-edge-ratio", request->primary_edge_ratio,
                  "Primary (silhouette/crease) edge samples per pixel sample, [0, 16]; 0 = off")
      ->capture_default_str();
  app->add_option("--shadow-edge-ratio", request->shadow_edge_ratio,
                  "Point-light shadow edge samples per pixel sample, [0, 16]; 0 = off")
      ->capture_default_str();
  app->add_option("--secondary-edge-samples", request->secondary_edge_samples,
                  "Secondary edge samples per path vertex, [0, 16]; 0 = off")
      ->capture_default_str();
  app->add_option("--texel-edge-ratio", request->texel_edge_ratio,
                  "Texel-boundary samples per pixel sample, [0, 16]; 0 = off")
      ->capture_default_str();
  app->add_flag("--no-normal-sliding{false}", request->normal_sliding,
                "Smooth shading: leave out the sliding (barycentric) term of the shading "
                "normal's derivative (biased, lower variance)");
}

std::string MaterialFile(const std::string& material) {
  return (material.empty() || material[0] == '{') ? std::string() : material;
}

int PrintError(const std::string& command, const Status& status) {
  std::fprintf(stderr, "sft %s: error: %s\n", command.c_str(), status.message().c_str());
  return 1;
}

int RunCommandTable(int argc, char** argv) {
  CLI::App app{
      "sft — Shape from Tracing: reconstruct a mesh and its spatially varying material "
      "from calibrated photographs with a differentiable path tracer.",
      "sft"};
  app.require_subcommand(1);
  // One error line; no "Run with --help" epilogue.
  // One error line naming the deepest command that was parsed ("sft bench render: error: ...").
  app.failure_message([](const CLI::App* failed, const CLI::Error& e) {
    std::string name = "sft";
    const CLI::App* current = failed;
    while (current != nullptr) {
      const CLI::App* next = nullptr;
      for (const CLI::App* sub : current->get_subcommands()) {
        if (sub->parsed()) next = sub;
      }
      if (next != nullptr) name += " " + next->get_name();
      current = next;
    }
    return name + ": error: " + std::string(e.what()) + "\n";
  });
  std::vector<std::pair<CLI::App*, CommandRunner>> runners;
  for (const CommandEntry& entry : kCommands) {
    CLI::App* sub = app.add_subcommand(entry.name, entry.description);
    runners.emplace_back(sub, entry.setup(sub));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  for (auto& [sub, runner] : runners) {
    if (sub->parsed()) return runner();
  }
  return 2;
}

}  // namespace sft
