#include "src/render/render.h"

#include <pmmintrin.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <xmmintrin.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "src/core/rng.h"
#include "src/render/bsdf.h"

namespace sft {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Rays leave surfaces offset along the normal by this fraction of the scene scale (the larger of
// the mesh's extent and the point's distance from the origin, so float rounding of the hit point
// is covered at any scale).
constexpr double kRelativeRayOffset = 2e-5;
// Point lights closer than this (relative to the scene extent) to a shaded point are skipped:
// I/d² would overflow, and a light inside the surface lights nothing physical.
constexpr double kMinRelativeLightDistance = 1e-9;

double PowerHeuristic(double pdf_a, double pdf_b) {
  const double a2 = pdf_a * pdf_a;
  const double b2 = pdf_b * pdf_b;
  if (!(a2 + b2 > 0.0) || !std::isfinite(a2 + b2)) return pdf_a >= pdf_b ? 1.0 : 0.0;
  return a2 / (a2 + b2);
}

struct Context {
  const RenderScene& scene;
  const Material& material;
  const ViewSetup& view;
  const RenderOptions& options;
  const EnvironmentMap* environment;  // null when absent or disabled.
  int max_segments;
  double specular_scale;
};

BsdfParams LookUpMaterial(const Context& ctx, int face, double u, double v) {
  BsdfParams params;
  const double* albedo = ctx.material.albedo.texel(ctx.material.albedo.TexelIndex(face, u, v));
  params.albedo = Eigen::Vector3d(albedo[0], albedo[1], albedo[2]);
  params.roughness = *ctx.material.roughness.texel(ctx.material.roughness.TexelIndex(face, u, v));
  params.specular = ctx.material.specular * ctx.specular_scale;
  params.fresnel = ctx.material.fresnel;
  return params;
}

double RayOffset(const Context& ctx, const Eigen::Vector3d& p) {
  return kRelativeRayOffset * std::max(ctx.scene.extent(), p.cwiseAbs().maxCoeff());
}

// Radiance along the camera ray with direction `dir` whose first intersection is `hit` (traced
// by the caller, in packets).
Eigen::Vector3d TraceRadiance(const Context& ctx, Sampler* sampler, Eigen::Vector3d dir,
                              RayHit hit, RenderStats* stats) {
  const Effects& effects = ctx.options.effects;
  Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
  if (!hit.hit) {
    if (ctx.environment != nullptr && ctx.view.environment_background) {
      radiance = ctx.environment->Radiance(dir);
    }
    return radiance;
  }
  Eigen::Vector3d throughput = Eigen::Vector3d::Ones();
  for (int depth = 0;; ++depth) {
    const Eigen::Vector3d p = ctx.scene.Point(hit.face, hit.u, hit.v);
    Eigen::Vector3d n = ctx.scene.FaceNormal(hit.face);
    if (n.isZero()) break;  // degenerate triangle: no defined surface, nothing reflected.
    const Eigen::Vector3d wo = -dir;
    if (n.dot(wo) < 0.0) n = -n;  // two-sided shading.
    const BsdfParams params = LookUpMaterial(ctx, hit.face, hit.u, hit.v);
    const double offset = RayOffset(ctx, p);
    const Eigen::Vector3d p_off = p + offset * n;
    const bool lit_here = depth > 0 || effects.direct;

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
        if (f.isZero()) continue;
        if (effects.shadows) {
          ++stats->shadow_rays;
          if (ctx.scene.Occluded(p_off, wi, 0.0, dist - offset)) continue;
        }
        radiance += throughput.cwiseProduct(f).cwiseProduct(light.intensity) * (cos_i / dist2);
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
            bool visible = !f.isZero();
            if (visible && effects.shadows) {
              ++stats->shadow_rays;
              visible = !ctx.scene.Occluded(p_off, wi, 0.0, kInfinity);
            }
            if (visible) {
              // Without shadows the BSDF-sampled rays cannot tell whether the light is seen, so
              // the environment is lit by light sampling alone (weight 1).
              const double weight =
                  effects.shadows ? PowerHeuristic(pdf_light, BsdfPdf(params, n, wo, wi)) : 1.0;
              radiance += throughput.cwiseProduct(f).cwiseProduct(le) * (cos_i * weight / pdf_light);
            }
          }
        }
      }
    }

    const bool continue_path = depth + 1 < ctx.max_segments;
    const bool bsdf_lights_environment =
        ctx.environment != nullptr && lit_here && effects.shadows;
    if (!continue_path && !bsdf_lights_environment) break;
    BsdfSample sample;
    Eigen::Vector3d u;
    u.x() = sampler->Next1D();  // lobe choice
    sampler->Next2D(&u.y(), &u.z());
    if (!SampleBsdf(params, n, wo, u, &sample)) break;
    const Eigen::Vector3d next_throughput =
        throughput.cwiseProduct(sample.f) * (n.dot(sample.wi) / sample.pdf);
    if (!next_throughput.allFinite()) break;
    const RayHit next = ctx.scene.Intersect(p_off, sample.wi, 0.0, kInfinity);
    ++stats->bounce_rays;
    if (!next.hit) {
      if (bsdf_lights_environment) {
        const double weight = PowerHeuristic(sample.pdf, ctx.environment->Pdf(sample.wi));
        radiance += next_throughput.cwiseProduct(ctx.environment->Radiance(sample.wi)) * weight;
      }
      break;
    }
    if (!continue_path) break;
    throughput = next_throughput;
    dir = sample.wi;
    hit = next;
  }
  return radiance;
}

// First-hit auxiliary passes (albedo, roughness, normal, depth).
Eigen::Vector3d TraceAuxiliary(const Context& ctx, const Eigen::Vector3d& dir,
                               const RayHit& hit) {
  if (!hit.hit) return Eigen::Vector3d::Zero();
  const BsdfParams params = LookUpMaterial(ctx, hit.face, hit.u, hit.v);
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
    if (name == "direct") parsed.direct = true;
    else if (name == "shadows") parsed.shadows = true;
    else if (name == "bounces") parsed.bounces = true;
    else if (name == "specular") parsed.specular = true;
    else if (name == "environment") parsed.environment = true;
    else if (name == "all") parsed = Effects();
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
  if (name == "color") *pass = RenderPass::kColor;
  else if (name == "albedo") *pass = RenderPass::kAlbedo;
  else if (name == "roughness") *pass = RenderPass::kRoughness;
  else if (name == "normal") *pass = RenderPass::kNormal;
  else if (name == "depth") *pass = RenderPass::kDepth;
  else return false;
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

void RenderView(const RenderScene& scene, const Material& material, const ViewSetup& view,
                const RenderOptions& options, Image* image, RenderStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const Context ctx{scene,
                    material,
                    view,
                    options,
                    options.effects.environment ? view.environment : nullptr,
                    options.effects.bounces ? options.bounces : 1,
                    options.effects.specular ? 1.0 : 0.0};
  const int width = view.camera.width;
  const int height = view.camera.height;
  *image = Image(width, height, 4);
  const Rigid3d world_from_cam = view.cam_from_world.Inverse();
  const Eigen::Vector3d center = world_from_cam.translation;
  const Eigen::Matrix3d world_from_cam_rotation = world_from_cam.rotation.toRotationMatrix();
  const double inv_spp = 1.0 / options.spp;

  // Fixed 8×8 tiles; each tile row is one packet of camera rays per sample. The packet
  // composition depends only on the image size, never on scheduling, so images stay
  // bit-identical for any thread count.
  constexpr int kTile = 8;
  const int tiles_x = (width + kTile - 1) / kTile;
  const int tiles_y = (height + kTile - 1) / kTile;
  tbb::enumerable_thread_specific<RenderStats> thread_stats;
  auto render_tile = [&](int tile) {
    // Embree wants flush-to-zero / denormals-are-zero in every tracing thread.
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    RenderStats& local = thread_stats.local();
    const int x0 = (tile % tiles_x) * kTile;
    const int y0 = (tile / tiles_x) * kTile;
    const int count = std::min(kTile, width - x0);
    for (int y = y0; y < std::min(y0 + kTile, height); ++y) {
      Eigen::Vector3d sums[kTile];
      int hits[kTile] = {0};
      for (int i = 0; i < count; ++i) sums[i].setZero();
      for (int s = 0; s < options.spp; ++s) {
        Sampler samplers[kTile];
        Eigen::Vector3d dirs[kTile];
        for (int i = 0; i < count; ++i) {
          const uint64_t pixel = static_cast<uint64_t>(y) * width + (x0 + i);
          samplers[i] = Sampler(options.seed, view.view_index, pixel, static_cast<uint64_t>(s));
          double jitter_x, jitter_y;
          samplers[i].Next2D(&jitter_x, &jitter_y);
          const Eigen::Vector2d film(x0 + i + jitter_x, y + jitter_y);
          dirs[i] = (world_from_cam_rotation * view.camera.CamFromImage(film)).normalized();
        }
        RayHit first_hits[kTile];
        scene.Intersect8(center, dirs, count, first_hits);
        local.camera_rays += count;
        for (int i = 0; i < count; ++i) {
          const Eigen::Vector3d value =
              options.pass == RenderPass::kColor
                  ? TraceRadiance(ctx, &samplers[i], dirs[i], first_hits[i], &local)
                  : TraceAuxiliary(ctx, dirs[i], first_hits[i]);
          if (value.allFinite()) sums[i] += value;
          hits[i] += first_hits[i].hit ? 1 : 0;
        }
      }
      for (int i = 0; i < count; ++i) {
        for (int c = 0; c < 3; ++c) {
          image->at(x0 + i, y, c) = static_cast<float>(sums[i][c] * inv_spp);
        }
        image->at(x0 + i, y, 3) = static_cast<float>(hits[i] * inv_spp);
      }
    }
  };
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(0, tiles_x * tiles_y, render_tile);
  });
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

}  // namespace sft
