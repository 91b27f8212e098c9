// sft reconstruct: refines a mesh and its material until path-traced renders match a dataset's
// images (src/optim). Writes the state, metrics and an HTML report into OUT (src/optim/
// run_outputs.h); Ctrl-C stops after the current iteration, writes a checkpoint and exits 130;
// `--resume OUT` continues from it.
#include <csignal>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/eval/mesh_metrics.h"
#include "src/eval/reconstruct_report.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/light_scales.h"
#include "src/optim/config.h"
#include "src/optim/reconstruct.h"
#include "src/optim/run_outputs.h"

namespace sft {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void OnInterrupt(int) { g_interrupted = true; }

// Command-line values; those left unset do not override the config file.
struct ReconstructCommandOptions {
  std::string dataset;   // dataset directory.
  std::string init;      // initial mesh.
  std::string out;       // output directory.
  std::string resume;    // an earlier run's output directory to continue.
  std::string config;    // config JSON file.
  std::string material;  // initial material (JSON file or inline); "" = constant guess.
  std::string phases, solver;
  int outer = 0, steps = 0, spp = 0, bounces = 0, threads = 0;
  int64_t seed = 0;
  std::vector<int> views;
  std::set<std::string> given;  // config keys whose flag was on the command line.
  std::string reference;        // ground-truth mesh: F1 and Chamfer after every outer iteration.
  double reference_tolerance = 0.005;  // F1 tolerance, fraction of the reference's diagonal.
  bool quiet = false;
  bool no_report = false;
};

constexpr char kInitialGuess[] = R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5})";

// The effective options: defaults < config file < state.json (resume) < flags.
Status MakeOptions(const ReconstructCommandOptions& cli, const nlohmann::json* resumed,
                   ReconstructOptions* options) {
  if (resumed != nullptr) {
    SFT_RETURN_IF_ERROR(ApplyReconstructConfig(*resumed, cli.resume + "/state.json", options));
  }
  if (!cli.config.empty()) SFT_RETURN_IF_ERROR(ReadReconstructConfig(cli.config, options));
  const nlohmann::json all = {
      {"phases", cli.phases},   {"solver", cli.solver}, {"outer_iterations", cli.outer},
      {"steps", cli.steps},     {"spp", cli.spp},       {"bounces", cli.bounces},
      {"threads", cli.threads}, {"seed", cli.seed},     {"views", cli.views}};
  nlohmann::json flags = nlohmann::json::object();
  for (const auto& [key, value] : all.items()) {
    if (cli.given.count(key) > 0) flags[key] = value;
  }
  // Flag errors name the flag ("--steps: ...").
  for (const auto& [key, value] : flags.items()) {
    const Status status = ApplyReconstructConfig({{key, value}}, "flag", options);
    if (!status.ok()) {
      std::string message = status.message();
      message = message.substr(message.find(": ") + 2);  // "steps: expected ...".
      if (message.rfind("outer_iterations", 0) == 0) message.replace(0, 16, "outer");
      return Status::Error("--" + message);
    }
  }
  std::string why;
  if (!options->Check(&why)) return Status::Error(why);
  return Status::Ok();
}

// metrics.json's per-outer-iteration entry: cost, time, mesh quality against the initial mesh and,
// with a reference, F1 and Chamfer (50k samples per surface).
Status OuterRecord(int outer, const std::vector<IterationRecord>& records, const TriMesh& initial,
                   const Reconstruction& reconstruction, const TriMesh* reference, double tolerance,
                   nlohmann::json* out) {
  const TriMesh mesh = reconstruction.Mesh();
  const MeshQuality quality = CompareMeshQuality(initial, mesh);
  *out = {{"outer", outer},
          {"seconds", records.empty() ? 0.0 : records.back().seconds},
          {"cost", records.empty() ? 0.0 : records.back().cost},
          {"flipped_faces", quality.flipped_faces},
          {"degenerate_faces", quality.degenerate_faces}};
  if (reference != nullptr) {
    MeshMetricsOptions options;
    options.samples = 50000;
    options.tolerance = tolerance;
    MeshMetrics m;
    SFT_RETURN_IF_ERROR(ComputeMeshMetrics(*reference, mesh, options, &m, "--reference", "mesh"));
    (*out)["chamfer"] = m.chamfer;
    (*out)["f1"] = m.f1;
    (*out)["f1_tolerance"] = tolerance;
  }
  return Status::Ok();
}

// Settles the run's folders and options: a fresh run needs --dataset, --init and --out and an
// output folder that overlaps no input and holds no earlier run; --resume reads the earlier
// run's state (its dataset and effective options) from its own folder.
Status PrepareRun(ReconstructCommandOptions* cli, RunState* state, ReconstructOptions* options) {
  nlohmann::json resumed_config;
  if (!cli->resume.empty()) {
    if (!cli->out.empty() && cli->out != cli->resume) {
      return Status::Error("--resume continues in its own folder: drop --out or give the same");
    }
    cli->out = cli->resume;
    SFT_RETURN_IF_ERROR(ReadRunState(cli->resume, state));
    if (cli->dataset.empty()) cli->dataset = state->dataset;
    resumed_config = state->config;
  } else if (cli->dataset.empty() || cli->init.empty() || cli->out.empty()) {
    return Status::Error("--dataset, --init and --out are required (or --resume OUT)");
  }
  SFT_RETURN_IF_ERROR(MakeOptions(*cli, cli->resume.empty() ? nullptr : &resumed_config, options));
  if (!(cli->reference_tolerance > 0.0 && cli->reference_tolerance <= 1.0)) {
    return Status::Error("--reference-tolerance: must be in (0, 1]");
  }
  if (!cli->resume.empty()) {
    return CheckOutputDirectory(cli->out, {{cli->dataset}, {}}, "--resume");
  }
  const RunInputs inputs{{cli->dataset},
                         {cli->init, MaterialFile(cli->material), cli->config, cli->reference}};
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(cli->out, inputs, "--out"));
  if (FileExists(JoinPath(cli->out, "state.json"))) {
    return Status::Error("--out " + cli->out +
                         ": holds an earlier reconstruction (continue it with --resume " +
                         cli->out + ", or choose another folder)");
  }
  return Status::Ok();
}

// The starting mesh, material and light scales: --init and --material, or the checkpoint.
Status LoadStart(const ReconstructCommandOptions& cli, const Dataset& dataset, TriMesh* mesh,
                 Material* material, std::vector<double>* light_scales) {
  if (cli.resume.empty()) {
    SFT_RETURN_IF_ERROR(ReadMesh(cli.init, mesh));
    return LoadMaterial(cli.material.empty() ? kInitialGuess : cli.material, *mesh, material);
  }
  SFT_RETURN_IF_ERROR(ReadMesh(JoinPath(cli.out, "mesh.ply"), mesh));
  SFT_RETURN_IF_ERROR(LoadMaterial(JoinPath(cli.out, "material.json"), *mesh, material));
  return ReadLightScales(JoinPath(cli.out, "lights.json"), dataset, light_scales);
}

Status RunReconstruct(const ReconstructCommandOptions& cli_in) {
  ReconstructCommandOptions cli = cli_in;
  RunState state;
  ReconstructOptions options;
  SFT_RETURN_IF_ERROR(PrepareRun(&cli, &state, &options));
  Dataset dataset;
  SFT_RETURN_IF_ERROR(ReadDataset(cli.dataset, &dataset));
  SFT_RETURN_IF_ERROR(CheckViewsHaveLights(dataset));
  TriMesh mesh;
  Material material;
  std::vector<double> light_scales;
  SFT_RETURN_IF_ERROR(LoadStart(cli, dataset, &mesh, &material, &light_scales));
  std::unique_ptr<Reconstruction> reconstruction;
  SFT_RETURN_IF_ERROR(
      Reconstruction::Create(dataset, mesh, material, light_scales, options, &reconstruction));
  reconstruction->elapsed_offset = state.seconds;
  std::vector<IterationRecord> records;
  nlohmann::json outer_records = nlohmann::json::array();
  if (!cli.resume.empty()) {
    SFT_RETURN_IF_ERROR(ReadIterationRecords(cli.out, &records));
    SFT_RETURN_IF_ERROR(ReadOuterRecords(cli.out, &outer_records));
  }
  TriMesh reference;
  if (!cli.reference.empty()) SFT_RETURN_IF_ERROR(ReadMesh(cli.reference, &reference));
  SFT_RETURN_IF_ERROR(MakeDirectories(cli.out));
  // Folded faces are counted against the run's start, also after --resume.
  TriMesh initial_mesh = mesh;
  const std::string initial_path = JoinPath(cli.out, "initial_mesh.ply");
  if (cli.resume.empty()) {
    SFT_RETURN_IF_ERROR(WriteMesh(initial_path, mesh));
    state.init = cli.init;
  } else if (FileExists(initial_path)) {
    SFT_RETURN_IF_ERROR(ReadMesh(initial_path, &initial_mesh));
    if (initial_mesh.n_faces() != mesh.n_faces()) {
      return Status::Error(initial_path + ": " + std::to_string(initial_mesh.n_faces()) +
                           " faces, the checkpoint's mesh.ply has " +
                           std::to_string(mesh.n_faces()));
    }
  }

  state.dataset = cli.dataset;
  state.config = ReconstructConfigJson(options);
  const int phases_per_outer = options.phases == PhaseSchedule::kAlternate ? 2 : 1;
  Progress progress("reconstruct",
                    static_cast<int64_t>(options.outer_iterations - state.outer_done) *
                        phases_per_outer * options.solver.steps,
                    !cli.quiet);
  std::signal(SIGINT, OnInterrupt);
  const nlohmann::json run_info = {{"dataset", cli.dataset},
                                   {"init", state.init},
                                   {"config", state.config},
                                   {"views", reconstruction->view_indices()}};
  for (int outer = state.outer_done; outer < options.outer_iterations && !g_interrupted; ++outer) {
    SFT_RETURN_IF_ERROR(reconstruction->RunOuter(outer, [&](const IterationRecord& record) {
      records.push_back(record);
      progress.Advance();
      return !g_interrupted.load();
    }));
    if (!g_interrupted) state.outer_done = outer + 1;
    state.seconds = records.empty() ? 0.0 : records.back().seconds;
    nlohmann::json outer_record;
    SFT_RETURN_IF_ERROR(OuterRecord(outer, records, initial_mesh, *reconstruction,
                                    cli.reference.empty() ? nullptr : &reference,
                                    cli.reference_tolerance, &outer_record));
    outer_records.push_back(outer_record);
    nlohmann::json info = run_info;
    info["outer"] = outer_records;
    state.finished = state.outer_done == options.outer_iterations;
    SFT_RETURN_IF_ERROR(WriteReconstructionState(cli.out, dataset, *reconstruction));
    SFT_RETURN_IF_ERROR(WriteMetrics(cli.out, records, reconstruction->phases(), info));
    SFT_RETURN_IF_ERROR(WriteRunState(cli.out, state));
  }
  progress.Finish();
  std::signal(SIGINT, SIG_DFL);
  if (!cli.no_report) {
    SFT_RETURN_IF_ERROR(WriteReconstructReport(cli.out, dataset, records, reconstruction.get()));
  }
  if (g_interrupted) {
    return Status::Error("interrupted after " + std::to_string(state.outer_done) +
                         " outer iterations; state written to " + cli.out +
                         " (continue with --resume " + cli.out + ")");
  }
  std::printf("sft reconstruct: %d outer iterations, %.1f s; mesh %s, report %s\n",
              state.outer_done, state.seconds, JoinPath(cli.out, "mesh.ply").c_str(),
              cli.no_report ? "(none)" : JoinPath(cli.out, "report.html").c_str());
  return Status::Ok();
}

}  // namespace

CommandRunner SetupReconstructCommand(CLI::App* app) {
  auto opts = std::make_shared<ReconstructCommandOptions>();
  app->add_option("--dataset", opts->dataset, "Dataset directory (sft-dataset/1)");
  app->add_option("--init", opts->init, "Initial mesh (OBJ, PLY, OFF)");
  app->add_option("--out", opts->out, "Output directory");
  app->add_option("--resume", opts->resume, "Continue the run whose output directory is this");
  app->add_option("--config", opts->config,
                  "Config JSON (keys in docs/reconstruct.md); flags override it");
  app->add_option("--material", opts->material,
                  "Initial material (JSON file or inline); default: albedo 0.5, roughness 0.5");
  // Flags that override config keys: recorded as given only when on the command line.
  const auto key_flag = [&](CLI::Option* option, const std::string& key) {
    option->each([opts, key](const std::string&) { opts->given.insert(key); });
  };
  key_flag(app->add_option("--phases", opts->phases,
                           "texture | geometry | alternate (default alternate)"),
           "phases");
  key_flag(app->add_option("--solver", opts->solver, "lm | dogleg | lbfgs | adam (default lm)"),
           "solver");
  key_flag(
      app->add_option("--outer", opts->outer, "Outer iterations (fresh seeds each; default 4)"),
      "outer_iterations");
  key_flag(app->add_option("--steps", opts->steps,
                           "Solver iterations per outer iteration and phase (5)"),
           "steps");
  key_flag(app->add_option("--spp", opts->spp, "Samples per pixel of the fit's renders (16)"),
           "spp");
  key_flag(app->add_option("--bounces", opts->bounces, "Path segments (2)"), "bounces");
  key_flag(app->add_option("--threads", opts->threads, "Render threads (0 = all cores)"),
           "threads");
  key_flag(app->add_option("--seed", opts->seed, "Base seed"), "seed");
  key_flag(app->add_option("--views", opts->views, "Only these view indices (comma-separated)")
               ->delimiter(','),
           "views");
  app->add_option("--reference", opts->reference,
                  "Ground-truth mesh: F1 and Chamfer after every outer iteration (metrics.json)");
  app->add_option("--reference-tolerance", opts->reference_tolerance,
                  "F1 tolerance of --reference, fraction of its bounding-box diagonal")
      ->capture_default_str();
  app->add_flag("--quiet", opts->quiet, "No progress line");
  app->add_flag("--no-report", opts->no_report, "Do not write OUT/report.html");
  return [opts]() {
    const Status status = RunReconstruct(*opts);
    if (status.ok()) return 0;
    PrintError("reconstruct", status);
    return g_interrupted ? 130 : 1;
  };
}

}  // namespace sft
