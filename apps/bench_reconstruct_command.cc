// sft bench reconstruct: where one outer iteration of `sft reconstruct` spends its time on a
// dataset (src/eval/reconstruct_cost.h), against a forward render of every view measured in the
// same run.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/eval/reconstruct_cost.h"
#include "src/io/scene_setup.h"
#include "src/optim/config.h"
#include "src/optim/mpi_views.h"

namespace sft {
namespace {

struct BenchReconstructOptions {
  std::string dataset;   // dataset directory (sft-dataset/1).
  std::string init;      // starting mesh.
  std::string material;  // starting material (JSON file or inline); default as sft reconstruct.
  std::string config;    // reconstruct config JSON (docs/reconstruct.md).
  std::string json;      // optional JSON report path.
  bool quiet = false;    // no per-iteration lines.
  // Flags that override config keys, applied only when given (`given`).
  std::string phases = "geometry", solver = "lm";
  int steps = 2, spp = 16, bounces = 2, threads = 0;
  std::vector<int> views;
  std::set<std::string> given;
};

constexpr char kInitialGuess[] = R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5})";

// Defaults (geometry, 2 LM steps) < config file < flags.
Status MakeOptions(const BenchReconstructOptions& cli, ReconstructOptions* options) {
  SFT_RETURN_IF_ERROR(
      ApplyReconstructConfig({{"phases", "geometry"}, {"steps", 2}}, "defaults", options));
  if (!cli.config.empty()) SFT_RETURN_IF_ERROR(ReadReconstructConfig(cli.config, options));
  const nlohmann::json all = {
      {"phases", cli.phases},   {"solver", cli.solver},   {"steps", cli.steps}, {"spp", cli.spp},
      {"bounces", cli.bounces}, {"threads", cli.threads}, {"views", cli.views}};
  for (const auto& [key, value] : all.items()) {
    if (cli.given.count(key) == 0) continue;
    const Status status = ApplyReconstructConfig({{key, value}}, "flag", options);
    if (!status.ok()) {
      const std::string& message = status.message();
      return Status::Error("--" + message.substr(message.find(": ") + 2));
    }
  }
  std::string why;
  if (!options->Check(&why)) return Status::Error(why);
  return Status::Ok();
}

// Under mpirun (rank 0): the handshake once the inputs are read, the views spread while
// measuring. Null `session`: one process.
Status RunBenchReconstruct(const BenchReconstructOptions& cli, const MpiSession* session,
                           bool* agreed) {
  if (cli.dataset.empty() || cli.init.empty()) {
    return Status::Error("--dataset and --init are required");
  }
  ReconstructCostOptions options;
  options.progress = !cli.quiet;
  SFT_RETURN_IF_ERROR(MakeOptions(cli, &options.reconstruct));
  if (!cli.json.empty()) {
    const RunInputs inputs{{cli.dataset}, {cli.init, MaterialFile(cli.material), cli.config}};
    SFT_RETURN_IF_ERROR(CheckOutputFile(cli.json, inputs, "--json"));
  }
  Dataset dataset;
  SFT_RETURN_IF_ERROR(ReadDataset(cli.dataset, &dataset));
  TriMesh mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(cli.init, &mesh));
  Material material;
  SFT_RETURN_IF_ERROR(
      LoadMaterial(cli.material.empty() ? kInitialGuess : cli.material, mesh, &material));
  std::unique_ptr<MpiViewRunner> runner;
  if (session != nullptr) {
    std::vector<int> views;
    SFT_RETURN_IF_ERROR(
        SelectViews(options.reconstruct.views, static_cast<int>(dataset.views.size()), &views));
    *agreed = true;
    SFT_RETURN_IF_ERROR(
        MpiHandshake(*session, Status::Ok(), cli.dataset, static_cast<int>(views.size()), nullptr));
    runner = std::make_unique<MpiViewRunner>(*session, 3600.0);
    SetViewRunner(runner.get());
  }
  ReconstructCostReport report;
  const Status measured = MeasureReconstructCost(dataset, mesh, material, options, &report);
  SetViewRunner(nullptr);
  if (runner) runner->Stop();
  SFT_RETURN_IF_ERROR(measured);
  std::printf("sft bench reconstruct: %s\n%s", cli.dataset.c_str(),
              ReconstructCostTable(report).c_str());
  if (runner) {
    const MpiViewStats& m = runner->stats();
    std::printf(
        "mpi: %d ranks, %lld spread evaluations, %lld jobs rendered on other ranks; "
        "rank 0: broadcast %.3f s, own renders %.3f s, imbalance %.3f s (workers idle %.3f s), "
        "gather %.3f s\n",
        m.ranks, static_cast<long long>(m.evaluations), static_cast<long long>(m.remote_jobs),
        m.broadcast, m.local_render, m.imbalance, m.worker_idle, m.gather);
  }
  std::fflush(stdout);
  if (!cli.json.empty()) {
    nlohmann::json json = ReconstructCostToJson(report);
    if (runner) json["mpi"] = MpiViewStatsJson(runner->stats());
    json["dataset"] = cli.dataset;
    json["init"] = cli.init;
    SFT_RETURN_IF_ERROR(WriteTextFile(cli.json, json.dump(1) + "\n"));
  }
  return Status::Ok();
}

}  // namespace

CommandRunner AddBenchReconstructCommand(CLI::App* bench) {
  CLI::App* app = bench->add_subcommand(
      "reconstruct",
      "Where one outer iteration of sft reconstruct spends its time (render, Jacobian, linear "
      "solve, problem build) against a forward render of every view");
  auto opts = std::make_shared<BenchReconstructOptions>();
  app->add_option("--dataset", opts->dataset, "Dataset directory (sft-dataset/1)");
  app->add_option("--init", opts->init, "Starting mesh (OBJ, PLY, OFF)");
  app->add_option("--material", opts->material,
                  "Starting material (JSON file or inline); default: albedo 0.5, roughness 0.5");
  app->add_option("--config", opts->config, "Reconstruct config JSON; flags override it");
  const auto key_flag = [&](CLI::Option* option, const std::string& key) {
    option->each([opts, key](const std::string&) { opts->given.insert(key); });
  };
  key_flag(app->add_option("--phases", opts->phases, "texture | geometry | alternate (geometry)"),
           "phases");
  key_flag(app->add_option("--solver", opts->solver, "lm | dogleg | lbfgs | adam (lm)"), "solver");
  key_flag(app->add_option("--steps", opts->steps, "Solver iterations per phase (2)"), "steps");
  key_flag(app->add_option("--spp", opts->spp, "Samples per pixel (16)"), "spp");
  key_flag(app->add_option("--bounces", opts->bounces, "Path segments (2)"), "bounces");
  key_flag(app->add_option("--threads", opts->threads, "Render threads (0 = all cores)"),
           "threads");
  key_flag(app->add_option("--views", opts->views, "Only these view indices (comma-separated)")
               ->delimiter(','),
           "views");
  app->add_option("--json", opts->json, "Also write the results to this JSON file");
  app->add_flag("--quiet", opts->quiet, "No per-iteration lines");
  return [app, opts]() {
    if (!app->parsed()) return -1;
    if (!MpiSession::Launched()) {
      const Status status = RunBenchReconstruct(*opts, nullptr, nullptr);
      return status.ok() ? 0 : PrintError("bench reconstruct", status);
    }
    // Under mpirun (src/optim/mpi_views.h): rank 0 measures, the others serve renders.
    std::unique_ptr<MpiSession> session;
    Status status = MpiSession::Start(&session);
    if (!status.ok()) return PrintError("bench reconstruct", status);
    if (session->rank() != 0) {
      Dataset dataset;
      status = MpiHandshake(*session, Status::Ok(), "", 0, &dataset);
      if (status.ok()) status = ServeViews(*session, dataset);
      return status.ok() ? 0 : 1;
    }
    bool agreed = false;
    status = RunBenchReconstruct(*opts, session.get(), &agreed);
    // An error before the handshake releases the workers through it.
    if (!agreed) MpiHandshake(*session, status, opts->dataset, 0, nullptr);
    return status.ok() ? 0 : PrintError("bench reconstruct", status);
  };
}

}  // namespace sft
