// sft reconstruct: refines a mesh and its material until path-traced renders match a dataset's
// images, stage by stage (src/optim/schedule.h; stages and keys in docs/reconstruct.md). This
// file only configures the schedule, shows progress and writes the report. Ctrl-C stops after the
// current solver iteration, writes a checkpoint and exits 130; `--resume OUT` continues from it.
#include <algorithm>
#include <atomic>
#include <climits>
#include <csignal>
#include <cstdio>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/eval/reconstruct_report.h"
#include "src/eval/reference_score.h"
#include "src/export/export.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/fitted_environment.h"
#include "src/optim/holdout.h"
#include "src/optim/lamp_finder.h"
#include "src/optim/mpi_views.h"
#include "src/optim/run_outputs.h"
#include "src/optim/schedule.h"
#include "src/optim/schedule_config.h"
#include "src/optim/start_mesh.h"

namespace sft {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void OnInterrupt(int) { g_interrupted = true; }
// Rank 0 under mpirun: SIGTERM, which Open MPI's launcher sends when another rank died (a fault:
// MpiViewRunner).
std::atomic<bool> g_terminating{false};
extern "C" void OnTerminate(int) { g_terminating = true; }

// Command-line values; those left unset do not override the config file.
struct ReconstructCommandOptions {
  std::string dataset;   // dataset directory.
  std::string init;      // initial mesh; "" = the dataset's initial_mesh, else a carved hull.
  std::string out;       // output directory.
  std::string resume;    // an earlier run's output directory to continue.
  std::string config;    // config JSON file.
  std::string material;  // initial material (JSON file or inline); "" = constant guess.
  std::string phases, solver, effects;
  int outer = 0, steps = 0, spp = 0, bounces = 0, threads = 0;
  int64_t seed = 0;
  std::vector<int> views;
  int holdout = 0;                // every K-th selected view is held out of the fit; 0 = off.
  std::string environment_frame;  // unknown lighting's fitted map: "world" or "camera".
  std::string estimate_lights;    // unknown lighting: a lights file estimated beside the map.
  bool find_lamp = false;         // unknown lighting: look for a lamp in the map fitted alone.
  std::set<std::string> given;    // config keys whose flag was on the command line.
  std::string reference;          // ground-truth mesh: F1 and Chamfer after every outer iteration.
  double reference_tolerance = 0.005;  // F1 tolerance, fraction of the reference's diagonal.
  bool print_schedule = false;
  bool quiet = false;
  bool no_report = false;
  double mpi_timeout = 3600.0;  // seconds rank 0 waits for a worker's result under mpirun.
};

// Called by PrepareSchedule once the run is settled, just before the schedule starts (and writes
// into the output folder), with the dataset path and the stages.
using BeforeStart = std::function<Status(const std::string& dataset, const Dataset&,
                                         const std::vector<StageOptions>&)>;

// The flat keys of the command line (flags override the config file's keys in every stage).
Status FlagKeys(const ReconstructCommandOptions& cli, ScheduleConfig* config) {
  const nlohmann::json all = {{"phases", cli.phases},
                              {"solver", cli.solver},
                              {"outer_iterations", cli.outer},
                              {"steps", cli.steps},
                              {"spp", cli.spp},
                              {"bounces", cli.bounces},
                              {"threads", cli.threads},
                              {"seed", cli.seed},
                              {"views", cli.views},
                              {"effects", cli.effects},
                              {"holdout", cli.holdout},
                              {"environment_frame", cli.environment_frame},
                              {"estimate_lights", cli.estimate_lights},
                              {"find_lamp", cli.find_lamp}};
  for (const auto& [key, value] : all.items()) {
    if (cli.given.count(key) == 0) continue;
    const Status status = MergeScheduleConfig({{key, value}}, "flag", config);
    if (!status.ok()) {  // name the flag: "--steps: expected ...".
      std::string message = status.message().substr(status.message().find(": ") + 2);
      if (message.rfind("outer_iterations", 0) == 0) message.replace(0, 16, "outer");
      if (message.rfind("environment_frame", 0) == 0) message.replace(0, 17, "environment-frame");
      if (message.rfind("estimate_lights", 0) == 0) message.replace(0, 15, "estimate-lights");
      if (message.rfind("find_lamp", 0) == 0) message.replace(0, 9, "find-lamp");
      return Status::Error("--" + message);
    }
  }
  return Status::Ok();
}

// A fresh run's stages: built-in or from --config, with the flags applied.
Status FreshStages(const ReconstructCommandOptions& cli, const StartChoice& start,
                   ScheduleConfig* config, std::vector<StageOptions>* stages) {
  if (!cli.config.empty()) SFT_RETURN_IF_ERROR(ReadScheduleConfig(cli.config, config));
  SFT_RETURN_IF_ERROR(FlagKeys(cli, config));
  return ResolveStages(*config, start.kind == StartKind::kCarved, stages);
}

// A resumed run's stages: state.json's, with --config's flat keys and the flags over each; the
// run's held-out views stay out of every stage, and a different --holdout is refused.
Status ResumedStages(const ReconstructCommandOptions& cli, const RunState& state,
                     const Dataset& dataset, std::vector<StageOptions>* stages) {
  SFT_RETURN_IF_ERROR(StagesFromJson(state.stages, JoinPath(cli.resume, "state.json"), stages));
  ScheduleConfig overrides;
  if (!cli.config.empty()) {
    SFT_RETURN_IF_ERROR(ReadScheduleConfig(cli.config, &overrides));
    if (!overrides.stages.is_null() || overrides.schedule != "auto") {
      return Status::Error(cli.config + ": stages/schedule: a resumed run keeps its stages " +
                           "(only flat keys may change)");
    }
    if (overrides.environment_given) {
      return Status::Error(cli.config +
                           ": environment_stage/environment_size/estimate_lights/find_lamp: " +
                           "a resumed run keeps its stages and its fitted lighting");
    }
    if (!overrides.carve_keys.empty()) {
      return Status::Error(cli.config + ": carve: a resumed run has its start already");
    }
  }
  for (const char* key : {"estimate_lights", "find_lamp"}) {
    if (cli.given.count(key) > 0) {
      std::string flag = std::string("--") + key;
      std::replace(flag.begin(), flag.end(), '_', '-');
      return Status::Error(flag + ": a resumed run keeps its fitted lighting");
    }
  }
  SFT_RETURN_IF_ERROR(FlagKeys(cli, &overrides));
  if (overrides.holdout_given && overrides.holdout != state.holdout) {
    return Status::Error("--holdout " + std::to_string(overrides.holdout) + ": the run in " +
                         cli.resume + " was started with --holdout " +
                         std::to_string(state.holdout) + " and keeps its held-out views");
  }
  if (overrides.environment_frame_given && LightingUnknown(dataset)) {
    LightFrame frame = LightFrame::kWorld;
    SFT_RETURN_IF_ERROR(ReadFittedEnvironmentFrame(cli.resume, &frame));
    if (overrides.environment.frame != frame) {
      return Status::Error(std::string("environment_frame ") +
                           LightFrameName(overrides.environment.frame) + ": the run in " +
                           cli.resume + " fits a " + LightFrameName(frame) +
                           "-fixed environment and keeps it");
    }
  }
  for (StageOptions& stage : *stages) {
    SFT_RETURN_IF_ERROR(ApplyStageConfig(overrides.flat, "overrides", &stage));
    std::string why;
    if (!stage.Check(&why)) return Status::Error(stage.name + ": " + why);
  }
  return ExcludeHeldOutViews(state.held_out_views, static_cast<int>(dataset.views.size()), stages);
}

// --print-schedule: the stages with the views each fits, then the held-out views, if any.
Status PrintSchedule(const std::vector<StageOptions>& stages, const Dataset& dataset, int holdout,
                     const std::vector<int>& held_out) {
  const int views = static_cast<int>(dataset.views.size());
  std::printf("%s", FormatSchedule(stages, views).c_str());
  if (!held_out.empty()) {
    std::printf("held out (--holdout %d): %s\n", holdout,
                DescribeStageViews(held_out, views).c_str());
  }
  return Status::Ok();
}

// Unknown lighting (no view lists lights) is estimated as a fitted environment
// (src/optim/fitted_environment.h), said in one line; `run` is the resumed folder ("" fresh),
// whose map keeps its own frame.
Status UnknownLighting(const std::string& run, const EnvironmentEstimateOptions& options,
                       const ReconstructCommandOptions& cli, Dataset* dataset) {
  std::string note;
  SFT_RETURN_IF_ERROR(PrepareUnknownLighting(run, options, dataset, &note));
  if (!note.empty() && !cli.quiet) {
    std::printf("%s\n", note.c_str());
    std::fflush(stdout);  // before the progress lines on stderr.
  }
  return CheckViewsHaveLights(*dataset);
}

// --find-lamp: the environment stage `environment` fits the map alone first; a lamp in its
// brightest lobe's direction (src/optim/lamp_finder.h) joins the dataset's lights before the run
// starts, said in one line.
Status FindLampForRun(const ReconstructCommandOptions& cli,
                      const EnvironmentEstimateOptions& options, const StageOptions& environment,
                      const ScheduleStart& start, Dataset* dataset) {
  Progress progress(
      "find lamp",
      static_cast<int64_t>(environment.fit.outer_iterations) * environment.fit.solver.steps,
      !cli.quiet);
  LampSearch search;
  SFT_RETURN_IF_ERROR(FindLamp(
      *dataset, start.mesh, start.material, environment.fit, options.lamp_distance,
      [&](const IterationRecord& record) {
        if (!record.full) progress.Advance();
        return !g_interrupted.load();
      },
      &search));
  progress.Finish();
  if (!cli.quiet) {
    std::printf("%s\n", search.Describe().c_str());
    std::fflush(stdout);
  }
  return search.found ? AddEstimatedLights({search.lamp}, dataset) : Status::Ok();
}

// Settles folders, stages and the schedule (fresh or resumed). Returns with *schedule null after
// --print-schedule.
Status PrepareSchedule(ReconstructCommandOptions* cli, Dataset* dataset,
                       const BeforeStart& before_start, std::unique_ptr<Schedule>* schedule) {
  if (!(cli->reference_tolerance > 0.0 && cli->reference_tolerance <= 1.0)) {
    return Status::Error("--reference-tolerance: must be in (0, 1]");
  }
  std::vector<StageOptions> stages;
  if (!cli->resume.empty()) {
    if (!cli->out.empty() && cli->out != cli->resume) {
      return Status::Error("--resume continues in its own folder: drop --out or give the same");
    }
    cli->out = cli->resume;
    RunState state;
    SFT_RETURN_IF_ERROR(ReadRunState(cli->resume, &state));
    if (cli->dataset.empty()) cli->dataset = state.dataset();
    SFT_RETURN_IF_ERROR(ReadDataset(cli->dataset, dataset));
    SFT_RETURN_IF_ERROR(ResumedStages(*cli, state, *dataset, &stages));
    if (cli->print_schedule) {
      return PrintSchedule(stages, *dataset, state.holdout, state.held_out_views);
    }
    SFT_RETURN_IF_ERROR(CheckOutputDirectory(cli->out, {{cli->dataset}, {}}, "--resume"));
    SFT_RETURN_IF_ERROR(UnknownLighting(cli->resume, EnvironmentEstimateOptions(), *cli, dataset));
    if (before_start) SFT_RETURN_IF_ERROR(before_start(cli->dataset, *dataset, stages));
    SFT_RETURN_IF_ERROR(Schedule::Resume(*dataset, cli->out, stages, state.run_info, state.progress,
                                         state.view_gains, schedule));
    (*schedule)->SetHeldOut(state.holdout, state.held_out_views);
    return Status::Ok();
  }
  if (cli->dataset.empty() || (cli->out.empty() && !cli->print_schedule)) {
    return Status::Error("--dataset and --out are required (or --resume OUT)");
  }
  SFT_RETURN_IF_ERROR(ReadDataset(cli->dataset, dataset));
  StartChoice start;
  SFT_RETURN_IF_ERROR(ChooseStart(*dataset, cli->init, &start));
  ScheduleConfig config;
  SFT_RETURN_IF_ERROR(FreshStages(*cli, start, &config, &stages));
  if (config.environment.find_lamp && !config.environment_stage) {
    return Status::Error("find_lamp: needs the environment stage (environment_stage is false)");
  }
  if (LightingUnknown(*dataset) && config.environment_stage) {
    StageOptions environment;
    SFT_RETURN_IF_ERROR(EnvironmentStage(config, stages.front(), &environment));
    stages.insert(stages.begin(), std::move(environment));
  }
  std::vector<int> held_out;
  SFT_RETURN_IF_ERROR(ApplyHoldout(config.holdout, config.flat.value("views", std::vector<int>()),
                                   static_cast<int>(dataset->views.size()), &stages, &held_out));
  if (cli->print_schedule) return PrintSchedule(stages, *dataset, config.holdout, held_out);
  const RunInputs inputs{{cli->dataset},
                         {start.path, MaterialFile(cli->material), cli->config, cli->reference}};
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(cli->out, inputs, "--out"));
  if (FileExists(JoinPath(cli->out, "state.json"))) {
    return Status::Error("--out " + cli->out +
                         ": holds an earlier reconstruction (continue it with --resume " +
                         cli->out + ", or choose another folder)");
  }
  SFT_RETURN_IF_ERROR(UnknownLighting("", config.environment, *cli, dataset));
  ScheduleStart state;
  std::string start_line;
  SFT_RETURN_IF_ERROR(
      LoadStartMesh(*dataset, start, config.carve, &state.mesh, held_out, &start_line));
  if (!cli->quiet) {
    std::printf("%s\n", start_line.c_str());
    std::fflush(stdout);  // before the progress lines on stderr.
  }
  SFT_RETURN_IF_ERROR(LoadMaterial(cli->material.empty() ? kInitialMaterial : cli->material,
                                   state.mesh, &state.material));
  if (config.environment.find_lamp) {
    SFT_RETURN_IF_ERROR(FindLampForRun(*cli, config.environment, stages.front(), state, dataset));
  }
  const nlohmann::json run_info = {
      {"dataset", cli->dataset},
      {"start", start.Describe()},
      {"init", start.path},
      {"material", cli->material},
      {"config", config.flat},
      {"schedule", config.stages.is_null() ? config.schedule : "explicit"},
      {"carve", config.carve_keys}};
  if (before_start) SFT_RETURN_IF_ERROR(before_start(cli->dataset, *dataset, stages));
  SFT_RETURN_IF_ERROR(Schedule::Start(*dataset, cli->out, stages, state, run_info, schedule));
  (*schedule)->SetHeldOut(config.holdout, held_out);
  return Status::Ok();
}

// OUT/export/ (ExportFinishedRun) for the report's 3D view and for other programs. A failed export
// does not fail the run, whose results are written: one line says why, and the report shows it.
ReportModel ExportAsset(const std::string& out, const Dataset& dataset, bool stopped) {
  ReportModel model;
  if (stopped) {
    model.missing = "the run was interrupted; sft export --reconstruction " + out +
                    " writes the asset of the state it reached";
    return model;
  }
  nlohmann::json summary;
  const Status exported = ExportFinishedRun(out, dataset, &summary);
  if (!exported.ok()) {
    model.missing = "the export failed: " + exported.message();
    std::fprintf(stderr, "sft reconstruct: warning: %s\n", model.missing.c_str());
    return model;
  }
  model.viewer.export_dir = kRunExportDir;
  const std::string start = JoinPath(out, "initial_mesh.ply");
  if (FileExists(start)) model.viewer.start_mesh = start;
  return model;
}

// `stop`, when given, is asked after every solver iteration too: true stops the run as Ctrl-C
// does. *stopped: whether the run stopped early (and wrote its checkpoint).
Status RunReconstruct(const ReconstructCommandOptions& cli_in, const BeforeStart& before_start = {},
                      const std::function<nlohmann::json()>& extra_metrics = {},
                      const std::function<bool()>& stop = {}, bool* stopped = nullptr) {
  ReconstructCommandOptions cli = cli_in;
  // The reference first: a bad one must not leave an output folder behind.
  TriMesh reference;
  if (!cli.reference.empty()) SFT_RETURN_IF_ERROR(ReadMesh(cli.reference, &reference));
  Dataset dataset;
  std::unique_ptr<Schedule> schedule;
  SFT_RETURN_IF_ERROR(PrepareSchedule(&cli, &dataset, before_start, &schedule));
  if (!schedule) return Status::Ok();  // --print-schedule.
  if (extra_metrics) schedule->SetExtraMetrics(extra_metrics);
  // The ETA prices LM and Adam steps, texture and geometry phases, each at its own rate.
  Progress progress("reconstruct", schedule->RemainingWorkByKind(), !cli.quiet);
  ScheduleCallbacks callbacks;
  callbacks.on_iteration = [&](const IterationRecord& record) {
    progress.SetDetail(record.stage);
    if (!record.full) {  // not a step.
      progress.Advance(schedule->CurrentStepWork(),
                       Schedule::WorkKindOf(schedule->CurrentStage(), record.phase));
    }
    return !g_interrupted.load() && !(stop && stop());
  };
  callbacks.on_event = [&](const std::string& line) { progress.Note(line); };
  if (!cli.reference.empty()) {
    callbacks.score = [&](const TriMesh& mesh, nlohmann::json* out) {
      return ScoreAgainstReference(reference, cli.reference_tolerance, mesh, "--reference", out);
    };
  }
  SFT_RETURN_IF_ERROR(schedule->Run(callbacks));
  progress.Finish();
  if (!cli.no_report && schedule->reconstruction() != nullptr) {
    const ReportModel model = ExportAsset(cli.out, dataset, schedule->stopped());
    SFT_RETURN_IF_ERROR(
        WriteReconstructReport(cli.out, dataset, schedule->records(), schedule->reconstruction(),
                               schedule->outer_records(), schedule->stage_records(), model));
  }
  const ScheduleProgress& p = schedule->progress();
  if (stopped != nullptr) *stopped = schedule->stopped();
  if (schedule->stopped()) {
    return Status::Error("interrupted after " + std::to_string(p.outer_done) +
                         " outer iterations; state written to " + cli.out +
                         " (continue with --resume " + cli.out + ")");
  }
  std::printf("sft reconstruct: %d outer iterations, %.1f s; mesh %s, report %s, asset %s\n",
              p.outer_done, p.seconds, JoinPath(cli.out, "mesh.ply").c_str(),
              cli.no_report ? "(none)" : JoinPath(cli.out, "report.html").c_str(),
              cli.no_report ? "(none)" : JoinPath(cli.out, kRunExportDir).c_str());
  return Status::Ok();
}

// The smallest number of views any stage fits.
int FittedViews(const Dataset& dataset, const std::vector<StageOptions>& stages) {
  int fitted = INT_MAX;
  for (const StageOptions& stage : stages) {
    const size_t n = stage.fit.views.empty() ? dataset.views.size() : stage.fit.views.size();
    fitted = std::min(fitted, static_cast<int>(n));
  }
  return fitted;
}

// `sft reconstruct` under mpirun (src/optim/mpi_views.h): rank 0 runs the schedule with its
// renders spread over the ranks; the others serve renders. Errors print on rank 0 only; every
// rank exits non-zero when the ranks do not agree to start (the handshake). A fault (a rank that
// died or stopped answering, or the launcher's SIGTERM) stops the run after the current solver
// iteration, its renders finished on rank 0; rank 0 writes the checkpoint, prints one line and
// ends every rank.
int RunReconstructMpi(const ReconstructCommandOptions& cli) {
  std::unique_ptr<MpiSession> session;
  Status status = MpiSession::Start(&session);
  if (!status.ok()) {
    PrintError("reconstruct", status);
    return 1;
  }
  if (session->rank() != 0) {
    Dataset dataset;
    status = MpiHandshake(*session, Status::Ok(), "", 0, &dataset);
    if (status.ok()) status = ServeViews(*session, dataset);
    return status.ok() ? 0 : 1;
  }
  std::unique_ptr<MpiViewRunner> runner;
  bool agreed = false;
  const BeforeStart before_start = [&](const std::string& path, const Dataset& dataset,
                                       const std::vector<StageOptions>& stages) {
    agreed = true;
    // The workers read the dataset from its path and add the estimated lights sent here; the
    // fitted map comes with the first state.
    SFT_RETURN_IF_ERROR(MpiHandshake(*session, Status::Ok(), path, FittedViews(dataset, stages),
                                     nullptr, EstimatedLights(dataset)));
    g_terminating = false;
    std::signal(SIGTERM, OnTerminate);  // from now on a SIGTERM stops the run as a fault.
    runner = std::make_unique<MpiViewRunner>(*session, cli.mpi_timeout, &g_terminating);
    if (session->size() > 1) SetViewRunner(runner.get());
    return Status::Ok();
  };
  const auto metrics = [&]() {
    return runner ? nlohmann::json{{"mpi", MpiViewStatsJson(runner->stats())}} : nlohmann::json{};
  };
  const auto fault = [&]() { return runner && runner->failed(); };
  bool stopped = false;
  if (!(cli.mpi_timeout > 0.0)) {
    status = Status::Error("--mpi-timeout: must be > 0 seconds");
  } else {
    status = RunReconstruct(cli, before_start, metrics, fault, &stopped);
  }
  SetViewRunner(nullptr);
  if (fault()) {
    // The workers cannot be released (one is gone or silent): one line, then every rank ends.
    const std::string out = cli.resume.empty() ? cli.out : cli.resume;
    if (stopped) {
      status = Status::Error(runner->failure() + "; state written to " + out +
                             " (continue with --resume " + out + ", with any number of ranks)");
    } else if (status.ok()) {
      status = Status::Error(runner->failure() + " after the run had finished (every output in " +
                             out + " is written)");
    }
    PrintError("reconstruct", status);
    std::fflush(nullptr);
    session->Abort(1);
  }
  std::signal(SIGTERM, SIG_DFL);
  if (!agreed) {
    // Stopped before the run (a usage error, or --print-schedule): the workers are released
    // through the handshake, with rank 0's error.
    const Status verdict = MpiHandshake(*session, status, cli.dataset, INT_MAX, nullptr);
    if (verdict.ok()) MpiViewRunner(*session, cli.mpi_timeout).Stop();
  }
  if (runner) runner->Stop();
  if (status.ok()) return 0;
  PrintError("reconstruct", status);
  return g_interrupted ? 130 : 1;
}

}  // namespace

CommandRunner SetupReconstructCommand(CLI::App* app) {
  auto opts = std::make_shared<ReconstructCommandOptions>();
  app->add_option("--dataset", opts->dataset, "Dataset directory (sft-dataset/1)");
  app->add_option("--init", opts->init,
                  "Initial mesh (OBJ, PLY, OFF); default: the dataset's initial_mesh, else a "
                  "hull carved from the masks");
  app->add_option("--out", opts->out, "Output directory");
  app->add_option("--resume", opts->resume, "Continue the run whose output directory is this");
  app->add_option("--config", opts->config,
                  "Config JSON: flat keys and stages (docs/reconstruct.md); flags override it");
  app->add_option("--material", opts->material,
                  "Initial material (JSON file or inline); default: albedo 0.5, roughness 0.5");
  // Flags that override config keys in every stage: recorded as given only when on the command
  // line.
  const auto key_flag = [&](CLI::Option* option, const std::string& key) {
    option->each([opts, key](const std::string&) { opts->given.insert(key); });
  };
  key_flag(app->add_option("--phases", opts->phases, "texture | geometry | alternate"), "phases");
  key_flag(app->add_option("--solver", opts->solver, "lm | dogleg | lbfgs | adam"), "solver");
  key_flag(app->add_option("--outer", opts->outer, "Outer iterations of every stage"),
           "outer_iterations");
  key_flag(
      app->add_option("--steps", opts->steps, "Solver iterations per outer iteration and phase"),
      "steps");
  key_flag(app->add_option("--spp", opts->spp, "Samples per pixel of the fit's renders"), "spp");
  key_flag(app->add_option("--bounces", opts->bounces, "Path segments"), "bounces");
  key_flag(app->add_option("--effects", opts->effects,
                           "auto (the effect planner chooses; default) or a fixed list: "
                           "direct,shadows,bounces,specular,environment | all"),
           "effects");
  key_flag(app->add_option("--threads", opts->threads, "Render threads (0 = all cores)"),
           "threads");
  key_flag(app->add_option("--seed", opts->seed, "Base seed"), "seed");
  key_flag(app->add_option("--views", opts->views, "Only these view indices (comma-separated)")
               ->delimiter(','),
           "views");
  key_flag(app->add_option("--holdout", opts->holdout,
                           "Keep every K-th selected view (0, K, 2K, ...) out of the fit, for "
                           "sft eval --held-out; 0 = off"),
           "holdout");
  key_flag(app->add_option("--environment-frame", opts->environment_frame,
                           "Unknown lighting: fit an environment fixed in the world (lights in "
                           "the room; default) or in the camera (lights riding with it)"),
           "environment_frame");
  key_flag(app->add_option("--estimate-lights", opts->estimate_lights,
                           "Unknown lighting: a lights file ({\"lights\": [...]}, scene.json's "
                           "format) of point or directional lights whose place is roughly known, "
                           "fitted beside the environment"),
           "estimate_lights");
  key_flag(app->add_flag("--find-lamp", opts->find_lamp,
                         "Unknown lighting, no lamp given: fit the environment alone first and "
                         "start a point lamp in its brightest direction, fitted beside the map"),
           "find_lamp");
  app->add_option("--reference", opts->reference,
                  "Ground-truth mesh: F1 and Chamfer after every outer iteration (metrics.json)");
  app->add_option("--reference-tolerance", opts->reference_tolerance,
                  "F1 tolerance of --reference, fraction of its bounding-box diagonal")
      ->capture_default_str();
  app->add_flag("--print-schedule", opts->print_schedule,
                "Print the effective stage list and exit (nothing is written)");
  app->add_flag("--quiet", opts->quiet, "No progress line");
  app->add_flag("--no-report", opts->no_report, "Do not write OUT/report.html");
  app->add_option("--mpi-timeout", opts->mpi_timeout,
                  "Under mpirun: seconds rank 0 waits for another rank's renders before it stops "
                  "the run (checkpoint written, every rank ended)")
      ->capture_default_str();
  return [opts]() {
    // First, so that an interrupt at any point stops cleanly (a checkpoint exists only once the
    // first outer iteration has run; the message says so).
    g_interrupted = false;
    std::signal(SIGINT, OnInterrupt);
    if (MpiSession::Launched()) {
      const int code = RunReconstructMpi(*opts);
      std::signal(SIGINT, SIG_DFL);
      return code;
    }
    const Status status = RunReconstruct(*opts);
    std::signal(SIGINT, SIG_DFL);
    if (status.ok()) return 0;
    PrintError("reconstruct", status);
    return g_interrupted ? 130 : 1;
  };
}

}  // namespace sft
