// RenderView and RenderViewWithDerivatives: camera samples in fixed tiles, run in parallel, and
// the reduction of their derivatives. The parts live in src/render/internal/:
//   integrator       camera paths: TraceRadiance (next-event estimation, BSDF sampling, MIS);
//   path_derivatives the interior terms of one path's derivatives and the per-pixel sums;
//   edge_sampling    what the boundary terms share, and the image-curve terms' driver;
//   primary_edges, shadow_edges, texel_edges   the curves the camera sees directly;
//   secondary_edges  the curves seen from path vertices (Li et al. 2018 §5);
//   sampling         discrete distributions, frustum clipping, resampling.
#include "src/render/render.h"

#include <glog/logging.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>

#include "src/core/rng.h"
#include "src/render/internal/context.h"
#include "src/render/internal/edge_sampling.h"
#include "src/render/internal/fp_mode.h"
#include "src/render/internal/integrator.h"
#include "src/render/internal/path_derivatives.h"
#include "src/render/internal/secondary_edges.h"
#include "src/render/internal/vertex_normal_jacobian.h"

namespace sft {
namespace {

using render_internal::Context;
using render_internal::DerivativeList;
using render_internal::ParamSums;
using render_internal::PathDerivatives;
using render_internal::RowAccumulator;

// Camera samples are traced in fixed kTile × kTile pixel tiles (RenderImpl).
constexpr int kTile = 8;

// What the tiles of one render share, and where they write.
struct TileJob {
  explicit TileJob(const Context& context) : ctx(context) {}
  const Context& ctx;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d world_from_cam_rotation = Eigen::Matrix3d::Identity();
  int tiles_x = 0;
  bool want_rows = false;
  const Image* weights = nullptr;  // adjoint weights, or null.
  bool want_derivatives = false;
  // Boundary (edge) terms of vertex derivatives, gathered per pixel before the tiles run.
  std::vector<DerivativeList> edge_lists;
  Image* image = nullptr;
  std::vector<std::vector<JacobianEntry>> pixel_rows;  // per pixel, rows only.
  // Adjoint only: per tile, its pixels' terms w·∂RGB summed per parameter (one entry per distinct
  // parameter of the tile), reduced in tile order by CollectDerivatives so that the gradient
  // does not depend on which thread ran which tile.
  std::vector<std::vector<std::pair<int, double>>> tile_gradients;
  tbb::enumerable_thread_specific<RenderStats> thread_stats;
  tbb::enumerable_thread_specific<std::array<RowAccumulator, kTile>> thread_rows;
  tbb::enumerable_thread_specific<ParamSums<double>> thread_tile_sums;  // the running tile's.
  // DerivativeRequest::gradient_parts: the edge terms' parts (the image curves' filled before the
  // tiles run), and per tile its secondary edge terms w·∂RGB/spp summed per parameter, reduced in
  // tile order like tile_gradients.
  bool want_parts = false;
  GradientParts parts;
  std::vector<std::vector<std::pair<int, double>>> tile_secondary;
  tbb::enumerable_thread_specific<ParamSums<double>> thread_secondary_sums;
};

// Writes pixel (x, y)'s value and coverage, and merges its derivatives (path terms in `rows`,
// edge terms from the job's lists) into its Jacobian row and/or the tile's gradient sums.
void FinishPixel(TileJob* job, int x, int y, const Eigen::Vector3d& sum, int hits,
                 RowAccumulator* rows, std::vector<JacobianEntry>* merged,
                 ParamSums<double>* tile_sums, RenderStats* stats) {
  const double inv_spp = 1.0 / job->ctx.options.spp;
  const int width = job->ctx.view.camera.width;
  for (int c = 0; c < 3; ++c) {
    const float value = static_cast<float>(sum[c] * inv_spp);
    job->image->at(x, y, c) = value;
    if (!std::isfinite(value)) ++stats->nonfinite_outputs;
  }
  job->image->at(x, y, 3) = static_cast<float>(hits * inv_spp);
  if (!job->want_derivatives) return;
  if (!job->edge_lists.empty()) {
    for (const auto& [param, d] : job->edge_lists[static_cast<size_t>(y) * width + x]) {
      rows->Add(param, d);
    }
  }
  rows->Flush(inv_spp, merged, &stats->nonfinite_outputs);
  if (job->weights != nullptr) {
    const Image& w_image = *job->weights;
    const Eigen::Vector3d w(w_image.at(x, y, 0), w_image.at(x, y, 1), w_image.at(x, y, 2));
    for (const JacobianEntry& e : *merged) {
      const double g = w[0] * e.d[0] + w[1] * e.d[1] + w[2] * e.d[2];
      if (g != 0.0) tile_sums->Add(e.param, g);
    }
  }
  if (job->want_rows) job->pixel_rows[static_cast<size_t>(y) * width + x] = *merged;
}

// The weight of pixel (x, y)'s secondary edge terms in their part of the gradient: the adjoint
// weight over spp (FinishPixel weighs the pixel's sums, which it divides by spp).
Eigen::Vector3d SecondaryPartWeight(const TileJob& job, int x, int y) {
  const Image& w = *job.weights;
  return Eigen::Vector3d(w.at(x, y, 0), w.at(x, y, 1), w.at(x, y, 2)) / job.ctx.options.spp;
}

// One 8×8 tile; each tile row is one packet of camera rays per sample.
void RenderTile(TileJob* job, int tile) {
  const render_internal::ScopedTracingFpMode fp_mode;
  const Context& ctx = job->ctx;
  const RenderOptions& options = ctx.options;
  const int width = ctx.view.camera.width, height = ctx.view.camera.height;
  RenderStats& local = job->thread_stats.local();
  const int x0 = (tile % job->tiles_x) * kTile;
  const int y0 = (tile / job->tiles_x) * kTile;
  const int count = std::min(kTile, width - x0);
  std::array<RowAccumulator, kTile>& rows = job->thread_rows.local();
  std::optional<PathDerivatives> path;
  if (job->want_derivatives) path.emplace(ctx);
  std::vector<JacobianEntry> merged;
  ParamSums<double>& tile_sums = job->thread_tile_sums.local();
  ParamSums<double>* secondary_sums =
      job->want_parts ? &job->thread_secondary_sums.local() : nullptr;
  for (int y = y0; y < std::min(y0 + kTile, height); ++y) {
    Eigen::Vector3d sums[kTile];
    int hits[kTile] = {0};
    for (int i = 0; i < count; ++i) sums[i].setZero();
    for (int s = 0; s < options.spp; ++s) {
      Sampler samplers[kTile];
      Eigen::Vector3d dirs[kTile];
      for (int i = 0; i < count; ++i) {
        dirs[i] = CameraSampleDirection(ctx.view, job->world_from_cam_rotation, options.seed,
                                        x0 + i, y, s, &samplers[i]);
      }
      RayHit first_hits[kTile];
      ctx.scene.Intersect8(job->center, dirs, count, first_hits);
      local.camera_rays += count;
      for (int i = 0; i < count; ++i) {
        if (secondary_sums != nullptr) {
          path->Reset(&rows[i], secondary_sums, SecondaryPartWeight(*job, x0 + i, y));
        } else if (path) {
          path->Reset(&rows[i]);
        }
        const Eigen::Vector3d value =
            options.pass == RenderPass::kColor
                ? render_internal::TraceRadiance(ctx, &samplers[i], dirs[i], first_hits[i], &local,
                                                 path ? &*path : nullptr)
                : render_internal::TraceAuxiliary(ctx, dirs[i], first_hits[i]);
        // A sample with a value that is not finite is dropped whole: radiance and derivatives.
        if (value.allFinite() && (!path || path->Finite())) {
          sums[i] += value;
          if (path) path->Commit();
        } else {
          ++local.nonfinite_samples;
        }
        hits[i] += first_hits[i].hit ? 1 : 0;
      }
    }
    for (int i = 0; i < count; ++i) {
      FinishPixel(job, x0 + i, y, sums[i], hits[i], &rows[i], &merged, &tile_sums, &local);
    }
  }
  if (job->weights != nullptr) tile_sums.MoveTo(&job->tile_gradients[tile]);
  if (secondary_sums != nullptr) secondary_sums->MoveTo(&job->tile_secondary[tile]);
  if (options.on_tile_done) options.on_tile_done();
}

// Moves the job's gradient parts into *output (after its gradient): the secondary edges' tile
// sums in tile order, and the rest as the gradient minus the edge parts.
void CollectGradientParts(TileJob* job, DerivativeOutput* output) {
  GradientParts& parts = job->parts;
  std::vector<double>& secondary = parts.part(DerivativeTerm::kSecondaryEdges);
  for (const auto& list : job->tile_secondary) {
    for (const auto& [param, g] : list) secondary[param] += g;
  }
  std::vector<double>& rest = parts.part(DerivativeTerm::kRest);
  rest = output->gradient;
  for (int t = 0; t < kNumDerivativeTerms; ++t) {
    if (t == static_cast<int>(DerivativeTerm::kRest)) continue;
    const std::vector<double>& part = parts.parts[t];
    for (size_t i = 0; i < rest.size(); ++i) rest[i] -= part[i];
  }
  output->gradient_parts = std::move(parts);
}

// Moves the job's per-pixel rows and per-tile gradient terms into *output; counts the gradient
// terms in *stats.
void CollectDerivatives(TileJob* job, const ParameterLayout& layout, DerivativeOutput* output,
                        RenderStats* stats) {
  output->layout = layout;
  if (job->want_rows) {
    JacobianRows& rows = output->rows;
    rows.width = job->ctx.view.camera.width;
    rows.height = job->ctx.view.camera.height;
    rows.offsets.assign(static_cast<size_t>(rows.width) * rows.height + 1, 0);
    size_t total = 0;
    for (const auto& pixel : job->pixel_rows) total += pixel.size();
    rows.entries.clear();
    rows.entries.reserve(total);
    for (size_t p = 0; p < job->pixel_rows.size(); ++p) {
      rows.offsets[p] = rows.entries.size();
      rows.entries.insert(rows.entries.end(), job->pixel_rows[p].begin(), job->pixel_rows[p].end());
    }
    rows.offsets.back() = rows.entries.size();
  }
  if (job->weights != nullptr) {
    output->gradient.assign(layout.size(), 0.0);
    for (const auto& list : job->tile_gradients) {
      stats->gradient_terms += static_cast<int64_t>(list.size());
      for (const auto& [param, g] : list) output->gradient[param] += g;
    }
  }
  if (job->want_parts) CollectGradientParts(job, output);
}

// The candidates of secondary edge samples, when the request needs them.
std::optional<render_internal::SecondaryEdges> MaybeSecondaryEdges(
    const RenderScene& scene, const Material& material, const ViewSetup& view,
    const RenderOptions& options, const DerivativeRequest* request, const ParameterLayout* layout,
    const EnvironmentMap* environment, int max_segments, RenderStats* stats) {
  if (request == nullptr || !(request->jacobian_rows || request->adjoint_weights != nullptr) ||
      options.pass != RenderPass::kColor || !(request->secondary_edge_samples > 0)) {
    return std::nullopt;
  }
  // Without vertex derivatives only the point lights' positions and the directional lights'
  // directions have secondary terms: their shadow boundaries seen through a bounce, (B).
  const bool light_positions =
      layout != nullptr && options.effects.shadows && max_segments > 1 &&
      ((request->params.light_positions && layout->light_positions && !view.point_lights.empty()) ||
       (request->params.light_directions && layout->light_directions &&
        !view.directional_lights.empty()));
  if ((request->params.vertices &&
       ((environment != nullptr && options.effects.shadows) || max_segments > 1)) ||
      (!request->params.vertices && light_positions)) {
    return render_internal::BuildSecondaryEdges(scene, material, view, options, *request,
                                                environment != nullptr, max_segments, stats);
  }
  return std::nullopt;
}

void RenderImpl(const RenderScene& scene, const Material& material, const ViewSetup& view,
                const RenderOptions& options, const DerivativeRequest* request,
                const ParameterLayout* layout, Image* image, DerivativeOutput* output,
                RenderStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const EnvironmentMap* environment = options.effects.environment ? view.environment : nullptr;
  const int max_segments = options.effects.bounces ? options.bounces : 1;
  RenderStats edge_stats;  // of the edge terms' set-up and samples outside the tiles.
  const std::optional<render_internal::SecondaryEdges> secondary = MaybeSecondaryEdges(
      scene, material, view, options, request, layout, environment, max_segments, &edge_stats);
  std::shared_ptr<const render_internal::VertexNormalJacobian> normal_jacobian;
  if (request != nullptr && (request->jacobian_rows || request->adjoint_weights != nullptr) &&
      request->params.vertices && options.shading == Shading::kSmooth) {
    normal_jacobian = render_internal::VertexNormalJacobian::Of(scene);
  }
  const Context ctx{scene,
                    material,
                    options.sampling_material != nullptr ? *options.sampling_material : material,
                    view,
                    options,
                    environment,
                    environment != nullptr && options.sampling_environment != nullptr
                        ? options.sampling_environment
                        : environment,
                    max_segments,
                    options.effects.specular ? 1.0 : 0.0,
                    request,
                    layout,
                    secondary ? &*secondary : nullptr,
                    normal_jacobian.get()};
  const int width = view.camera.width;
  const int height = view.camera.height;
  *image = Image(width, height, 4);
  TileJob job(ctx);
  const Rigid3d world_from_cam = view.cam_from_world.Inverse();
  job.center = world_from_cam.translation;
  job.world_from_cam_rotation = world_from_cam.rotation.toRotationMatrix();
  job.want_rows = request != nullptr && request->jacobian_rows;
  job.weights = request != nullptr ? request->adjoint_weights : nullptr;
  job.want_derivatives = job.want_rows || job.weights != nullptr;
  job.image = image;
  // Fixed 8×8 tiles: the packet composition depends only on the image size, never on
  // scheduling, so images (and derivatives, reduced in tile order) stay bit-identical for any
  // thread count.
  job.tiles_x = (width + kTile - 1) / kTile;
  const int num_tiles = job.tiles_x * ((height + kTile - 1) / kTile);
  if (job.want_rows) job.pixel_rows.resize(static_cast<size_t>(width) * height);
  if (job.weights != nullptr) job.tile_gradients.resize(num_tiles);
  job.want_parts = job.weights != nullptr && request->gradient_parts;
  if (job.want_parts) {
    job.parts.Reset(layout->size());
    job.tile_secondary.resize(num_tiles);
  }
  // Light positions and directions move shadow boundaries: edge terms even without vertices.
  const bool moves_lights = request != nullptr && layout != nullptr &&
                            ((request->params.light_positions && layout->light_positions) ||
                             (request->params.light_directions && layout->light_directions));
  if (job.want_derivatives && (request->params.vertices || moves_lights) &&
      options.pass == RenderPass::kColor) {
    job.edge_lists.resize(static_cast<size_t>(width) * height);
    render_internal::AddEdgeTerms(ctx, &job.edge_lists, &edge_stats,
                                  job.want_parts ? &job.parts : nullptr);
  }
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute(
      [&] { tbb::parallel_for(0, num_tiles, [&](int tile) { RenderTile(&job, tile); }); });
  RenderStats collect_stats;
  if (output != nullptr && layout != nullptr) {
    CollectDerivatives(&job, *layout, output, &collect_stats);
  }
  if (stats != nullptr) {
    *stats = edge_stats;
    stats->AddCounts(collect_stats);
    for (const RenderStats& s : job.thread_stats) stats->AddCounts(s);
    stats->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
}

}  // namespace

int64_t RenderTileCount(int width, int height) {
  return static_cast<int64_t>((width + kTile - 1) / kTile) * ((height + kTile - 1) / kTile);
}

double SurfaceScale(const RenderScene& scene, int face, const Eigen::Vector3d& p) {
  return std::max(scene.FaceScale(face), p.cwiseAbs().maxCoeff());
}

double SurfaceRayOffset(const RenderScene& scene, int face, const Eigen::Vector3d& p) {
  return kRelativeRayOffset * SurfaceScale(scene, face, p);
}

Eigen::Vector3d CameraSampleDirection(const ViewSetup& view,
                                      const Eigen::Matrix3d& world_from_cam_rotation, uint64_t seed,
                                      int x, int y, int s, Sampler* sampler) {
  const uint64_t pixel = static_cast<uint64_t>(y) * view.camera.width + x;
  *sampler = Sampler(seed, view.view_index, pixel, static_cast<uint64_t>(s));
  double jitter_x, jitter_y;
  sampler->Next2D(&jitter_x, &jitter_y);
  const Eigen::Vector2d film(x + jitter_x, y + jitter_y);
  return (world_from_cam_rotation * view.camera.CamFromImage(film)).normalized();
}

Eigen::Matrix3d LightPositionJacobian(const ViewSetup& view, const PointLight& light) {
  if (!light.camera_frame) return Eigen::Matrix3d::Identity();
  return view.cam_from_world.rotation.toRotationMatrix().transpose();
}

Eigen::Matrix3d LightDirectionJacobian(const ViewSetup& view, const DirectionalLight& light) {
  const Eigen::Vector3d& d = light.direction;
  const Eigen::Matrix3d project = Eigen::Matrix3d::Identity() - d * d.transpose();
  const Eigen::Matrix3d scaled = project / light.parameter_norm;
  if (!light.camera_frame) return scaled;
  return scaled * view.cam_from_world.rotation.toRotationMatrix().transpose();
}

void RenderView(const RenderScene& scene, const Material& material, const ViewSetup& view,
                const RenderOptions& options, Image* image, RenderStats* stats) {
  RenderImpl(scene, material, view, options, nullptr, nullptr, image, nullptr, stats);
}

ParameterLayout MakeParameterLayout(const RenderScene& scene, const Material& material,
                                    int num_lights) {
  ParameterLayout layout;
  layout.num_vertices = static_cast<int>(scene.positions().size());
  layout.num_albedo_texels = material.NumAlbedoTexels();
  layout.num_roughness_texels = material.NumRoughnessTexels();
  layout.num_lights = num_lights;
  return layout;
}

void RenderViewWithDerivatives(const RenderScene& scene, const Material& material,
                               const ViewSetup& view, const RenderOptions& options,
                               const DerivativeRequest& request, int num_lights, Image* image,
                               DerivativeOutput* output, RenderStats* stats) {
  RenderViewWithDerivatives(scene, material, view, options, request,
                            MakeParameterLayout(scene, material, num_lights), image, output, stats);
}

void RenderViewWithDerivatives(const RenderScene& scene, const Material& material,
                               const ViewSetup& view, const RenderOptions& options,
                               const DerivativeRequest& request, const ParameterLayout& layout,
                               Image* image, DerivativeOutput* output, RenderStats* stats) {
  std::string why;
  CHECK(request.Check(&why)) << why;
  const ParameterLayout base = MakeParameterLayout(scene, material, layout.num_lights);
  CHECK(base.num_vertices == layout.num_vertices &&
        base.num_albedo_texels == layout.num_albedo_texels &&
        base.num_roughness_texels == layout.num_roughness_texels)
      << "parameter layout does not match the scene and material";
  if (layout.FitsEnvironment(view.environment_light_index) && view.environment != nullptr) {
    CHECK_EQ(view.environment->width() * view.environment->height(), layout.num_environment_texels);
  }
  RenderImpl(scene, material, view, options, &request, &layout, image, output, stats);
}

}  // namespace sft
