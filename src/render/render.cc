#include "src/render/render.h"

#include <glog/logging.h>
#include <pmmintrin.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <xmmintrin.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "src/core/rng.h"
#include "src/render/bsdf.h"

namespace sft {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
double PowerHeuristic(double pdf_a, double pdf_b) {
  const double a2 = pdf_a * pdf_a;
  const double b2 = pdf_b * pdf_b;
  if (!(a2 + b2 > 0.0) || !std::isfinite(a2 + b2)) return pdf_a >= pdf_b ? 1.0 : 0.0;
  return a2 / (a2 + b2);
}

struct Context {
  const RenderScene& scene;
  const Material& material;
  const Material& sampling_material;
  const ViewSetup& view;
  const RenderOptions& options;
  const EnvironmentMap* environment;  // null when absent or disabled.
  int max_segments;
  double specular_scale;
  // Derivatives (null request: none).
  const DerivativeRequest* request;
  const ParameterLayout* layout;
};

// Texel indices of a hit, and the BSDF parameters there.
struct SurfaceMaterial {
  int albedo_texel = 0;
  int roughness_texel = 0;
  BsdfParams params;
};

SurfaceMaterial LookUpMaterial(const Context& ctx, const Material& material, int face, double u,
                               double v) {
  SurfaceMaterial m;
  m.albedo_texel = material.albedo.TexelIndex(face, u, v);
  m.roughness_texel = material.roughness.TexelIndex(face, u, v);
  const double* albedo = material.albedo.texel(m.albedo_texel);
  m.params.albedo = Eigen::Vector3d(albedo[0], albedo[1], albedo[2]);
  m.params.roughness = *material.roughness.texel(m.roughness_texel);
  m.params.specular = material.specular * ctx.specular_scale;
  m.params.fresnel = material.fresnel;
  return m;
}

double RayOffset(const Context& ctx, const Eigen::Vector3d& p) {
  return SurfaceRayOffset(ctx.scene, p);
}

// Per-sample derivative sink: (parameter, ∂RGB) pairs of one path, appended.
using DerivativeList = std::vector<std::pair<int, Eigen::Vector3d>>;

// Bookkeeping of one path's derivatives. A path's light contributions have the form
//   C = (s_0 ⊙ … ⊙ s_{i−1}) ⊙ f_i(wo_i, wi) ⊙ Q,
// with s_k = f_k(wo_k, wi_k)·|n·wi_k|/pdf_k the scatter factor of vertex k (pdf detached) and Q
// the light term. ∂C/∂θ for a parameter of vertex j < i replaces s_j by ∂s_j/∂θ; for vertex i it
// replaces f_i by ∂f_i/∂θ. `excluded_[j]` keeps Π_{k<i, k≠j} s_k so that no division by a
// possibly zero factor is needed.
class PathDerivatives {
 public:
  PathDerivatives(const Context& ctx, DerivativeList* out) : ctx_(ctx), out_(out) {}

  // A light contribution at the current vertex (index = number of scatters so far).
  void AddContribution(const Eigen::Vector3d& prefix, const SurfaceMaterial& surface,
                       const BsdfDerivatives& d_f, const Eigen::Vector3d& f,
                       const Eigen::Vector3d& q, int light_index) {
    const Eigen::Vector3d contribution = prefix.cwiseProduct(f).cwiseProduct(q);
    AddMaterial(surface, d_f, prefix.cwiseProduct(q));
    const Eigen::Vector3d f_q = f.cwiseProduct(q);
    for (int j = 0; j < count_; ++j) {
      AddMaterial(scatters_[j].surface, scatters_[j].d_s, excluded_[j].cwiseProduct(f_q));
    }
    if (ctx_.request->params.lights && light_index >= 0) {
      out_->emplace_back(ctx_.layout->LightOffset() + light_index, contribution);
    }
  }

  // The path continues from the current vertex with scatter factor s (and its derivatives).
  void AddScatter(const Eigen::Vector3d& prefix, const SurfaceMaterial& surface,
                  const Eigen::Vector3d& s, const BsdfDerivatives& d_s) {
    CHECK_LT(count_, kMaxScatters);
    for (int j = 0; j < count_; ++j) excluded_[j] = excluded_[j].cwiseProduct(s);
    excluded_[count_] = prefix;
    scatters_[count_] = {surface, d_s};
    ++count_;
  }

 private:
  struct Scatter {
    SurfaceMaterial surface;
    BsdfDerivatives d_s;
  };

  // Adds base ⊙ ∂(factor)/∂θ for the material parameters of `surface`, where ∂factor/∂θ is
  // described by `d` (albedo: own channel only; roughness and specular: all channels).
  void AddMaterial(const SurfaceMaterial& surface, const BsdfDerivatives& d,
                   const Eigen::Vector3d& base) {
    const ParameterSelection& sel = ctx_.request->params;
    const ParameterLayout& layout = *ctx_.layout;
    if (sel.albedo && d.d_albedo != 0.0) {
      const int first = layout.AlbedoOffset() + 3 * surface.albedo_texel;
      for (int c = 0; c < 3; ++c) {
        Eigen::Vector3d v = Eigen::Vector3d::Zero();
        v[c] = base[c] * d.d_albedo;
        out_->emplace_back(first + c, v);
      }
    }
    if (sel.roughness && d.d_roughness != 0.0) {
      out_->emplace_back(layout.RoughnessOffset() + surface.roughness_texel, base * d.d_roughness);
    }
    if (sel.specular && d.d_specular != 0.0) {
      out_->emplace_back(layout.SpecularIndex(), base * d.d_specular);
    }
  }

  // A path scatters at most bounces − 1 ≤ 15 times (RenderOptions::Check caps bounces at 16).
  static constexpr int kMaxScatters = 16;
  const Context& ctx_;
  DerivativeList* out_;
  int count_ = 0;
  std::array<Scatter, kMaxScatters> scatters_;
  std::array<Eigen::Vector3d, kMaxScatters> excluded_;
};

// Radiance along the camera ray with direction `dir` whose first intersection is `hit` (traced
// by the caller, in packets). When `derivatives` is non-null, the path's parameter derivatives
// are appended to it.
Eigen::Vector3d TraceRadiance(const Context& ctx, Sampler* sampler, Eigen::Vector3d dir, RayHit hit,
                              RenderStats* stats, DerivativeList* derivatives) {
  const Effects& effects = ctx.options.effects;
  Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
  if (!hit.hit) {
    if (ctx.environment != nullptr && ctx.view.environment_background) {
      radiance = ctx.view.environment_scale * ctx.environment->Radiance(dir);
      if (derivatives != nullptr && ctx.request->params.lights &&
          ctx.view.environment_light_index >= 0) {
        derivatives->emplace_back(ctx.layout->LightOffset() + ctx.view.environment_light_index,
                                  radiance);
      }
    }
    return radiance;
  }
  const bool detached = &ctx.sampling_material != &ctx.material;
  std::optional<PathDerivatives> path;
  if (derivatives != nullptr) path.emplace(ctx, derivatives);
  Eigen::Vector3d throughput = Eigen::Vector3d::Ones();
  for (int depth = 0;; ++depth) {
    const Eigen::Vector3d p = ctx.scene.Point(hit.face, hit.u, hit.v);
    Eigen::Vector3d n = ctx.scene.FaceNormal(hit.face);
    if (n.isZero()) break;  // degenerate triangle: no defined surface, nothing reflected.
    const Eigen::Vector3d wo = -dir;
    if (n.dot(wo) < 0.0) n = -n;  // two-sided shading.
    const SurfaceMaterial surface = LookUpMaterial(ctx, ctx.material, hit.face, hit.u, hit.v);
    const BsdfParams& params = surface.params;
    const BsdfParams sampling =
        detached ? LookUpMaterial(ctx, ctx.sampling_material, hit.face, hit.u, hit.v).params
                 : params;
    const double offset = RayOffset(ctx, p);
    const Eigen::Vector3d p_off = p + offset * n;
    const bool lit_here = depth > 0 || effects.direct;

    // Adds throughput ⊙ f ⊙ q to the radiance (and its derivatives).
    auto contribute = [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& f,
                          const Eigen::Vector3d& q, int light_index) {
      radiance += throughput.cwiseProduct(f).cwiseProduct(q);
      if (path) {
        path->AddContribution(throughput, surface,
                              EvalBsdfDerivatives(params, n, wo, wi, ctx.specular_scale), f, q,
                              light_index);
      }
    };

    if (lit_here) {
      for (const PointLight& light : ctx.view.point_lights) {
        const Eigen::Vector3d to_light = light.position - p;
        const double dist2 = to_light.squaredNorm();
        const double min_dist = kMinRelativeLightDistance * ctx.scene.extent();
        if (!(dist2 > min_dist * min_dist)) continue;
        const double dist = std::sqrt(dist2);
        const Eigen::Vector3d wi = to_light / dist;
        const double cos_i = n.dot(wi);
        if (cos_i <= 0.0) continue;
        const Eigen::Vector3d f = EvalBsdf(params, n, wo, wi);
        if (f.isZero() && !path) continue;
        if (effects.shadows) {
          ++stats->shadow_rays;
          if (ctx.scene.Occluded(p_off, wi, 0.0, dist - offset)) continue;
        }
        contribute(wi, f, light.intensity * (cos_i / dist2), light.light_index);
      }
      if (ctx.environment != nullptr) {
        Eigen::Vector3d wi, le;
        double pdf_light = 0.0;
        double u1, u2;
        sampler->Next2D(&u1, &u2);
        if (ctx.environment->Sample(u1, u2, &wi, &le, &pdf_light)) {
          const double cos_i = n.dot(wi);
          if (cos_i > 0.0) {
            const Eigen::Vector3d f = EvalBsdf(params, n, wo, wi);
            bool visible = !f.isZero() || path.has_value();
            if (visible && effects.shadows) {
              ++stats->shadow_rays;
              visible = !ctx.scene.Occluded(p_off, wi, 0.0, kInfinity);
            }
            if (visible) {
              // Without shadows the BSDF-sampled rays cannot tell whether the light is seen, so
              // the environment is lit by light sampling alone (weight 1).
              const double weight =
                  effects.shadows ? PowerHeuristic(pdf_light, BsdfPdf(sampling, n, wo, wi)) : 1.0;
              contribute(wi, f, le * (ctx.view.environment_scale * cos_i * weight / pdf_light),
                         ctx.view.environment_light_index);
            }
          }
        }
      }
    }

    const bool continue_path = depth + 1 < ctx.max_segments;
    const bool bsdf_lights_environment = ctx.environment != nullptr && lit_here && effects.shadows;
    if (!continue_path && !bsdf_lights_environment) break;
    BsdfSample sample;
    Eigen::Vector3d u;
    u.x() = sampler->Next1D();  // lobe choice
    sampler->Next2D(&u.y(), &u.z());
    if (!SampleBsdf(sampling, n, wo, u, &sample)) break;
    const Eigen::Vector3d wi = sample.wi;
    const Eigen::Vector3d f = detached ? EvalBsdf(params, n, wo, wi) : sample.f;
    const double cos_over_pdf = n.dot(wi) / sample.pdf;
    if (!std::isfinite(cos_over_pdf)) break;
    const RayHit next = ctx.scene.Intersect(p_off, wi, 0.0, kInfinity);
    ++stats->bounce_rays;
    if (!next.hit) {
      if (bsdf_lights_environment) {
        const double weight = PowerHeuristic(sample.pdf, ctx.environment->Pdf(wi));
        contribute(
            wi, f,
            ctx.environment->Radiance(wi) * (ctx.view.environment_scale * weight * cos_over_pdf),
            ctx.view.environment_light_index);
      }
      break;
    }
    if (!continue_path) break;
    const Eigen::Vector3d scatter = f * cos_over_pdf;
    if (path) {
      BsdfDerivatives d_s = EvalBsdfDerivatives(params, n, wo, wi, ctx.specular_scale);
      d_s.d_albedo *= cos_over_pdf;
      d_s.d_roughness *= cos_over_pdf;
      d_s.d_specular *= cos_over_pdf;
      path->AddScatter(throughput, surface, scatter, d_s);
    }
    throughput = throughput.cwiseProduct(scatter);
    dir = wi;
    hit = next;
  }
  return radiance;
}

// First-hit auxiliary passes (albedo, roughness, normal, depth).
Eigen::Vector3d TraceAuxiliary(const Context& ctx, const Eigen::Vector3d& dir, const RayHit& hit) {
  if (!hit.hit) return Eigen::Vector3d::Zero();
  const BsdfParams params = LookUpMaterial(ctx, ctx.material, hit.face, hit.u, hit.v).params;
  switch (ctx.options.pass) {
    case RenderPass::kAlbedo:
      return params.albedo;
    case RenderPass::kRoughness:
      return Eigen::Vector3d::Constant(params.roughness);
    case RenderPass::kNormal: {
      Eigen::Vector3d n = ctx.scene.FaceNormal(hit.face);
      if (n.dot(dir) > 0.0) n = -n;
      return n;
    }
    case RenderPass::kDepth: {
      const Eigen::Vector3d p = ctx.scene.Point(hit.face, hit.u, hit.v);
      return Eigen::Vector3d::Constant((ctx.view.cam_from_world * p).z());
    }
    case RenderPass::kColor:
      break;
  }
  return Eigen::Vector3d::Zero();
}

}  // namespace

std::string Effects::ToString() const {
  std::string s;
  auto add = [&s](bool on, const char* name) {
    if (!on) return;
    if (!s.empty()) s += ",";
    s += name;
  };
  add(direct, "direct");
  add(shadows, "shadows");
  add(bounces, "bounces");
  add(specular, "specular");
  add(environment, "environment");
  return s.empty() ? "none" : s;
}

bool Effects::Parse(const std::string& list, Effects* effects, std::string* why) {
  Effects parsed;
  parsed.direct = parsed.shadows = parsed.bounces = parsed.specular = parsed.environment = false;
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    const std::string name = list.substr(start, end - start);
    if (name == "direct")
      parsed.direct = true;
    else if (name == "shadows")
      parsed.shadows = true;
    else if (name == "bounces")
      parsed.bounces = true;
    else if (name == "specular")
      parsed.specular = true;
    else if (name == "environment")
      parsed.environment = true;
    else if (name == "all")
      parsed = Effects();
    else if (name == "none" || name.empty()) {
    } else {
      *why = "effects: unknown effect '" + name +
             "' (known: direct, shadows, bounces, specular, environment, all, none)";
      return false;
    }
    start = end + 1;
  }
  *effects = parsed;
  return true;
}

bool RenderPassFromName(const std::string& name, RenderPass* pass) {
  if (name == "color")
    *pass = RenderPass::kColor;
  else if (name == "albedo")
    *pass = RenderPass::kAlbedo;
  else if (name == "roughness")
    *pass = RenderPass::kRoughness;
  else if (name == "normal")
    *pass = RenderPass::kNormal;
  else if (name == "depth")
    *pass = RenderPass::kDepth;
  else
    return false;
  return true;
}

bool RenderOptions::Check(std::string* why) const {
  if (spp < 1 || spp > (1 << 20)) {
    *why = "spp: must be in [1, 1048576], got " + std::to_string(spp);
    return false;
  }
  if (bounces < 1 || bounces > 16) {
    *why = "bounces: must be in [1, 16] (1 = direct light only), got " + std::to_string(bounces);
    return false;
  }
  if (threads < 0) {
    *why = "threads: must be >= 0 (0 = all cores), got " + std::to_string(threads);
    return false;
  }
  return true;
}

namespace {

// Sorts a pixel's derivative list by parameter and merges duplicates, scaling by `scale`.
void MergeDerivatives(DerivativeList* list, double scale, std::vector<JacobianEntry>* merged) {
  merged->clear();
  std::sort(list->begin(), list->end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (size_t i = 0; i < list->size();) {
    const int param = (*list)[i].first;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; i < list->size() && (*list)[i].first == param; ++i) sum += (*list)[i].second;
    if (!sum.allFinite()) continue;
    merged->push_back({param,
                       {static_cast<float>(sum[0] * scale), static_cast<float>(sum[1] * scale),
                        static_cast<float>(sum[2] * scale)}});
  }
}

void RenderImpl(const RenderScene& scene, const Material& material, const ViewSetup& view,
                const RenderOptions& options, const DerivativeRequest* request,
                const ParameterLayout* layout, Image* image, DerivativeOutput* output,
                RenderStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const Context ctx{scene,
                    material,
                    options.sampling_material != nullptr ? *options.sampling_material : material,
                    view,
                    options,
                    options.effects.environment ? view.environment : nullptr,
                    options.effects.bounces ? options.bounces : 1,
                    options.effects.specular ? 1.0 : 0.0,
                    request,
                    layout};
  const int width = view.camera.width;
  const int height = view.camera.height;
  *image = Image(width, height, 4);
  const Rigid3d world_from_cam = view.cam_from_world.Inverse();
  const Eigen::Vector3d center = world_from_cam.translation;
  const Eigen::Matrix3d world_from_cam_rotation = world_from_cam.rotation.toRotationMatrix();
  const double inv_spp = 1.0 / options.spp;
  const bool want_rows = request != nullptr && request->jacobian_rows;
  const Image* weights = request != nullptr ? request->adjoint_weights : nullptr;
  const bool want_derivatives = want_rows || weights != nullptr;

  // Fixed 8×8 tiles; each tile row is one packet of camera rays per sample. The packet
  // composition depends only on the image size, never on scheduling, so images (and
  // derivatives, reduced in tile order) stay bit-identical for any thread count.
  constexpr int kTile = 8;
  const int tiles_x = (width + kTile - 1) / kTile;
  const int tiles_y = (height + kTile - 1) / kTile;
  const int num_tiles = tiles_x * tiles_y;
  std::vector<std::vector<JacobianEntry>> pixel_rows(want_rows ? static_cast<size_t>(width) * height
                                                               : 0);
  std::vector<std::vector<std::pair<int, double>>> tile_gradients(weights != nullptr ? num_tiles
                                                                                     : 0);
  tbb::enumerable_thread_specific<RenderStats> thread_stats;
  auto render_tile = [&](int tile) {
    // Embree wants flush-to-zero / denormals-are-zero in every tracing thread.
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    RenderStats& local = thread_stats.local();
    const int x0 = (tile % tiles_x) * kTile;
    const int y0 = (tile / tiles_x) * kTile;
    const int count = std::min(kTile, width - x0);
    DerivativeList lists[kTile];
    std::vector<JacobianEntry> merged;
    for (int y = y0; y < std::min(y0 + kTile, height); ++y) {
      Eigen::Vector3d sums[kTile];
      int hits[kTile] = {0};
      for (int i = 0; i < count; ++i) {
        sums[i].setZero();
        lists[i].clear();
      }
      for (int s = 0; s < options.spp; ++s) {
        Sampler samplers[kTile];
        Eigen::Vector3d dirs[kTile];
        for (int i = 0; i < count; ++i) {
          dirs[i] = CameraSampleDirection(view, world_from_cam_rotation, options.seed, x0 + i, y, s,
                                          &samplers[i]);
        }
        RayHit first_hits[kTile];
        scene.Intersect8(center, dirs, count, first_hits);
        local.camera_rays += count;
        for (int i = 0; i < count; ++i) {
          const Eigen::Vector3d value =
              options.pass == RenderPass::kColor
                  ? TraceRadiance(ctx, &samplers[i], dirs[i], first_hits[i], &local,
                                  want_derivatives ? &lists[i] : nullptr)
                  : TraceAuxiliary(ctx, dirs[i], first_hits[i]);
          if (value.allFinite()) sums[i] += value;
          hits[i] += first_hits[i].hit ? 1 : 0;
        }
      }
      for (int i = 0; i < count; ++i) {
        const int x = x0 + i;
        for (int c = 0; c < 3; ++c) image->at(x, y, c) = static_cast<float>(sums[i][c] * inv_spp);
        image->at(x, y, 3) = static_cast<float>(hits[i] * inv_spp);
        if (!want_derivatives) continue;
        MergeDerivatives(&lists[i], inv_spp, &merged);
        if (weights != nullptr) {
          const Eigen::Vector3d w(weights->at(x, y, 0), weights->at(x, y, 1), weights->at(x, y, 2));
          for (const JacobianEntry& e : merged) {
            const double g = w[0] * e.d[0] + w[1] * e.d[1] + w[2] * e.d[2];
            if (g != 0.0) tile_gradients[tile].emplace_back(e.param, g);
          }
        }
        if (want_rows) pixel_rows[static_cast<size_t>(y) * width + x] = merged;
      }
    }
  };
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] { tbb::parallel_for(0, num_tiles, render_tile); });

  if (output != nullptr && layout != nullptr) {
    output->layout = *layout;
    if (want_rows) {
      JacobianRows& rows = output->rows;
      rows.width = width;
      rows.height = height;
      rows.offsets.assign(static_cast<size_t>(width) * height + 1, 0);
      size_t total = 0;
      for (size_t p = 0; p < pixel_rows.size(); ++p) total += pixel_rows[p].size();
      rows.entries.clear();
      rows.entries.reserve(total);
      for (size_t p = 0; p < pixel_rows.size(); ++p) {
        rows.offsets[p] = rows.entries.size();
        rows.entries.insert(rows.entries.end(), pixel_rows[p].begin(), pixel_rows[p].end());
      }
      rows.offsets.back() = rows.entries.size();
    }
    if (weights != nullptr) {
      output->gradient.assign(layout->size(), 0.0);
      for (const auto& list : tile_gradients) {
        for (const auto& [param, g] : list) output->gradient[param] += g;
      }
    }
  }
  if (stats != nullptr) {
    *stats = RenderStats();
    for (const RenderStats& s : thread_stats) {
      stats->camera_rays += s.camera_rays;
      stats->shadow_rays += s.shadow_rays;
      stats->bounce_rays += s.bounce_rays;
    }
    stats->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
}

}  // namespace

double SurfaceRayOffset(const RenderScene& scene, const Eigen::Vector3d& p) {
  return kRelativeRayOffset * std::max(scene.extent(), p.cwiseAbs().maxCoeff());
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

void RenderView(const RenderScene& scene, const Material& material, const ViewSetup& view,
                const RenderOptions& options, Image* image, RenderStats* stats) {
  RenderImpl(scene, material, view, options, nullptr, nullptr, image, nullptr, stats);
}

ParameterLayout MakeParameterLayout(const RenderScene& scene, const Material& material,
                                    int num_lights) {
  ParameterLayout layout;
  layout.num_vertices = static_cast<int>(scene.positions().size());
  layout.num_albedo_texels = material.albedo.num_texels();
  layout.num_roughness_texels = material.roughness.num_texels();
  layout.num_lights = num_lights;
  return layout;
}

void RenderViewWithDerivatives(const RenderScene& scene, const Material& material,
                               const ViewSetup& view, const RenderOptions& options,
                               const DerivativeRequest& request, int num_lights, Image* image,
                               DerivativeOutput* output, RenderStats* stats) {
  std::string why;
  CHECK(request.Check(&why)) << why;
  const ParameterLayout layout = MakeParameterLayout(scene, material, num_lights);
  RenderImpl(scene, material, view, options, &request, &layout, image, output, stats);
}

}  // namespace sft
