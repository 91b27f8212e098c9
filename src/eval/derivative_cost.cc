#include "src/eval/derivative_cost.h"

#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "src/core/memory.h"
#include "src/core/progress.h"
#include "src/core/rng.h"
#include "src/geometry/material.h"
#include "src/io/scene_setup.h"
#include "src/render/camera_rig.h"
#include "src/render/scene.h"

namespace sft {
namespace {

// Camera placement and light as `sft synth`'s defaults (apps/synth_command.cc).
constexpr double kFovDeg = 40.0;
constexpr double kFill = 0.6;
constexpr double kLightOffset = 0.15;  // along the camera's +x, in bounding-box diagonals.
constexpr int kNumLights = 1;          // the one camera-attached light (light scale parameter 0).

// The material: random per-texel albedo, constant roughness and specular.
constexpr int kMaterialResolution = 2;
constexpr double kAlbedoMin = 0.2;
constexpr double kAlbedoMax = 0.9;
constexpr double kRoughness = 0.4;
constexpr double kSpecular = 0.3;

// Streams of the hashed random numbers (albedo texels, adjoint weights).
constexpr uint64_t kAlbedoStream = 0xA1BED0ull;
constexpr uint64_t kWeightStream = 0x3E1647ull;

constexpr double kAim = 3.0;  // issue 3 item 6: either derivative pass ≤ 3× the forward time.

// A uniform number in [0, 1) that is a pure function of (seed, stream, index).
double UnitHash(uint64_t seed, uint64_t stream, uint64_t index) {
  return static_cast<double>(Mix64(Mix64(Mix64(seed) ^ stream) ^ index) >> 11) * 0x1.0p-53;
}

template <typename F>
double WallSeconds(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void AddRays(const RenderStats& stats, RenderStats* sum) {
  sum->camera_rays += stats.camera_rays;
  sum->shadow_rays += stats.shadow_rays;
  sum->bounce_rays += stats.bounce_rays;
  sum->seconds += stats.seconds;
}

// The cameras and lights (see the header comment).
std::vector<ViewSetup> MakeViews(const TriMesh& mesh, const DerivativeCostOptions& options) {
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const Eigen::Vector3d target = 0.5 * (lo + hi);
  const double diagonal = (hi - lo).norm();
  const double distance = OrbitDistance(0.5 * diagonal, kFovDeg, kFill);
  const double focal = OrbitFocal(options.resolution, kFovDeg);
  const Eigen::Vector3d up(0, 0, 1);
  std::vector<ViewSetup> views(options.views);
  for (int k = 0; k < options.views; ++k) {
    ViewSetup& view = views[k];
    view.camera.id = "bench";
    view.camera.model = CameraModel::kPinhole;
    view.camera.width = view.camera.height = options.resolution;
    view.camera.params = {focal, focal, 0.5 * options.resolution, 0.5 * options.resolution};
    view.cam_from_world =
        LookAt(target + distance * FibonacciSphereDirection(k, options.views), target, up);
    view.view_index = static_cast<uint64_t>(k);
    PointLight light;
    light.position =
        view.cam_from_world.Inverse() * Eigen::Vector3d(kLightOffset * diagonal, 0.0, 0.0);
    light.intensity = Eigen::Vector3d::Constant(0.5 * M_PI * distance * distance);
    light.light_index = 0;
    view.point_lights.push_back(light);
  }
  return views;
}

Material MakeMaterial(const TriMesh& mesh, uint64_t seed) {
  Material material = ConstantMaterial(static_cast<int>(mesh.n_faces()),
                                       Eigen::Vector3d::Constant(0.5 * (kAlbedoMin + kAlbedoMax)),
                                       kRoughness, kSpecular, kMaterialResolution);
  std::vector<double>& albedo = material.albedo.values();
  for (size_t i = 0; i < albedo.size(); ++i) {
    albedo[i] = kAlbedoMin + (kAlbedoMax - kAlbedoMin) * UnitHash(seed, kAlbedoStream, i);
  }
  return material;
}

// The adjoint weights: uniform in [−1, 1] per pixel and channel.
Image MakeWeights(int width, int height, uint64_t seed) {
  Image weights(width, height, 3);
  for (size_t i = 0; i < weights.data.size(); ++i) {
    weights.data[i] = static_cast<float>(2.0 * UnitHash(seed, kWeightStream, i) - 1.0);
  }
  return weights;
}

nlohmann::json PassJson(const DerivativePassCost& pass) {
  return {{"seconds", pass.seconds},
          {"ratio_to_forward", pass.ratio},
          {"camera_rays", pass.rays.camera_rays},
          {"shadow_rays", pass.rays.shadow_rays},
          {"bounce_rays", pass.rays.bounce_rays},
          {"renderer_seconds", pass.rays.seconds},
          {"rss_before_bytes", pass.rss_before_bytes},
          {"peak_rss_bytes", pass.peak_rss_bytes}};
}

double Mebibytes(int64_t bytes) { return bytes / (1024.0 * 1024.0); }

}  // namespace

bool DerivativeCostOptions::Check(std::string* why) const {
  if (views < 1 || views > 10000) {
    *why = "views: must be in [1, 10000], got " + std::to_string(views);
    return false;
  }
  if (resolution < 1 || resolution > 4096) {
    *why = "res: must be in [1, 4096], got " + std::to_string(resolution);
    return false;
  }
  if (noise_seeds != 0 && (noise_seeds < 2 || noise_seeds > 64)) {
    *why = "noise-seeds: must be 0 or in [2, 64], got " + std::to_string(noise_seeds);
    return false;
  }
  if (!derivatives.Check(why)) return false;
  RenderOptions render;
  render.spp = spp;
  render.bounces = bounces;
  render.threads = threads;
  return render.Check(why);
}

namespace {

// What the three passes render: a scene, its material and views, and the lights' count.
struct CostScene {
  const RenderScene* scene;
  const Material* material;
  const std::vector<ViewSetup>* views;
  int num_lights;
};

// Resets the peak before a pass; EndPass reads it.
void BeginPass(DerivativeCostReport* result, DerivativePassCost* cost) {
  result->peak_rss_reset = ResetPeakResidentSet();
  cost->rss_before_bytes = ProcessStatusBytes("VmRSS:");
}
void EndPass(DerivativePassCost* cost) { cost->peak_rss_bytes = ProcessStatusBytes("VmHWM:"); }

// (1) Forward only.
void ForwardPass(const CostScene& s, const RenderOptions& render, bool progress_lines,
                 DerivativeCostReport* result) {
  BeginPass(result, &result->forward);
  Progress progress("forward", static_cast<int64_t>(s.views->size()), progress_lines);
  for (const ViewSetup& view : *s.views) {
    Image image;
    RenderStats stats;
    result->forward.seconds +=
        WallSeconds([&] { RenderView(*s.scene, *s.material, view, render, &image, &stats); });
    AddRays(stats, &result->forward.rays);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) result->covered_pixels += image.at(x, y, 3) > 0.f;
    }
    progress.Advance();
  }
  progress.Finish();
  EndPass(&result->forward);
}

// (2) Forward + Jacobian rows; the rows of a view are freed before the next unless kept.
void RowsPass(const CostScene& s, const RenderOptions& render, const DerivativeRequest& request,
              const DerivativeCostOptions& options, DerivativeCostReport* result) {
  BeginPass(result, &result->jacobian_rows);
  std::vector<DerivativeOutput> kept;
  if (options.keep_rows) kept.reserve(s.views->size());
  Progress progress("jacobian rows", static_cast<int64_t>(s.views->size()), options.progress);
  for (const ViewSetup& view : *s.views) {
    Image image;
    DerivativeOutput output;
    RenderStats stats;
    result->jacobian_rows.seconds += WallSeconds([&] {
      RenderViewWithDerivatives(*s.scene, *s.material, view, render, request, s.num_lights, &image,
                                &output, &stats);
    });
    AddRays(stats, &result->jacobian_rows.rays);
    result->num_parameters = output.layout.size();
    result->num_differentiated = output.layout.size();
    const int64_t bytes = static_cast<int64_t>(output.rows.MemoryBytes());
    result->jacobian_entries += static_cast<int64_t>(output.rows.entries.size());
    result->rows_bytes_total += bytes;
    result->rows_bytes_peak_view = std::max(result->rows_bytes_peak_view, bytes);
    if (options.keep_rows) kept.push_back(std::move(output));
    progress.Advance();
  }
  progress.Finish();
  EndPass(&result->jacobian_rows);  // with keep_rows, every view's rows are still alive here.
  result->rows_bytes_resident =
      options.keep_rows ? result->rows_bytes_total : result->rows_bytes_peak_view;
}

// Σ_views Jᵀw of the adjoint request with fixed random weights of each view's size (seeded by
// options.seed), rendered with `render`'s seed; adds the render time and rays to *cost and,
// when `terms` is given, the stored adjoint terms to its counts.
std::vector<double> AdjointGradient(const CostScene& s, const RenderOptions& render,
                                    DerivativeRequest request, const DerivativeCostOptions& options,
                                    const char* label, DerivativePassCost* cost,
                                    DerivativeCostReport* terms = nullptr) {
  std::vector<double> gradient;
  Progress progress(label, static_cast<int64_t>(s.views->size()), options.progress);
  for (const ViewSetup& view : *s.views) {
    const Image weights = MakeWeights(view.camera.width, view.camera.height, options.seed);
    request.adjoint_weights = &weights;
    Image image;
    DerivativeOutput output;
    RenderStats stats;
    cost->seconds += WallSeconds([&] {
      RenderViewWithDerivatives(*s.scene, *s.material, view, render, request, s.num_lights, &image,
                                &output, &stats);
    });
    AddRays(stats, &cost->rays);
    if (terms != nullptr) {
      terms->gradient_terms += stats.gradient_terms;
      terms->gradient_terms_peak_view =
          std::max(terms->gradient_terms_peak_view, stats.gradient_terms);
    }
    if (gradient.empty()) gradient.assign(output.gradient.size(), 0.0);
    for (size_t i = 0; i < gradient.size() && i < output.gradient.size(); ++i) {
      gradient[i] += output.gradient[i];
    }
    progress.Advance();
  }
  progress.Finish();
  return gradient;
}

// (3) Forward + adjoint gradient for fixed random weights.
void AdjointPass(const CostScene& s, const RenderOptions& render, const DerivativeRequest& request,
                 const DerivativeCostOptions& options, DerivativeCostReport* result) {
  BeginPass(result, &result->adjoint);
  const std::vector<double> gradient =
      AdjointGradient(s, render, request, options, "adjoint", &result->adjoint, result);
  EndPass(&result->adjoint);
  double sum2 = 0.0;
  for (double g : gradient) sum2 += g * g;
  result->gradient_norm = std::sqrt(sum2);
}

// The noise measurement (DerivativeCostOptions::noise_seeds): the vertex part of the adjoint
// gradient over several render seeds.
void NoisePasses(const CostScene& s, RenderOptions render, const DerivativeRequest& request,
                 const DerivativeCostOptions& options, DerivativeCostReport* result) {
  const int n = options.noise_seeds;
  const size_t num_vertex = 3 * s.scene->positions().size();
  std::vector<std::vector<double>> gradients;
  DerivativePassCost cost;
  double forward_seconds = 0.0;
  for (int k = 0; k < n; ++k) {
    render.seed = options.seed + 1 + static_cast<uint64_t>(k);
    // A forward pass with the same seed next to each adjoint pass: the ratio of the means is
    // then not at the mercy of one forward timing (single passes scatter by ±10% here).
    for (const ViewSetup& view : *s.views) {
      Image image;
      forward_seconds +=
          WallSeconds([&] { RenderView(*s.scene, *s.material, view, render, &image); });
    }
    std::vector<double> g = AdjointGradient(s, render, request, options, "noise", &cost);
    g.resize(num_vertex);  // the vertex coordinates come first in the layout.
    gradients.push_back(std::move(g));
  }
  std::vector<double> mean(num_vertex, 0.0);
  for (const auto& g : gradients) {
    for (size_t i = 0; i < num_vertex; ++i) mean[i] += g[i] / n;
  }
  double spread2 = 0.0, mean2 = 0.0;
  for (size_t i = 0; i < num_vertex; ++i) mean2 += mean[i] * mean[i];
  for (const auto& g : gradients) {
    for (size_t i = 0; i < num_vertex; ++i) spread2 += (g[i] - mean[i]) * (g[i] - mean[i]);
  }
  result->noise_seeds = n;
  // E‖ḡ‖² = ‖E g‖² + tr(Cov)/N, and spread2/(N − 1) estimates tr(Cov): the noise is relative to
  // the unbiased estimate of ‖E g‖² (all configurations of unbiased estimators share E g).
  const double trace = spread2 / (n - 1);
  const double signal2 = mean2 - trace / n;
  result->vertex_noise = signal2 > 0.0 ? std::sqrt(trace / signal2) : 0.0;
  result->noise_adjoint_seconds = cost.seconds / n;
  result->noise_forward_seconds = forward_seconds / n;
}

// The three passes over `s`; `result` already holds the setup fields.
Status MeasureScene(const CostScene& s, const DerivativeCostOptions& options,
                    DerivativeCostReport* result) {
  {
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    arena.initialize();
    result->threads = arena.max_concurrency();
  }
  result->spp = options.spp;
  result->bounces = options.bounces;
  result->keep_rows = options.keep_rows;
  result->derivatives = options.derivatives;
  result->derivatives.adjoint_weights = nullptr;
  RenderOptions render;
  render.spp = options.spp;
  render.bounces = options.bounces;
  render.seed = options.seed;
  render.threads = options.threads;

  // Every parameter kind, vertices (and edge sampling) included.
  DerivativeRequest rows_request = options.derivatives;
  rows_request.params = ParameterSelection();
  rows_request.params.vertices = true;
  rows_request.jacobian_rows = true;
  rows_request.adjoint_weights = nullptr;
  DerivativeRequest adjoint_request = rows_request;
  adjoint_request.jacobian_rows = false;
  const Image probe(1, 1, 3);  // Check needs weights; the pass sets each view's own.
  adjoint_request.adjoint_weights = &probe;
  std::string why;
  if (!rows_request.Check(&why) || !adjoint_request.Check(&why)) {
    return Status::Error("derivative request: " + why);
  }

  // Untimed warm-up (thread pool, first touch of the scene) so the forward pass is not charged.
  {
    Image image;
    RenderView(*s.scene, *s.material, s.views->front(), render, &image);
  }
  ForwardPass(s, render, options.progress, result);
  RowsPass(s, render, rows_request, options, result);
  AdjointPass(s, render, adjoint_request, options, result);
  if (options.noise_seeds > 0) NoisePasses(s, render, adjoint_request, options, result);

  const double forward = result->forward.seconds;
  result->forward.ratio = forward > 0.0 ? 1.0 : 0.0;
  result->jacobian_rows.ratio = forward > 0.0 ? result->jacobian_rows.seconds / forward : 0.0;
  result->adjoint.ratio = forward > 0.0 ? result->adjoint.seconds / forward : 0.0;
  if (result->noise_seeds > 0 && result->noise_forward_seconds > 0.0) {
    result->cost_times_variance = result->noise_adjoint_seconds / result->noise_forward_seconds *
                                  result->vertex_noise * result->vertex_noise;
  }
  return Status::Ok();
}

}  // namespace

Status MeasureDerivativeCost(const DerivativeCostOptions& options, const TriMesh& mesh,
                             DerivativeCostReport* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (mesh.n_faces() == 0) return Status::Error("mesh: has no faces");
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  if (!((hi - lo).norm() > 0.0)) return Status::Error("mesh: has zero extent");

  DerivativeCostReport result;
  result.num_faces = static_cast<int>(mesh.n_faces());
  result.num_vertices = static_cast<int>(mesh.n_vertices());
  result.views = options.views;
  result.width = result.height = options.resolution;
  const RenderScene scene(mesh);
  const Material material = MakeMaterial(mesh, options.seed);
  const std::vector<ViewSetup> views = MakeViews(mesh, options);
  SFT_RETURN_IF_ERROR(MeasureScene({&scene, &material, &views, kNumLights}, options, &result));
  *report = result;
  return Status::Ok();
}

Status MeasureDatasetDerivativeCost(const DerivativeCostOptions& options, const Dataset& dataset,
                                    const std::vector<int>& view_indices, const TriMesh& mesh,
                                    const Material& material, DerivativeCostReport* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (mesh.n_faces() == 0) return Status::Error("mesh: has no faces");
  DatasetViews all;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &all));
  std::vector<int> selected;
  SFT_RETURN_IF_ERROR(SelectViews(view_indices, static_cast<int>(all.views.size()), &selected));
  std::vector<ViewSetup> views;
  for (int v : selected) views.push_back(all.views[v]);

  DerivativeCostReport result;
  result.num_faces = static_cast<int>(mesh.n_faces());
  result.num_vertices = static_cast<int>(mesh.n_vertices());
  result.views = static_cast<int>(views.size());
  result.width = views.front().camera.width;  // of the first view (datasets may mix sizes).
  result.height = views.front().camera.height;
  const RenderScene scene(mesh);
  SFT_RETURN_IF_ERROR(MeasureScene(
      {&scene, &material, &views, static_cast<int>(dataset.lights.size())}, options, &result));
  *report = result;
  return Status::Ok();
}

nlohmann::json DerivativeCostReportToJson(const DerivativeCostReport& report) {
  nlohmann::json json;
  json["mesh_faces"] = report.num_faces;
  json["mesh_vertices"] = report.num_vertices;
  json["threads"] = report.threads;
  json["views"] = report.views;
  json["width"] = report.width;
  json["height"] = report.height;
  json["spp"] = report.spp;
  json["bounces"] = report.bounces;
  json["edge_budgets"] = {{"primary_edge_ratio", report.derivatives.primary_edge_ratio},
                          {"shadow_edge_ratio", report.derivatives.shadow_edge_ratio},
                          {"secondary_edge_samples", report.derivatives.secondary_edge_samples},
                          {"texel_edge_ratio", report.derivatives.texel_edge_ratio}};
  json["covered_pixels"] = report.covered_pixels;
  json["parameters"] = {{"total", report.num_parameters},
                        {"differentiated", report.num_differentiated},
                        {"kinds", {"vertices", "albedo", "roughness", "specular", "light"}}};
  json["passes"] = {{"forward", PassJson(report.forward)},
                    {"jacobian_rows", PassJson(report.jacobian_rows)},
                    {"adjoint", PassJson(report.adjoint)}};
  json["jacobian_rows"] = {{"entries", report.jacobian_entries},
                           {"entry_bytes", sizeof(JacobianEntry)},
                           {"bytes_total", report.rows_bytes_total},
                           {"bytes_peak_view", report.rows_bytes_peak_view},
                           {"bytes_resident", report.rows_bytes_resident},
                           {"keep_rows", report.keep_rows}};
  json["adjoint_terms"] = {{"entries", report.gradient_terms},
                           {"entries_peak_view", report.gradient_terms_peak_view}};
  json["peak_rss_reset"] = report.peak_rss_reset;
  json["gradient_norm"] = report.gradient_norm;
  if (report.noise_seeds > 0) {
    json["noise"] = {{"seeds", report.noise_seeds},
                     {"vertex_noise", report.vertex_noise},
                     {"adjoint_seconds_mean", report.noise_adjoint_seconds},
                     {"forward_seconds_mean", report.noise_forward_seconds},
                     {"cost_times_variance", report.cost_times_variance}};
  }
  json["aim_ratio"] = kAim;
  json["aim_met"] = report.jacobian_rows.ratio <= kAim && report.adjoint.ratio <= kAim;
  return json;
}

std::string DerivativeCostReportTable(const DerivativeCostReport& report) {
  std::string out;
  char line[320];
  auto add = [&](const char* format, auto... args) {
    std::snprintf(line, sizeof(line), format, args...);
    out += line;
  };
  add("mesh           %d faces, %d vertices\n", report.num_faces, report.num_vertices);
  add("setup          %d views x %d x %d, %d spp, %d bounces, %d threads; %lld covered pixels\n",
      report.views, report.width, report.height, report.spp, report.bounces, report.threads,
      static_cast<long long>(report.covered_pixels));
  add("parameters     %d differentiated (vertices, albedo, roughness, specular, light) of %d\n",
      report.num_differentiated, report.num_parameters);
  add("edge budgets   primary %g, shadow %g, texel %g (x spp x pixels); secondary %g per path "
      "vertex\n",
      report.derivatives.primary_edge_ratio, report.derivatives.shadow_edge_ratio,
      report.derivatives.texel_edge_ratio, report.derivatives.secondary_edge_samples);
  add("%-28s %10s %10s %12s %14s\n", "pass", "seconds", "x forward", "Mrays/s", "peak RSS MiB");
  auto row = [&](const char* name, const DerivativePassCost& pass) {
    add("%-28s %10.3f %10.2f %12.2f %14.1f\n", name, pass.seconds, pass.ratio,
        pass.seconds > 0.0 ? pass.rays.TotalRays() / pass.seconds * 1e-6 : 0.0,
        Mebibytes(pass.peak_rss_bytes));
  };
  row("forward (RenderView)", report.forward);
  row("forward + Jacobian rows", report.jacobian_rows);
  row("forward + adjoint gradient", report.adjoint);
  const double per_pixel =
      report.covered_pixels > 0
          ? static_cast<double>(report.jacobian_entries) / report.covered_pixels
          : 0.0;
  add("Jacobian rows  %lld entries (%.1f per covered pixel, %zu bytes each); %.1f MiB over all "
      "views, %.1f MiB for the largest view\n",
      static_cast<long long>(report.jacobian_entries), per_pixel, sizeof(JacobianEntry),
      Mebibytes(report.rows_bytes_total), Mebibytes(report.rows_bytes_peak_view));
  add("rows resident  %.1f MiB at once (%s)\n", Mebibytes(report.rows_bytes_resident),
      report.keep_rows ? "--keep-rows: every view's rows held" : "one view's rows at a time");
  add("adjoint terms  %lld held before the reduction over all views, %lld for the largest view\n",
      static_cast<long long>(report.gradient_terms),
      static_cast<long long>(report.gradient_terms_peak_view));
  const bool met = report.jacobian_rows.ratio <= kAim && report.adjoint.ratio <= kAim;
  add("aim <= %.0fx    rows %.2fx, adjoint %.2fx: %s\n", kAim, report.jacobian_rows.ratio,
      report.adjoint.ratio, met ? "met" : "not met");
  if (report.noise_seeds > 0) {
    add("noise          vertex gradient %.2f%% (seed-to-seed, %d seeds); adjoint %.3f s mean = "
        "%.2fx the forward passes run between them (%.3f s mean); cost x variance %.4g (forward "
        "passes x relative variance)\n",
        100.0 * report.vertex_noise, report.noise_seeds, report.noise_adjoint_seconds,
        report.noise_forward_seconds > 0.0
            ? report.noise_adjoint_seconds / report.noise_forward_seconds
            : 0.0,
        report.noise_forward_seconds, report.cost_times_variance);
  }
  if (!report.peak_rss_reset) {
    add("note           peak RSS could not be reset per pass: it is the process peak so far\n");
  }
  return out;
}

}  // namespace sft
