#include "src/eval/reconstruct_cost.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <utility>

#include "src/core/memory.h"

namespace sft {
namespace {

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Seconds of one solver iteration: everything after the solver's start-up, per iteration.
double SecondsPerIteration(const SolverRunStats& stats) {
  const SolverTimeSplit& t = stats.time;
  const double loop = t.render + t.pyramid + t.evaluation + t.linear_solver + t.other;
  return loop / std::max(1, stats.iterations);
}

}  // namespace

bool ReconstructCostOptions::Check(std::string* why) const { return reconstruct.Check(why); }

Status MeasureReconstructCost(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                              const ReconstructCostOptions& options,
                              ReconstructCostReport* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  *report = ReconstructCostReport();
  ResetPeakResidentSet();
  auto start = std::chrono::steady_clock::now();
  std::unique_ptr<Reconstruction> reconstruction;
  SFT_RETURN_IF_ERROR(
      Reconstruction::Create(dataset, mesh, material, {}, options.reconstruct, &reconstruction));
  report->create_seconds = Seconds(start);

  // The baseline: the forward pass alone, same spp, bounces and threads, another seed.
  start = std::chrono::steady_clock::now();
  const std::vector<Image> images = reconstruction->RenderViews(options.reconstruct.seed + 99991);
  report->forward_seconds = Seconds(start);
  for (const Image& image : images) report->pixels += int64_t{image.width} * image.height;

  bool first = true;
  const auto on_iteration = [&](const IterationRecord& record) {
    if (first) report->cost_before = record.cost;
    first = false;
    report->cost_after = record.cost;
    report->accepted_steps += record.accepted && record.iteration > 0 && !record.full;
    if (options.progress) {
      std::fprintf(stderr, "bench reconstruct: %s iteration %d cost %.6g %s (%.1f s)\n",
                   record.phase.c_str(), record.iteration, record.cost,
                   record.accepted ? "accepted" : "rejected", record.seconds);
    }
    return true;
  };
  SFT_RETURN_IF_ERROR(reconstruction->RunOuter(0, on_iteration));
  report->phases_run = reconstruction->phases();
  report->rows_bytes = static_cast<int64_t>(reconstruction->cache().RowMemoryBytes());
  report->peak_rss_bytes = ProcessStatusBytes("VmHWM:");

  const ReconstructOptions& o = options.reconstruct;
  report->views = static_cast<int>(reconstruction->view_indices().size());
  report->vertices = static_cast<int>(mesh.n_vertices());
  report->faces = static_cast<int>(mesh.n_faces());
  report->spp = o.cache.render.spp;
  report->bounces = o.cache.render.bounces;
  report->threads = o.cache.render.threads;
  report->solver = SolverKindName(o.solver.kind);
  report->phases = PhaseScheduleName(o.phases);
  return Status::Ok();
}

std::string ReconstructCostTable(const ReconstructCostReport& report) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof(line),
                "%d views, %lld pixels, %d vertices, %d faces, %d spp, %d bounces; solver %s\n"
                "forward render of every view (baseline): %.2f s; setup (targets, scene): %.2f s\n",
                report.views, static_cast<long long>(report.pixels), report.vertices, report.faces,
                report.spp, report.bounces, report.solver.c_str(), report.forward_seconds,
                report.create_seconds);
  out += line;
  for (const PhaseRecord& phase : report.phases_run) {
    const SolverRunStats& s = phase.stats;
    const double per_iteration = SecondsPerIteration(s);
    std::snprintf(line, sizeof(line),
                  "%s: %d iterations, %d evaluations, %.2f s; %.2f s per iteration = %.2f× the "
                  "forward render\n",
                  phase.phase.c_str(), s.iterations, s.evaluations, s.seconds, per_iteration,
                  per_iteration / std::max(1e-9, report.forward_seconds));
    out += line;
    for (const auto& [name, seconds] : TimeSplitParts(s.time)) {
      std::snprintf(line, sizeof(line), "  %-17s %9.2f s %6.1f%%\n", name, seconds,
                    100.0 * seconds / std::max(1e-9, s.seconds));
      out += line;
    }
    if (s.problem.residual_blocks > 0) {
      std::snprintf(line, sizeof(line),
                    "  problem: %lld residual blocks, %lld parameter blocks, %lld superset "
                    "entries; dropped Jacobian mass %.2f%%\n",
                    static_cast<long long>(s.problem.residual_blocks),
                    static_cast<long long>(s.problem.parameter_blocks),
                    static_cast<long long>(s.problem.superset_entries),
                    100.0 * s.dropped_jacobian_fraction);
      out += line;
    }
  }
  std::snprintf(line, sizeof(line),
                "cost %.6g -> %.6g (%d accepted steps); rows %s; peak resident set %s\n",
                report.cost_before, report.cost_after, report.accepted_steps,
                FormatBytes(report.rows_bytes).c_str(),
                report.peak_rss_bytes > 0 ? FormatBytes(report.peak_rss_bytes).c_str() : "unknown");
  out += line;
  return out;
}

nlohmann::json ReconstructCostToJson(const ReconstructCostReport& report) {
  nlohmann::json phases = nlohmann::json::array();
  for (const PhaseRecord& phase : report.phases_run) {
    const SolverRunStats& s = phase.stats;
    nlohmann::json split = nlohmann::json::object();
    for (const auto& [name, seconds] : TimeSplitParts(s.time)) split[name] = seconds;
    const double per_iteration = SecondsPerIteration(s);
    phases.push_back(
        {{"phase", phase.phase},
         {"iterations", s.iterations},
         {"evaluations", s.evaluations},
         {"seconds", s.seconds},
         {"seconds_per_iteration", per_iteration},
         {"iteration_over_forward", per_iteration / std::max(1e-9, report.forward_seconds)},
         {"time_split", split},
         {"residual_blocks", s.problem.residual_blocks},
         {"parameter_blocks", s.problem.parameter_blocks},
         {"superset_entries", s.problem.superset_entries},
         {"dropped_jacobian_fraction", s.dropped_jacobian_fraction},
         {"termination", s.termination}});
  }
  return {{"views", report.views},
          {"pixels", report.pixels},
          {"vertices", report.vertices},
          {"faces", report.faces},
          {"spp", report.spp},
          {"bounces", report.bounces},
          {"threads", report.threads},
          {"solver", report.solver},
          {"phases", report.phases},
          {"create_seconds", report.create_seconds},
          {"forward_seconds", report.forward_seconds},
          {"phase_runs", phases},
          {"cost_before", report.cost_before},
          {"cost_after", report.cost_after},
          {"accepted_steps", report.accepted_steps},
          {"rows_bytes", report.rows_bytes},
          {"peak_rss_bytes", report.peak_rss_bytes}};
}

}  // namespace sft
