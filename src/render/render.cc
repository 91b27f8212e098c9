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
#include "src/render/geometry_derivatives.h"

namespace sft {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
double PowerHeuristic(double pdf_a, double pdf_b) {
  const double a2 = pdf_a * pdf_a;
  const double b2 = pdf_b * pdf_b;
  if (!(a2 + b2 > 0.0) || !std::isfinite(a2 + b2)) return pdf_a >= pdf_b ? 1.0 : 0.0;
  return a2 / (a2 + b2);
}

struct SecondaryEdges;

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
  // Candidates of secondary edge samples; null when they are off.
  const SecondaryEdges* secondary;
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

double RayOffset(const Context& ctx, int face, const Eigen::Vector3d& p) {
  return SurfaceRayOffset(ctx.scene, face, p);
}

// Direction, distance, cosine and BSDF value of a point light seen from the shading point p
// (normal n, outgoing direction wo).
struct PointLightSample {
  Eigen::Vector3d wi;
  double dist = 0.0;
  double cos_i = 0.0;
  Eigen::Vector3d f;
};

// False when the light is below the surface or closer than kMinRelativeLightDistance (the
// contribution is then zero).
bool SamplePointLight(const Context& ctx, const PointLight& light, int face,
                      const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                      const BsdfParams& params, PointLightSample* sample) {
  const Eigen::Vector3d to_light = light.position - p;
  const double dist2 = to_light.squaredNorm();
  const double min_dist = kMinRelativeLightDistance * SurfaceScale(ctx.scene, face, p);
  if (!(dist2 > min_dist * min_dist)) return false;
  sample->dist = std::sqrt(dist2);
  sample->wi = to_light / sample->dist;
  sample->cos_i = n.dot(sample->wi);
  if (sample->cos_i <= 0.0) return false;
  sample->f = EvalBsdf(params, n, wo, sample->wi);
  return true;
}

// Whether the shadow ray from p (started `offset` along it) reaches the light.
bool PointLightVisible(const Context& ctx, const Eigen::Vector3d& p, double offset,
                       const PointLightSample& sample, RenderStats* stats) {
  ++stats->shadow_rays;
  return !ctx.scene.Occluded(p, sample.wi, offset, sample.dist - offset);
}

// (parameter, ∂RGB) pairs, in arrival order (edge terms of one pixel).
using DerivativeList = std::vector<std::pair<int, Eigen::Vector3d>>;

// One pixel's derivatives, summed per parameter as they arrive: an open-addressing hash table
// (linear probing, load ≤ 1/2) over the parameters touched so far. A pixel's paths touch the same
// few faces and texels over and over (every contribution re-emits the corners of the faces behind
// it), so summing on arrival keeps the work per entry O(1) and sorts only the distinct parameters.
class RowAccumulator {
 public:
  RowAccumulator() { Resize(64); }

  void Add(int param, const Eigen::Vector3d& d) {
    uint32_t slot = Hash(param) & mask_;
    while (true) {
      const int key = keys_[slot];
      if (key == param) {
        values_[slot] += d;
        return;
      }
      if (key < 0) break;
      slot = (slot + 1) & mask_;
    }
    keys_[slot] = param;
    values_[slot] = d;
    used_.push_back(slot);
    if (2 * used_.size() > keys_.size()) Grow();
  }

  // Writes the sums (finite ones, times `scale`) sorted by parameter, and empties the table.
  void Flush(double scale, std::vector<JacobianEntry>* merged) {
    merged->clear();
    std::sort(used_.begin(), used_.end(),
              [this](uint32_t a, uint32_t b) { return keys_[a] < keys_[b]; });
    for (const uint32_t slot : used_) {
      const Eigen::Vector3d& sum = values_[slot];
      if (sum.allFinite()) {
        merged->push_back({keys_[slot],
                           {static_cast<float>(sum[0] * scale), static_cast<float>(sum[1] * scale),
                            static_cast<float>(sum[2] * scale)}});
      }
      keys_[slot] = -1;
    }
    used_.clear();
  }

 private:
  static uint32_t Hash(int param) { return static_cast<uint32_t>(param) * 2654435761u; }

  void Resize(size_t capacity) {
    keys_.assign(capacity, -1);
    values_.resize(capacity);
    mask_ = static_cast<uint32_t>(capacity - 1);
  }

  void Grow() {
    std::vector<std::pair<int, Eigen::Vector3d>> entries;
    entries.reserve(used_.size());
    for (const uint32_t slot : used_) entries.emplace_back(keys_[slot], values_[slot]);
    used_.clear();
    Resize(2 * keys_.size());
    for (const auto& [param, d] : entries) Add(param, d);
  }

  std::vector<int> keys_;  // −1: empty.
  std::vector<Eigen::Vector3d> values_;
  std::vector<uint32_t> used_;  // occupied slots, in insertion order.
  uint32_t mask_ = 0;
};

// The light term Q of a contribution, split as Q = q·c with c the part that depends on the
// geometry of the shading point: point light q = I, c = (n·wi)/d² (wi and d follow the point x);
// environment (light- or BSDF-sampled, direction fixed) q = L·scale·w_MIS/pdf, c = n·wi.
struct LightTerm {
  Eigen::Vector3d q;
  double c = 0.0;
  Eigen::Vector3d dc_dn = Eigen::Vector3d::Zero();
  bool follows_point = false;                        // point light: the next three are set.
  Eigen::Vector3d dc_dx = Eigen::Vector3d::Zero();   // ∂c/∂x = (3(n·wi)wi − n)/d³.
  Eigen::Matrix3d dwi_dx = Eigen::Matrix3d::Zero();  // ∂wi/∂x = −(I − wi wiᵀ)/d.
};

// Bookkeeping of one path's derivatives. A path's light contributions have the form
//   C = (s_0 ⊙ … ⊙ s_{i−1}) ⊙ f_i(wo_i, wi) ⊙ Q,
// with s_k = f_k(wo_k, wi_k)·|n·wi_k|/pdf_k the scatter factor of vertex k (pdf detached) and Q
// the light term. ∂C/∂θ for a parameter of vertex j < i replaces s_j by ∂s_j/∂θ; for vertex i it
// replaces f_i by ∂f_i/∂θ. `excluded_[j]` keeps Π_{k<i, k≠j} s_k so that no division by a
// possibly zero factor is needed.
//
// Vertex coordinates enter (directions detached, so wo and sampled wi stay fixed) through the
// normal n_k of every vertex's face — s_k, f_i and c depend on it — and, for point lights,
// through the position x_i (wi = (L − x_i)/d, c), which moves with the faces hit before
// (PointJacobian). Texel lookups are piecewise constant and contribute nothing.
class PathDerivatives {
 public:
  explicit PathDerivatives(const Context& ctx)
      : ctx_(ctx), vertices_(ctx.request->params.vertices) {}

  // Starts a new path whose derivatives go to `out`. (One object serves many paths: its
  // per-scatter storage is large and needs no initialization.)
  void Reset(RowAccumulator* out) {
    out_ = out;
    count_ = 0;
    point_.count = 0;
    point_.valid = true;
  }
  RowAccumulator* out() const { return out_; }

  // The path reached a new vertex on face `face` (hit barycentrics `barycentrics`, ray direction
  // `dir`), shaded with normal sign·n̂. `track_point`: keep x's Jacobian (point lights exist).
  void SetVertex(int face, const Eigen::Vector3d& barycentrics, const Eigen::Vector3d& dir,
                 double sign, bool track_point) {
    if (!vertices_) return;
    const Eigen::Vector3i& corners = ctx_.scene.faces()[face];
    const auto& p = ctx_.scene.positions();
    corners_ = corners;
    normal_ = NormalChain(p[corners[0]], p[corners[1]], p[corners[2]], sign);
    if (track_point) point_.Advance(count_ == 0, dir, normal_.unit_normal(), barycentrics, corners);
  }

  // A light contribution f ⊙ (q·c) at the current vertex (index = number of scatters so far),
  // with shading normal n and directions wo, wi.
  void AddContribution(const Eigen::Vector3d& prefix, const SurfaceMaterial& surface,
                       const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                       const Eigen::Vector3d& wi, const Eigen::Vector3d& f, const LightTerm& light,
                       int light_index) {
    const Eigen::Vector3d q = light.q * light.c;
    const Eigen::Vector3d contribution = prefix.cwiseProduct(f).cwiseProduct(q);
    const bool material = ctx_.request->params.albedo || ctx_.request->params.roughness ||
                          ctx_.request->params.specular;
    const Eigen::Vector3d f_q = f.cwiseProduct(q);
    if (material) {
      AddMaterial(surface, EvalBsdfDerivatives(surface.params, n, wo, wi, ctx_.specular_scale),
                  prefix.cwiseProduct(q));
      for (int j = 0; j < count_; ++j) {
        AddMaterial(scatters_[j].surface, scatters_[j].d_s, excluded_[j].cwiseProduct(f_q));
      }
    }
    if (ctx_.request->params.lights && light_index >= 0) {
      out_->Add(ctx_.layout->LightOffset() + light_index, contribution);
    }
    if (!vertices_) return;
    // ∂(f ⊙ q·c) = (f ⊙ q)·∂c + c·q·∂g, g the glossy term (the diffuse term is constant).
    Eigen::Vector3d dg_dn, dg_dwi;
    EvalGlossyWithGradient(surface.params, n, wo, wi, &dg_dn, &dg_dwi);
    const Eigen::Vector3d base = prefix.cwiseProduct(light.q);
    const Eigen::Vector3d base_f = base.cwiseProduct(f);
    const Eigen::Matrix3d d_n =
        base_f * light.dc_dn.transpose() + light.c * base * dg_dn.transpose();
    AddFace(corners_, normal_.Map(d_n));
    if (light.follows_point && point_.valid) {
      const Eigen::Matrix3d d_x =
          base_f * light.dc_dx.transpose() + light.c * base * (dg_dwi.transpose() * light.dwi_dx);
      for (int e = 0; e < point_.count; ++e) {
        const Eigen::Matrix3d g = d_x * point_.m[e];
        for (int k = 0; k < 3; ++k) Emit(3 * point_.vertex[e] + k, g.col(k));
      }
    }
    for (int j = 0; j < count_; ++j) {
      const Eigen::Vector3d w = excluded_[j].cwiseProduct(f_q);
      AddFace(scatters_[j].corners, w.asDiagonal() * scatters_[j].ds_dcorners);
    }
  }

  // A boundary (edge) term at the current vertex: Σ_j weight·(rows_j·∂y/∂p_{vertices_j}) for
  // the vertices that move the curve point, plus weight·(x_row·∂x/∂θ) for the motion of the
  // vertex itself (chained to the faces hit before; dropped when that chain is undefined).
  void AddBoundary(const Eigen::Vector3d& weight, const int* vertices, const Eigen::Vector3d* rows,
                   int count, const Eigen::Vector3d& x_row) {
    if (!vertices_ || !weight.allFinite()) return;
    for (int j = 0; j < count; ++j) {
      for (int k = 0; k < 3; ++k) {
        if (std::isfinite(rows[j][k])) Emit(3 * vertices[j] + k, weight * rows[j][k]);
      }
    }
    if (!point_.valid) return;
    for (int e = 0; e < point_.count; ++e) {
      const Eigen::RowVector3d g = x_row.transpose() * point_.m[e];
      for (int k = 0; k < 3; ++k) {
        if (std::isfinite(g[k])) Emit(3 * point_.vertex[e] + k, weight * g[k]);
      }
    }
  }

  // The path continues from the current vertex with scatter factor s = f·(n·wi)/pdf.
  void AddScatter(const Eigen::Vector3d& prefix, const SurfaceMaterial& surface,
                  const Eigen::Vector3d& n, const Eigen::Vector3d& wo, const Eigen::Vector3d& wi,
                  const Eigen::Vector3d& f, double pdf) {
    CHECK_LT(count_, kMaxScatters);
    const double cos_over_pdf = n.dot(wi) / pdf;
    const Eigen::Vector3d s = f * cos_over_pdf;
    for (int j = 0; j < count_; ++j) excluded_[j] = excluded_[j].cwiseProduct(s);
    excluded_[count_] = prefix;
    Scatter& scatter = scatters_[count_];
    scatter.surface = surface;
    scatter.d_s = EvalBsdfDerivatives(surface.params, n, wo, wi, ctx_.specular_scale);
    scatter.d_s.d_albedo *= cos_over_pdf;
    scatter.d_s.d_roughness *= cos_over_pdf;
    scatter.d_s.d_specular *= cos_over_pdf;
    if (vertices_) {
      // ∂s/∂n = (f·wiᵀ + (n·wi)·1·∂g/∂nᵀ)/pdf.
      Eigen::Vector3d dg_dn, dg_dwi;
      EvalGlossyWithGradient(surface.params, n, wo, wi, &dg_dn, &dg_dwi);
      const Eigen::Matrix3d ds_dn =
          (f * wi.transpose() + n.dot(wi) * Eigen::Vector3d::Ones() * dg_dn.transpose()) / pdf;
      scatter.corners = corners_;
      scatter.ds_dcorners = normal_.Map(ds_dn);
    }
    ++count_;
  }

 private:
  struct Scatter {
    SurfaceMaterial surface;
    BsdfDerivatives d_s;
    Eigen::Vector3i corners;
    Eigen::Matrix<double, 3, 9> ds_dcorners;  // ∂s/∂(corner coordinates), rows = channels.
  };

  void Emit(int param, const Eigen::Vector3d& d) {
    if (d[0] != 0.0 || d[1] != 0.0 || d[2] != 0.0) out_->Add(param, d);
  }
  void AddFace(const Eigen::Vector3i& corners, const Eigen::Matrix<double, 3, 9>& g) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) Emit(3 * corners[j] + k, g.col(3 * j + k));
    }
  }

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
        out_->Add(first + c, v);
      }
    }
    if (sel.roughness && d.d_roughness != 0.0) {
      out_->Add(layout.RoughnessOffset() + surface.roughness_texel, base * d.d_roughness);
    }
    if (sel.specular && d.d_specular != 0.0) {
      out_->Add(layout.SpecularIndex(), base * d.d_specular);
    }
  }

  // A path scatters at most bounces − 1 ≤ 15 times (RenderOptions::Check caps bounces at 16).
  static constexpr int kMaxScatters = 16;
  const Context& ctx_;
  RowAccumulator* out_ = nullptr;
  const bool vertices_;
  int count_ = 0;
  Scatter scatters_[kMaxScatters];
  std::array<Eigen::Vector3d, kMaxScatters> excluded_;
  // The current vertex's face and normal chain, and its position's Jacobian.
  Eigen::Vector3i corners_ = Eigen::Vector3i::Zero();
  NormalChain normal_;
  PointJacobian point_;
};

// Secondary edge samples at a path vertex (defined with the edge sampling below).
void AddSecondaryEdgeSamples(const Context& ctx, const Sampler& path_sampler, int depth, int face,
                             const Eigen::Vector3d& throughput, const Eigen::Vector3d& x,
                             const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                             const BsdfParams& params, PathDerivatives* path, RenderStats* stats);

// Radiance along the camera ray with direction `dir` whose first intersection is `hit` (traced
// by the caller, in packets). When `path` is non-null (its Reset called by the caller), the
// path's parameter derivatives are added to its accumulator. `first_depth` > 0 continues a
// path whose first first_depth segments were traced elsewhere (the ray along `dir` is then
// segment first_depth + 1): the radiance leaving `hit` towards −dir with the remaining depth.
Eigen::Vector3d TraceRadiance(const Context& ctx, Sampler* sampler, Eigen::Vector3d dir, RayHit hit,
                              RenderStats* stats, PathDerivatives* path, int first_depth = 0) {
  const Effects& effects = ctx.options.effects;
  Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
  if (!hit.hit) {
    if (ctx.environment != nullptr && ctx.view.environment_background) {
      radiance = ctx.view.environment_scale * ctx.environment->Radiance(dir);
      if (path != nullptr && ctx.request->params.lights && ctx.view.environment_light_index >= 0) {
        path->out()->Add(ctx.layout->LightOffset() + ctx.view.environment_light_index, radiance);
      }
    }
    return radiance;
  }
  const bool detached = &ctx.sampling_material != &ctx.material;
  Eigen::Vector3d throughput = Eigen::Vector3d::Ones();
  for (int depth = first_depth;; ++depth) {
    const Eigen::Vector3d p = ctx.scene.Point(hit.face, hit.u, hit.v);
    Eigen::Vector3d n = ctx.scene.FaceNormal(hit.face);
    if (n.isZero()) break;  // degenerate triangle: no defined surface, nothing reflected.
    const Eigen::Vector3d wo = -dir;
    const double sign = n.dot(wo) < 0.0 ? -1.0 : 1.0;
    n *= sign;  // two-sided shading.
    if (path) {
      path->SetVertex(hit.face, Eigen::Vector3d(1.0 - hit.u - hit.v, hit.u, hit.v), dir, sign,
                      !ctx.view.point_lights.empty() || ctx.secondary != nullptr);
    }
    const SurfaceMaterial surface = LookUpMaterial(ctx, ctx.material, hit.face, hit.u, hit.v);
    const BsdfParams& params = surface.params;
    const BsdfParams sampling =
        detached ? LookUpMaterial(ctx, ctx.sampling_material, hit.face, hit.u, hit.v).params
                 : params;
    const double offset = RayOffset(ctx, hit.face, p);
    const Eigen::Vector3d p_off = p + offset * n;
    const bool lit_here = depth > 0 || effects.direct;

    // Adds throughput ⊙ f ⊙ (q·c) to the radiance (and its derivatives).
    auto contribute = [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& f,
                          const LightTerm& light, int light_index) {
      radiance += throughput.cwiseProduct(f).cwiseProduct(light.q) * light.c;
      if (path) path->AddContribution(throughput, surface, n, wo, wi, f, light, light_index);
    };

    if (lit_here) {
      for (const PointLight& light : ctx.view.point_lights) {
        PointLightSample ls;
        if (!SamplePointLight(ctx, light, hit.face, p, n, wo, params, &ls)) continue;
        if (ls.f.isZero() && !path) continue;
        if (effects.shadows && !PointLightVisible(ctx, p, offset, ls, stats)) continue;
        LightTerm term;
        term.q = light.intensity;
        term.c = ls.cos_i / (ls.dist * ls.dist);
        if (path) {
          const double dist2 = ls.dist * ls.dist;
          term.dc_dn = ls.wi / dist2;
          term.follows_point = true;
          term.dc_dx = (3.0 * ls.cos_i * ls.wi - n) / (dist2 * ls.dist);
          term.dwi_dx = -(Eigen::Matrix3d::Identity() - ls.wi * ls.wi.transpose()) / ls.dist;
        }
        contribute(ls.wi, ls.f, term, light.light_index);
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
            bool visible = !f.isZero() || path != nullptr;
            if (visible && effects.shadows) {
              ++stats->shadow_rays;
              visible = !ctx.scene.Occluded(p, wi, offset, kInfinity);
            }
            if (visible) {
              // Without shadows the BSDF-sampled rays cannot tell whether the light is seen, so
              // the environment is lit by light sampling alone (weight 1).
              const double weight =
                  effects.shadows ? PowerHeuristic(pdf_light, BsdfPdf(sampling, n, wo, wi)) : 1.0;
              LightTerm term;
              term.q = le * (ctx.view.environment_scale * weight / pdf_light);
              term.c = cos_i;
              term.dc_dn = wi;
              contribute(wi, f, term, ctx.view.environment_light_index);
            }
          }
        }
      }
    }

    if (path != nullptr && ctx.secondary != nullptr) {
      AddSecondaryEdgeSamples(ctx, *sampler, depth, hit.face, throughput, p, n, wo, params, path,
                              stats);
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
        LightTerm term;
        term.q = ctx.environment->Radiance(wi) * (ctx.view.environment_scale * weight / sample.pdf);
        term.c = n.dot(wi);
        term.dc_dn = wi;
        contribute(wi, f, term, ctx.view.environment_light_index);
      }
      break;
    }
    if (!continue_path) break;
    const Eigen::Vector3d scatter = f * cos_over_pdf;
    if (path) path->AddScatter(throughput, surface, n, wo, wi, f, sample.pdf);
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

// ---------------------------------------------------------------------------------------------
// Visibility derivatives by edge sampling (Li et al. 2018, "Differentiable Monte Carlo ray
// tracing through edge sampling", §3–4). The pixel integral I = ∫_pixel L(q) dq has, besides the
// interior term, a boundary term wherever L jumps along a curve in the image that moves with the
// vertices:  ∂I/∂θ += ∫_curve (L(q⁻) − L(q⁺)) · (m·∂q/∂θ) dl,  m the curve's unit normal, q± the
// sides q ± εm. The curves handled here:
//   primary edges: the projection of every mesh edge where the image is discontinuous —
//     silhouettes (adjacent faces facing opposite ways from the camera), boundary and
//     non-manifold edges, and creases (flat shading: any edge whose faces are not coplanar);
//   shadow edges: the shadow that a silhouette edge as seen from a point light casts on the
//     first surface behind it, as seen by the camera (the receiver's motion included);
//   texel boundaries: where the mesh-colors albedo or roughness differs on the two sides of a
//     texel grid line inside a face (α or β = k/r) or of an edge between coplanar faces (not a
//     primary edge). The points y = Σ_k b_k·p_k of such a line have fixed barycentrics b, so
//     ∂y/∂p_k = b_k·I, and the jump is that of the full paths across the line.
// Sampling: a curve is chosen with probability ∝ its length (projected length for primary
// edges, angle subtended at the light for shadow edges, projected length × the size of the
// material jump for texel boundaries), a point uniformly in its parameter s; the estimator is
// ΔL·(m·∂q/∂θ)·|dq/ds|/pdf, credited to the pixel holding q. Both sides are traced with the same
// random numbers, so away from a real jump ΔL is (nearly) zero.
// Not handled (documented in derivatives.h): jumps seen through a bounce (shadows, silhouettes or
// texel boundaries in reflections), occlusion of the environment light and of indirect light (Li
// et al.'s secondary edges for hemispherical integrals).

// Sides of an edge point are traced this far from it (pixels).
constexpr double kEdgeSideOffset = 1e-3;
// Edge samples are drawn and reduced in chunks of this many (deterministic for any threads).
constexpr int kEdgeChunk = 1024;
// Sample streams of edge samples are told apart from pixel samples by this key.
constexpr uint64_t kPrimaryEdgeKey = 0xE1D6E00000000000ull;
constexpr uint64_t kShadowEdgeKey = 0xE1D6500000000000ull;
constexpr uint64_t kTexelEdgeKey = 0xE1D6700000000000ull;
// Texel look-ups either side of a texel boundary are made this far from it (barycentric units;
// far above MeshColors' lattice snap of 1e-9 texels, far below a texel).
constexpr double kTexelSideOffset = 1e-6;

// One boundary-term contribution: pixel, parameter, ∂RGB (already divided by the sample count).
struct EdgeEntry {
  int pixel;
  int param;
  Eigen::Vector3d d;
};

// A curve to sample: mesh edge `edge` over the parameter range [s0, s1], with sampling weight.
struct EdgeCandidate {
  int edge;
  double s0, s1;
  double weight;
};

// A texel boundary segment to sample: the points Σ_k b_k(s)·p_k of face `face` (corners p_k),
// b(s) = b0 + s·(b1 − b0), over s ∈ [s0, s1] (the part in view); `other` is the face across it
// (`face` itself for a grid line inside the face, the neighbour for a coplanar mesh edge).
struct TexelCandidate {
  int face, other;
  Eigen::Vector3d b0, b1;
  Eigen::Vector3d c0, c1;  // the same points as barycentrics of `other`.
  double s0, s1;
  double weight;
};

// Picks a candidate ∝ weight from the cumulative weights.
int PickCandidate(const std::vector<double>& cumulative, double u) {
  const double target = u * cumulative.back();
  const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), target);
  return std::min<int>(static_cast<int>(it - cumulative.begin()),
                       static_cast<int>(cumulative.size()) - 1);
}

// Walker's alias table (Vose's construction): draws index i with probability w_i/Σw in O(1),
// where a binary search over cumulative weights costs a cache miss per level (secondary edge
// candidates are drawn 16 times per path vertex).
class AliasTable {
 public:
  AliasTable() = default;
  // Weights must be finite and ≥ 0 with a positive sum.
  explicit AliasTable(const std::vector<double>& weights) : cells_(weights.size()) {
    const int n = static_cast<int>(weights.size());
    for (double w : weights) total_ += w;
    std::vector<double> scaled(n);
    std::vector<int> small, large;
    for (int i = 0; i < n; ++i) {
      scaled[i] = weights[i] * n / total_;
      (scaled[i] < 1.0 ? small : large).push_back(i);
    }
    while (!small.empty() && !large.empty()) {
      const int s = small.back(), l = large.back();
      small.pop_back();
      cells_[s] = {scaled[s], l};
      scaled[l] -= 1.0 - scaled[s];
      if (scaled[l] < 1.0) {
        large.pop_back();
        small.push_back(l);
      }
    }
    // Left-overs are 1 up to rounding.
    for (int i : small) cells_[i] = {1.0, i};
    for (int i : large) cells_[i] = {1.0, i};
  }
  bool empty() const { return cells_.empty(); }
  double total() const { return total_; }
  int Sample(double u) const {
    const double scaled = u * static_cast<double>(cells_.size());
    const int i = std::min(static_cast<int>(scaled), static_cast<int>(cells_.size()) - 1);
    return scaled - i < cells_[i].probability ? i : cells_[i].alias;
  }

 private:
  struct Cell {
    double probability = 1.0;  // of keeping index i in cell i.
    int alias = 0;
  };
  std::vector<Cell> cells_;
  double total_ = 0.0;
};

// Normalized image-plane bounds (x/z, y/z) of the view, with a margin, for clipping edges.
struct FrustumBounds {
  double u_min, u_max, v_min, v_max;
  double z_min;
};

FrustumBounds ViewFrustum(const Context& ctx) {
  const Camera& camera = ctx.view.camera;
  FrustumBounds b{kInfinity, -kInfinity, kInfinity, -kInfinity, 0.0};
  constexpr int kSteps = 16;
  for (int i = 0; i <= kSteps; ++i) {
    const double t = static_cast<double>(i) / kSteps;
    for (const Eigen::Vector2d& pixel :
         {Eigen::Vector2d(t * camera.width, 0.0), Eigen::Vector2d(t * camera.width, camera.height),
          Eigen::Vector2d(0.0, t * camera.height),
          Eigen::Vector2d(camera.width, t * camera.height)}) {
      const Eigen::Vector3d ray = camera.CamFromImage(pixel);
      b.u_min = std::min(b.u_min, ray.x());
      b.u_max = std::max(b.u_max, ray.x());
      b.v_min = std::min(b.v_min, ray.y());
      b.v_max = std::max(b.v_max, ray.y());
    }
  }
  const double mu = 0.05 * (b.u_max - b.u_min), mv = 0.05 * (b.v_max - b.v_min);
  b.u_min -= mu;
  b.u_max += mu;
  b.v_min -= mv;
  b.v_max += mv;
  b.z_min = 1e-7 * ctx.scene.extent();
  return b;
}

// Clips the camera-frame segment a + s(b − a), s ∈ [0, 1], to the frustum; false when empty.
bool ClipSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const FrustumBounds& f,
                 double* s0, double* s1) {
  *s0 = 0.0;
  *s1 = 1.0;
  // Half-spaces h(p) ≥ 0, each linear in p.
  auto clip = [&](double ha, double hb) {
    if (ha >= 0.0 && hb >= 0.0) return true;
    if (ha < 0.0 && hb < 0.0) return false;
    const double s = ha / (ha - hb);
    if (ha < 0.0)
      *s0 = std::max(*s0, s);
    else
      *s1 = std::min(*s1, s);
    return *s0 < *s1;
  };
  return clip(a.z() - f.z_min, b.z() - f.z_min) &&
         clip(a.x() - f.u_min * a.z(), b.x() - f.u_min * b.z()) &&
         clip(f.u_max * a.z() - a.x(), f.u_max * b.z() - b.x()) &&
         clip(a.y() - f.v_min * a.z(), b.y() - f.v_min * b.z()) &&
         clip(f.v_max * a.z() - a.y(), f.v_max * b.z() - b.y()) && *s1 - *s0 > 0.0;
}

// The unit normals of a manifold edge's faces, f1's oriented consistently with f0's across the
// edge (MeshEdge::flip1), so that the classification below does not depend on face winding: two
// coplanar faces are coplanar whichever way each is wound.
void ConsistentEdgeNormals(const RenderScene& scene, const MeshEdge& edge, Eigen::Vector3d* n0,
                           Eigen::Vector3d* n1) {
  *n0 = scene.FaceNormal(edge.f0);
  *n1 = edge.flip1 * scene.FaceNormal(edge.f1);
}

// Whether flat-shaded radiance can jump across the edge as seen from `eye`: boundary,
// non-manifold or degenerate-neighbour edges always; else silhouettes w.r.t. eye (the two faces,
// consistently oriented, face opposite ways) and (when `creases`) edges between faces that are
// not coplanar.
bool IsDiscontinuityEdge(const RenderScene& scene, const MeshEdge& edge, const Eigen::Vector3d& eye,
                         bool creases) {
  if (edge.num_faces != 2) return true;
  Eigen::Vector3d n0, n1;
  ConsistentEdgeNormals(scene, edge, &n0, &n1);
  if (n0.isZero() || n1.isZero()) return true;
  const Eigen::Vector3d to_eye = eye - scene.positions()[edge.v0];
  if ((n0.dot(to_eye) > 0.0) != (n1.dot(to_eye) > 0.0)) return true;
  return creases && std::abs(n0.dot(n1)) < 1.0 - 1e-12;
}

// Directions of the camera rays through the two sides q ∓ εm of an edge point q (index 0: −).
void SideDirections(const Context& ctx, const Eigen::Matrix3d& world_from_cam_rotation,
                    const Eigen::Vector2d& q, const Eigen::Vector2d& m, Eigen::Vector3d dirs[2]) {
  for (int i = 0; i < 2; ++i) {
    const double side = i == 0 ? -1.0 : 1.0;
    dirs[i] =
        (world_from_cam_rotation * ctx.view.camera.CamFromImage(q + side * kEdgeSideOffset * m))
            .normalized();
  }
}

// Relative sampling density of a primary edge, ∝ the size of the jump expected across it:
// 1 where the image may jump to something unrelated (silhouettes, boundary, non-manifold and
// degenerate-neighbour edges); for a crease between faces with unit normals n0, n1 the
// flat-shaded radiance jumps by about |∂L/∂n|·|n0 − n1|, so |n0 − n1| (at least 1/16, because a
// glossy highlight makes ∂L/∂n large). Any positive density leaves the estimator unbiased (the
// pdf includes it); this one spends the samples where the derivative is.
double PrimaryEdgeImportance(const RenderScene& scene, const MeshEdge& edge,
                             const Eigen::Vector3d& eye) {
  if (edge.num_faces != 2) return 1.0;
  Eigen::Vector3d n0, n1;
  ConsistentEdgeNormals(scene, edge, &n0, &n1);
  if (n0.isZero() || n1.isZero()) return 1.0;
  const Eigen::Vector3d to_eye = eye - scene.positions()[edge.v0];
  if ((n0.dot(to_eye) > 0.0) != (n1.dot(to_eye) > 0.0)) return 1.0;
  return std::clamp((n0 - n1).norm(), 1.0 / 16.0, 1.0);
}

// The camera rays through the two sides q ∓ εm of a curve point and their first hits.
void TraceSides(const Context& ctx, const Eigen::Matrix3d& world_from_cam_rotation,
                const Eigen::Vector3d& center, const Eigen::Vector2d& q, const Eigen::Vector2d& m,
                Eigen::Vector3d dirs[2], RayHit hits[2], RenderStats* stats) {
  SideDirections(ctx, world_from_cam_rotation, q, m, dirs);
  for (int i = 0; i < 2; ++i) hits[i] = ctx.scene.Intersect(center, dirs[i], 0.0, kInfinity);
  stats->camera_rays += 2;
}

// L(q − εm) − L(q + εm) from the full camera paths through the two side rays, traced with the
// same random numbers on both sides so that only the jump remains. Zero when a side's radiance
// is not finite.
Eigen::Vector3d SideRadianceJump(const Context& ctx, const Eigen::Vector3d dirs[2],
                                 const RayHit hits[2], const Sampler& sampler, RenderStats* stats) {
  Eigen::Vector3d jump = Eigen::Vector3d::Zero();
  for (int i = 0; i < 2; ++i) {
    Sampler copy = sampler;
    const Eigen::Vector3d radiance = TraceRadiance(ctx, &copy, dirs[i], hits[i], stats, nullptr);
    if (!radiance.allFinite()) return Eigen::Vector3d::Zero();
    jump += i == 0 ? radiance : -radiance;
  }
  return jump;
}

// Relative depth margin by which a surface must lie in front of an edge's own face, along a side
// ray, to count as hiding the edge (not just float noise of Embree's single-precision t).
constexpr double kEdgeOcclusionMargin = 1e-5;

// The face of `edge` that the camera ray center + t·dir, passing just beside the edge, meets on
// its own side of the edge: among the edge's faces lying on that side of the plane through the
// centre and the edge (one each for a crease, both for a silhouette, none on a silhouette's outer
// side), the one whose plane the ray meets first — the one in front. On success *hit is that
// ray's hit on the face's plane, its barycentrics clamped to the triangle (the ray passes within
// a hair of the edge, so the clamp moves the point by at most that much).
bool EdgeFaceHit(const RenderScene& scene, const MeshEdge& edge, const Eigen::Vector3d& center,
                 const Eigen::Vector3d& dir, RayHit* hit) {
  if (edge.num_faces != 1 && edge.num_faces != 2) return false;
  const auto& positions = scene.positions();
  const Eigen::Vector3d& a = positions[edge.v0];
  const Eigen::Vector3d edge_plane = (a - center).cross(positions[edge.v1] - center);
  const double ray_side = edge_plane.dot(dir);
  hit->hit = false;
  for (const int face : {edge.f0, edge.f1}) {
    if (face < 0) continue;
    const Eigen::Vector3i& corners = scene.faces()[face];
    int third = 0;
    while (third < 2 && (scene.WeldedVertex(corners[third]) == edge.v0 ||
                         scene.WeldedVertex(corners[third]) == edge.v1)) {
      ++third;
    }
    if (edge_plane.dot(positions[corners[third]] - center) * ray_side <= 0.0) continue;
    const Eigen::Vector3d n = scene.FaceNormal(face);
    const double t = n.dot(a - center) / n.dot(dir);
    if (!(t > 0.0) || !std::isfinite(t) || (hit->hit && t >= hit->t)) continue;
    // Barycentrics of x = center + t·dir: x − p0 = u·e1 + v·e2, N = e1 × e2.
    const Eigen::Vector3d& p0 = positions[corners[0]];
    const Eigen::Vector3d e1 = positions[corners[1]] - p0, e2 = positions[corners[2]] - p0;
    const Eigen::Vector3d normal = e1.cross(e2);
    const double norm2 = normal.squaredNorm();
    if (!(norm2 > 0.0)) continue;
    const Eigen::Vector3d x = center + t * dir - p0;
    double u = std::max(0.0, x.cross(e2).dot(normal) / norm2);
    double v = std::max(0.0, e1.cross(x).dot(normal) / norm2);
    if (u + v > 1.0) {
      const double sum = u + v;
      u /= sum;
      v /= sum;
    }
    hit->hit = true;
    hit->t = t;
    hit->face = face;
    hit->u = u;
    hit->v = v;
  }
  return hit->hit;
}

// L(q − εm) − L(q + εm) across primary edge `edge` at image point q, for camera paths with the
// same random numbers on both sides. Zero without tracing paths when the edge is hidden there:
// both sides see the same face (or nothing), or a side sees a surface in front of the edge's own
// face on that side.
//
// A side ray must see the edge's face on its side (EdgeFaceHit) for the difference to be this
// edge's jump. Where that face is narrower than ε in the image — near a vertex where another
// edge of the face meets this one at a small angle, as for the nearly edge-on faces along a
// silhouette — the ray passes it and lands on whatever lies beyond the other edge (a
// neighbouring face, the background), so the difference would be the jump across both edges,
// and the other edge's jump, sampled on its own, would be counted twice. That side is then
// shaded on the face itself (the ray's hit on its plane). Without this, silhouette derivatives
// of icospheres came out 1.3–7.5% too large (VertexDerivativesTest.
// SilhouetteAgainstBackgroundMatchesExactAreaDerivative).
Eigen::Vector3d PrimaryJump(const Context& ctx, const Eigen::Matrix3d& world_from_cam_rotation,
                            const Eigen::Vector3d& center, const MeshEdge& edge,
                            const Eigen::Vector2d& q, const Eigen::Vector2d& m,
                            const Sampler& sampler, RenderStats* stats) {
  Eigen::Vector3d dirs[2];
  RayHit hits[2];
  TraceSides(ctx, world_from_cam_rotation, center, q, m, dirs, hits, stats);
  for (int i = 0; i < 2; ++i) {
    RayHit own;
    if (!EdgeFaceHit(ctx.scene, edge, center, dirs[i], &own)) continue;
    if (hits[i].hit && hits[i].face == own.face) continue;
    if (hits[i].hit && hits[i].face != edge.f0 && hits[i].face != edge.f1 &&
        hits[i].t < own.t * (1.0 - kEdgeOcclusionMargin)) {
      return Eigen::Vector3d::Zero();
    }
    hits[i] = own;
  }
  if (hits[0].hit == hits[1].hit && (!hits[0].hit || hits[0].face == hits[1].face)) {
    return Eigen::Vector3d::Zero();
  }
  return SideRadianceJump(ctx, dirs, hits, sampler, stats);
}

// L(q − εm) − L(q + εm) across a texel boundary between faces `face_a` and `face_b` (equal for a
// grid line inside a face). Zero without tracing paths unless the two sides see these faces, one
// each: otherwise the boundary is hidden at q, or q is where it meets a face border (where the
// primary edge term, if any, takes over).
Eigen::Vector3d TexelJump(const Context& ctx, const Eigen::Matrix3d& world_from_cam_rotation,
                          const Eigen::Vector3d& center, const Eigen::Vector2d& q,
                          const Eigen::Vector2d& m, int face_a, int face_b, const Sampler& sampler,
                          RenderStats* stats) {
  Eigen::Vector3d dirs[2];
  RayHit hits[2];
  TraceSides(ctx, world_from_cam_rotation, center, q, m, dirs, hits, stats);
  if (!hits[0].hit || !hits[1].hit) return Eigen::Vector3d::Zero();
  const bool seen = (hits[0].face == face_a && hits[1].face == face_b) ||
                    (hits[0].face == face_b && hits[1].face == face_a);
  if (!seen) return Eigen::Vector3d::Zero();
  return SideRadianceJump(ctx, dirs, hits, sampler, stats);
}

// Interior lines k/r (0 < k < r) of the albedo and the roughness texel grids, sorted; a line of
// both grids (equal fractions) appears once.
std::vector<double> TexelGridLines(const Material& material) {
  std::vector<double> lines;
  for (const int r : {material.albedo.resolution(), material.roughness.resolution()}) {
    for (int k = 1; k < r; ++k) lines.push_back(static_cast<double>(k) / r);
  }
  std::sort(lines.begin(), lines.end());
  // Distinct fractions k/r ≠ k'/r' differ by at least 1/(r·r'), far above 1e-9.
  lines.erase(
      std::unique(lines.begin(), lines.end(), [](double a, double b) { return b - a < 1e-9; }),
      lines.end());
  return lines;
}

// Whether the texels of `face` are not all equal.
bool FaceTexelsVary(const MeshColors& colors, int face) {
  const int n = MeshColors::TexelsPerFace(colors.resolution());
  const double* first = colors.texel(face * n);
  for (int k = 1; k < n; ++k) {
    const double* texel = colors.texel(face * n + k);
    for (int c = 0; c < colors.channels(); ++c) {
      if (texel[c] != first[c]) return true;
    }
  }
  return false;
}

// Size of the material jump between the barycentric points ab_a of face_a and ab_b of face_b:
// the mean absolute albedo difference over RGB plus, when the glossy lobe is on, the absolute
// roughness difference (without it roughness changes nothing). Zero when the two points look
// the same. It only weights the sampling (the pdf accounts for it), so any scale will do.
double MaterialJump(const Material& material, bool glossy, int face_a, const Eigen::Vector2d& ab_a,
                    int face_b, const Eigen::Vector2d& ab_b) {
  const double* a = material.albedo.texel(material.albedo.TexelIndex(face_a, ab_a.x(), ab_a.y()));
  const double* b = material.albedo.texel(material.albedo.TexelIndex(face_b, ab_b.x(), ab_b.y()));
  double size = (std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2])) / 3.0;
  if (glossy) {
    size += std::abs(
        *material.roughness.texel(material.roughness.TexelIndex(face_a, ab_a.x(), ab_a.y())) -
        *material.roughness.texel(material.roughness.TexelIndex(face_b, ab_b.x(), ab_b.y())));
  }
  return std::isfinite(size) ? size : 0.0;
}

// A texel boundary segment in 3D: the points Σ_k b_k(s)·p_k, b(s) = b0 + s·(b1 − b0), s ∈ [0, 1],
// of face `face` (corners p_k), separating texels whose material differs by `size`
// (MaterialJump); `other` is the face across it (`face` itself for a grid line inside the face,
// the neighbour for mesh edge `edge` between coplanar faces; edge −1 for grid lines), and c0, c1
// the ends as barycentrics of `other` (= b0, b1 for grid lines).
struct TexelSegment {
  int face, other, edge;
  Eigen::Vector3d b0, b1;
  double size;
  Eigen::Vector3d c0, c1;
};

// The vertices that move a boundary point y, with rows_j = (∂y/∂p_j)ᵀ·row for a row vector `row`
// (some linear functional of y's motion). A vertex may appear more than once (the sums are what
// count).
struct BoundaryRows {
  static constexpr int kCapacity = 24;  // 2 × 8 edge-end copies (scene.cc) + 3 receiver corners.
  int count = 0;
  int vertices[kCapacity];
  Eigen::Vector3d rows[kCapacity];
  void Add(int vertex, const Eigen::Vector3d& row) {
    CHECK_LT(count, kCapacity);
    vertices[count] = vertex;
    rows[count++] = row;
  }
};

// Rows of the point a + s(b − a) of welded edge `edge`: each end moves with the copies of it that
// the edge's faces use, shared as EdgeCopy describes (one copy with weight 1 on a welded mesh).
void AddEdgePointRows(const RenderScene& scene, const MeshEdge& edge, double s,
                      const Eigen::Vector3d& row, BoundaryRows* out) {
  const EdgeCopy* copies = scene.edge_copies().data() + edge.first_copy;
  for (int i = 0; i < edge.num_copies0; ++i) {
    out->Add(copies[i].vertex, (copies[i].weight * (1.0 - s)) * row);
  }
  for (int i = edge.num_copies0; i < edge.num_copies0 + edge.num_copies1; ++i) {
    out->Add(copies[i].vertex, (copies[i].weight * s) * row);
  }
}

// Rows of the texel-boundary point with barycentrics b on `face` and c on `other` (∂y/∂p_k =
// b_k·I). On an edge between two coplanar faces the motion is shared half and half between each
// face's own corners, as for mesh edges (EdgeCopy); where the faces share a vertex the halves add
// up to b_k.
void AddTexelPointRows(const RenderScene& scene, int face, int other, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c, const Eigen::Vector3d& row, BoundaryRows* out) {
  const Eigen::Vector3i& corners = scene.faces()[face];
  if (other == face) {
    for (int k = 0; k < 3; ++k) out->Add(corners[k], b[k] * row);
    return;
  }
  const Eigen::Vector3i& other_corners = scene.faces()[other];
  Eigen::Vector3d own = 0.5 * b, across = 0.5 * c;
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      if (other_corners[j] == corners[k]) {
        own[k] += across[j];
        across[j] = 0.0;
      }
    }
  }
  for (int k = 0; k < 3; ++k) out->Add(corners[k], own[k] * row);
  for (int j = 0; j < 3; ++j) {
    if (across[j] != 0.0) out->Add(other_corners[j], across[j] * row);
  }
}

// Every texel boundary of the material on the mesh: grid lines inside faces whose texels vary
// and edges between coplanar, equally oriented faces, each cut where other grid lines cross so
// that a piece separates two texels, kept where the two sides' materials differ (roughness only
// counts with the glossy lobe on).
std::vector<TexelSegment> TexelSegments(const RenderScene& scene, const Material& material,
                                        bool glossy) {
  std::vector<TexelSegment> segments;
  const std::vector<double> lines = TexelGridLines(material);
  if (lines.empty()) return segments;
  const auto& faces = scene.faces();
  const auto& positions = scene.positions();
  auto barycentrics = [](const Eigen::Vector2d& ab) {
    return Eigen::Vector3d(1.0 - ab.x() - ab.y(), ab.x(), ab.y());
  };
  // Grid lines inside the faces: α = a (axis 0) or β = a (axis 1), the other coordinate t over
  // [0, 1 − a], cut where the other grid lines cross.
  std::vector<double> cuts;
  for (size_t f = 0; f < faces.size(); ++f) {
    const int face = static_cast<int>(f);
    if (scene.FaceNormal(face).isZero()) continue;
    if (!FaceTexelsVary(material.albedo, face) &&
        !(glossy && FaceTexelsVary(material.roughness, face))) {
      continue;
    }
    for (const double a : lines) {
      const double extent = 1.0 - a;
      cuts.assign(1, 0.0);
      for (const double c : lines) {
        if (c < extent - 1e-9) cuts.push_back(c);  // lines ending on this one: not a cut.
      }
      cuts.push_back(extent);
      for (int axis = 0; axis < 2; ++axis) {
        // (α, β) of the point at distance `across` from the line's axis and `along` it.
        auto ab = [axis](double across, double along) {
          return axis == 0 ? Eigen::Vector2d(across, along) : Eigen::Vector2d(along, across);
        };
        for (size_t k = 0; k + 1 < cuts.size(); ++k) {
          const double mid = 0.5 * (cuts[k] + cuts[k + 1]);
          const double size = MaterialJump(material, glossy, face, ab(a - kTexelSideOffset, mid),
                                           face, ab(a + kTexelSideOffset, mid));
          if (!(size > 0.0)) continue;
          const Eigen::Vector3d b0 = barycentrics(ab(a, cuts[k]));
          const Eigen::Vector3d b1 = barycentrics(ab(a, cuts[k + 1]));
          segments.push_back({face, face, -1, b0, b1, size, b0, b1});
        }
      }
    }
  }
  // Edges between coplanar faces (the others are mesh edges, sampled as such, whose jump
  // includes the material's), cut at the grid lines' crossings t = k/r (the same on every edge).
  cuts.assign(1, 0.0);
  cuts.insert(cuts.end(), lines.begin(), lines.end());
  cuts.push_back(1.0);
  for (size_t e = 0; e < scene.edges().size(); ++e) {
    const MeshEdge& edge = scene.edges()[e];
    if (edge.num_faces != 2 || positions[edge.v0] == positions[edge.v1]) continue;
    Eigen::Vector3d n0, n1;
    ConsistentEdgeNormals(scene, edge, &n0, &n1);
    if (n0.isZero() || n1.isZero() || !(n0.dot(n1) >= 1.0 - 1e-12)) continue;
    // Per face (0: f0, 1: f1): the barycentric unit vectors of the edge's ends and of the
    // opposite corner.
    const int side_faces[2] = {edge.f0, edge.f1};
    Eigen::Vector3d end0[2], end1[2], opposite[2];
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector3i& corners = faces[side_faces[i]];
      for (int k = 0; k < 3; ++k) {
        const int welded = scene.WeldedVertex(corners[k]);
        end0[i][k] = welded == edge.v0 ? 1.0 : 0.0;
        end1[i][k] = welded == edge.v1 ? 1.0 : 0.0;
        opposite[i][k] = welded != edge.v0 && welded != edge.v1 ? 1.0 : 0.0;
      }
    }
    for (size_t k = 0; k + 1 < cuts.size(); ++k) {
      const double mid = 0.5 * (cuts[k] + cuts[k + 1]);
      Eigen::Vector2d ab[2];
      for (int i = 0; i < 2; ++i) {
        // The edge point, moved slightly into face i so that it looks up that face's texel.
        const Eigen::Vector3d b =
            (1.0 - kTexelSideOffset) * ((1.0 - mid) * end0[i] + mid * end1[i]) +
            kTexelSideOffset * opposite[i];
        ab[i] = Eigen::Vector2d(b[1], b[2]);
      }
      const double size = MaterialJump(material, glossy, edge.f0, ab[0], edge.f1, ab[1]);
      if (!(size > 0.0)) continue;
      segments.push_back({edge.f0, edge.f1, static_cast<int>(e),
                          (1.0 - cuts[k]) * end0[0] + cuts[k] * end1[0],
                          (1.0 - cuts[k + 1]) * end0[0] + cuts[k + 1] * end1[0], size,
                          (1.0 - cuts[k]) * end0[1] + cuts[k] * end1[1],
                          (1.0 - cuts[k + 1]) * end0[1] + cuts[k + 1] * end1[1]});
    }
  }
  return segments;
}

// The direct term of point light `light`, shadow ray included, at the first hit of the ray from
// `origin` along the unit direction `dir` (from t_near `t_near` on), as TraceRadiance computes
// it there. False when that hit is not on face `receiver`.
bool DirectAtReceiver(const Context& ctx, const PointLight& light, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& dir, double t_near, int receiver, RenderStats* stats,
                      Eigen::Vector3d* radiance) {
  const RayHit hit = ctx.scene.Intersect(origin, dir, t_near, kInfinity);
  ++stats->bounce_rays;
  if (!hit.hit || hit.face != receiver) return false;
  radiance->setZero();
  const Eigen::Vector3d p = ctx.scene.Point(hit.face, hit.u, hit.v);
  Eigen::Vector3d n = ctx.scene.FaceNormal(hit.face);
  const Eigen::Vector3d wo = -dir;
  if (n.dot(wo) < 0.0) n = -n;
  const BsdfParams params = LookUpMaterial(ctx, ctx.material, hit.face, hit.u, hit.v).params;
  PointLightSample ls;
  if (!SamplePointLight(ctx, light, hit.face, p, n, wo, params, &ls)) return true;
  if (!PointLightVisible(ctx, p, RayOffset(ctx, hit.face, p), ls, stats)) return true;
  *radiance = ls.f.cwiseProduct(light.intensity) * (ls.cos_i / (ls.dist * ls.dist));
  return true;
}

// The jump across the shadow that point light `light` casts on face `receiver` seen directly
// at image point q: only that light's direct term at the first vertex is discontinuous there
// (the rest of the paths varies smoothly with the same random numbers), so the jump is
// C(y⁻)V(y⁻) − C(y⁺)V(y⁺) with C the unshadowed direct term and V the shadow ray's visibility at
// the receiver points y± seen through q ∓ εm. Zero when a side does not see the receiver (the
// shadow boundary meets a primary edge there: a set of measure zero).
Eigen::Vector3d ShadowJump(const Context& ctx, const Eigen::Matrix3d& world_from_cam_rotation,
                           const Eigen::Vector3d& center, const PointLight& light, int receiver,
                           const Eigen::Vector2d& q, const Eigen::Vector2d& m, RenderStats* stats) {
  Eigen::Vector3d dirs[2];
  SideDirections(ctx, world_from_cam_rotation, q, m, dirs);
  Eigen::Vector3d direct[2];
  for (int i = 0; i < 2; ++i) {
    if (!DirectAtReceiver(ctx, light, center, dirs[i], 0.0, receiver, stats, &direct[i])) {
      return Eigen::Vector3d::Zero();
    }
  }
  const Eigen::Vector3d jump = direct[0] - direct[1];
  return jump.allFinite() ? jump : Eigen::Vector3d::Zero();
}

// A point of a mesh edge lit by a point light, and the shadow point it casts: the first surface
// behind the edge point along the light's ray.
struct ShadowPoint {
  int receiver = -1;             // face of the shadow point.
  Eigen::Vector3d y;             // the shadow point.
  Eigen::Vector3d barycentrics;  // of y on the receiver.
  Eigen::Matrix3d d_y_d_point;   // ∂y/∂(edge point).
  Eigen::Matrix3d along;         // ∂y/∂p_j = barycentrics_j·along (receiver corners p_j).
};

// Casts the shadow of point a + s(b − a) of `edge` from the light at `light`; false when the
// light does not reach the edge point, nothing lies behind it, or the receiver is grazed.
// y = light + τ·d on the receiver's plane, d = point − light, τ = (|d| + t)/|d|:
//   ∂y/∂point = τ(I − d̂ n_rᵀ/(n_r·d̂)),  ∂y/∂p_j = b_j·d̂ n_rᵀ/(n_r·d̂).
bool CastShadowPoint(const Context& ctx, const Eigen::Vector3d& light, const MeshEdge& edge,
                     double s, RenderStats* stats, ShadowPoint* out) {
  const RenderScene& scene = ctx.scene;
  const Eigen::Vector3d& a = scene.positions()[edge.v0];
  const Eigen::Vector3d& b = scene.positions()[edge.v1];
  const Eigen::Vector3d point = a + s * (b - a);
  const Eigen::Vector3d d = point - light;
  const double dist = d.norm();
  // The edge point lies on all of the edge's faces: the largest of their scales.
  double scale = SurfaceScale(scene, edge.f0, point);
  if (edge.f1 >= 0) scale = std::max(scale, SurfaceScale(scene, edge.f1, point));
  if (!(dist > kMinRelativeLightDistance * scale)) return false;
  const Eigen::Vector3d dir = d / dist;
  const double offset = kRelativeRayOffset * scale;
  // The light must reach the edge, and the ray grazing it must land on a receiver. A hit on the
  // edge's own faces before the edge point is float noise of the grazing ray (a plane containing
  // the point cannot be crossed on the way to it).
  ++stats->shadow_rays;
  const RayHit blocker = scene.Intersect(light, dir, 0.0, dist - offset);
  if (blocker.hit && blocker.face != edge.f0 && blocker.face != edge.f1) return false;
  ++stats->shadow_rays;
  const RayHit hit = scene.Intersect(point, dir, offset, kInfinity);
  if (!hit.hit || hit.face == edge.f0 || hit.face == edge.f1) return false;
  const Eigen::Vector3d n_r = scene.FaceNormal(hit.face);
  const double cosine = n_r.dot(dir);
  if (!(std::abs(cosine) > kMinHitCosine)) return false;
  out->receiver = hit.face;
  out->y = scene.Point(hit.face, hit.u, hit.v);
  out->barycentrics = Eigen::Vector3d(1.0 - hit.u - hit.v, hit.u, hit.v);
  const double tau = (dist + hit.t) / dist;
  out->along = dir * n_r.transpose() / cosine;
  out->d_y_d_point = tau * (Eigen::Matrix3d::Identity() - out->along);
  return true;
}

// The vertices that move a shadow point of `edge` at parameter s, and rows_j = (∂y/∂p_j)ᵀ·row for
// a row vector `row` (= some linear functional of y's motion): the edge's two ends (their copies,
// AddEdgePointRows) through the edge point, the receiver's three corners through its plane.
void ShadowPointRows(const ShadowPoint& shadow, const RenderScene& scene, const MeshEdge& edge,
                     double s, const Eigen::Vector3d& row, BoundaryRows* out) {
  const Eigen::Vector3d point_row = shadow.d_y_d_point.transpose() * row;
  const Eigen::Vector3d receiver_row = shadow.along.transpose() * row;
  const Eigen::Vector3i& corners = scene.faces()[shadow.receiver];
  AddEdgePointRows(scene, edge, s, point_row, out);
  for (int j = 0; j < 3; ++j) out->Add(corners[j], shadow.barycentrics[j] * receiver_row);
}

// Shadow-casting edges of a point light: every edge that can be a silhouette from it, weighted
// by the angle it subtends there (shadow samples are spread ∝ angle at the light).
std::vector<EdgeCandidate> ShadowEdgeCandidates(const RenderScene& scene,
                                                const Eigen::Vector3d& light) {
  std::vector<EdgeCandidate> candidates;
  const auto& positions = scene.positions();
  const auto& edges = scene.edges();
  for (size_t e = 0; e < edges.size(); ++e) {
    const MeshEdge& edge = edges[e];
    const Eigen::Vector3d a = positions[edge.v0] - light, b = positions[edge.v1] - light;
    if (a == b || !IsDiscontinuityEdge(scene, edge, light, /*creases=*/false)) continue;
    const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
    if (!(angle > 0.0) || !std::isfinite(angle)) continue;
    candidates.push_back({static_cast<int>(e), 0.0, 1.0, angle});
  }
  return candidates;
}

// ---------------------------------------------------------------------------------------------
// Secondary edges (Li et al. 2018 §5). A path vertex x estimates the hemisphere integral
//   H(x) = ∫ f(wo, ω)·(n·ω)·L_in(x, ω) dω,
// and L_in jumps along curves on x's sphere of directions that move with the vertices:
//   (A) the directions of mesh edges that are silhouettes seen from x (behind them: the
//       environment, when it is lit with shadows, or a farther surface, when a further bounce
//       is traced) and, when a further bounce is traced, creases (flat shading);
//   (B) when a further bounce is traced with shadows, the directions of the shadow points that
//       point lights' silhouette edges cast (the next vertex's direct term jumps there);
//   (C) when a further bounce is traced, the directions of texel boundaries (TexelSegments) on
//       the surfaces seen (the material, hence the radiance leaving them, jumps there).
// Boundary term: ∂H/∂θ += ∫_curve (g(ω⁻) − g(ω⁺))·(m·∂ω/∂θ) dl, g = f·(n·ω)·L_in, m the unit
// normal of the curve on the sphere and ω± = normalize(ω ± εm). For a curve point y seen from x,
// ω = (y − x)/r and m·∂ω/∂θ = mᵀ(∂y/∂θ − ∂x/∂θ)/r; dl = |dω/ds| ds along the curve parameter s.
// Estimator per sample: (A) an edge chosen by resampling among length-proportional candidates,
// a point uniform in the angle it subtends at x (see the loop below); (B) a light uniformly, a
// shadow-casting edge ∝ its angle at the light, s uniform; weight (g⁻ − g⁺)·(arc length)/pdf,
// times the path throughput, credited to the path's pixel. Both sides trace with the same random
// numbers. Other radiance leaving the next vertex is continuous along ω (its own hemisphere
// integrals smooth out their jumps), so (A) and (B) are all the curves for flat-shaded, untextured
// surfaces; (C) adds the texel boundaries of mesh-colors materials on the surfaces a further
// bounce sees. (B)'s uniform s still weights receiver points close to x by 1/r.

// Directions closer than this (relative to extent/r) to a curve on the sphere are its sides.
constexpr double kSecondarySideOffset = 1e-5;
constexpr uint64_t kSecondaryEdgeKey = 0x5EC0DE0000000000ull;
// (Edge, point) pairs drawn per secondary sample before one is kept (resampled importance
// sampling). On bunny_point_ggx_gi (two segments, 1024 spp) the secondary term's seed-to-seed
// block error was 13% with 8, 8–9% with 16 or 32; the gradcheck took 12.8, 16.3 and 21 s.
constexpr int kSecondaryCandidates = 16;
// Probability that a secondary sample also samples a texel boundary (C) (weighted by its
// inverse): (C) traces two paths where it is seen, and the indirect light's texel jumps are
// usually a small part of the derivative. On `sft bench gradient` (random albedo per texel,
// r = 2) the rows pass takes 6.0× the forward pass without (C), 7.6× with it always and 6.8×
// at 1/4; BoundarySeenThroughABounce's block error went from 4.8% to 5.2% (2048 spp).
constexpr double kSecondaryTexelProbability = 0.25;

struct SecondaryEdges {
  std::vector<int> edges;       // mesh edges where radiance can jump for some viewpoint.
  std::vector<double> lengths;  // their lengths.
  AliasTable by_length;         // draws an index into `edges` ∝ length.
  bool environment = false;     // the environment is lit with visibility (shadows on).
  // Texel boundaries (when a further bounce is traced and the material has any), with weights
  // 3D length × material jump and an alias table over them.
  std::vector<TexelSegment> texels;
  std::vector<double> texel_weights;
  AliasTable texels_by_weight;
  // Per point light of the view (when shadows and a further bounce exist): shadow-casting edges
  // and their cumulative weights (angles at the light).
  std::vector<std::vector<EdgeCandidate>> shadow_candidates;
  std::vector<std::vector<double>> shadow_cumulative;
};

SecondaryEdges BuildSecondaryEdges(const RenderScene& scene, const Material& material,
                                   const ViewSetup& view, const RenderOptions& options,
                                   bool environment, int max_segments) {
  SecondaryEdges out;
  if (max_segments > 1) {
    const bool glossy = options.effects.specular && material.specular > 0.0;
    for (const TexelSegment& segment : TexelSegments(scene, material, glossy)) {
      const Eigen::Vector3i& corners = scene.faces()[segment.face];
      Eigen::Vector3d along = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        along += (segment.b1[k] - segment.b0[k]) * scene.positions()[corners[k]];
      }
      const double weight = along.norm() * segment.size;
      if (!(weight > 0.0) || !std::isfinite(weight)) continue;
      out.texels.push_back(segment);
      out.texel_weights.push_back(weight);
    }
    if (!out.texels.empty()) out.texels_by_weight = AliasTable(out.texel_weights);
  }
  out.environment = environment && options.effects.shadows;
  for (size_t e = 0; e < scene.edges().size(); ++e) {
    const MeshEdge& edge = scene.edges()[e];
    const double length = (scene.positions()[edge.v1] - scene.positions()[edge.v0]).norm();
    if (!(length > 0.0) || !std::isfinite(length)) continue;
    if (edge.num_faces == 2) {
      Eigen::Vector3d n0, n1;
      ConsistentEdgeNormals(scene, edge, &n0, &n1);
      // Coplanar neighbours (consistently oriented): never a silhouette nor a crease.
      if (!n0.isZero() && !n1.isZero() && n0.dot(n1) > 1.0 - 1e-12) continue;
    }
    out.edges.push_back(static_cast<int>(e));
    out.lengths.push_back(length);
  }
  if (!out.edges.empty()) out.by_length = AliasTable(out.lengths);
  if (options.effects.shadows && max_segments > 1) {
    for (const PointLight& light : view.point_lights) {
      std::vector<EdgeCandidate> candidates = ShadowEdgeCandidates(scene, light.position);
      std::vector<double> cumulative;
      double sum = 0.0;
      for (const EdgeCandidate& c : candidates) cumulative.push_back(sum += c.weight);
      out.shadow_candidates.push_back(std::move(candidates));
      out.shadow_cumulative.push_back(std::move(cumulative));
    }
  }
  return out;
}

// The two side directions ω ∓ εm (index 0: −) of a curve point in direction ω (unit) at
// distance r from x, and the curve's unit normal m given its tangent dω/ds (false when
// degenerate).
bool SphereSides(const Eigen::Vector3d& omega, const Eigen::Vector3d& d_omega_ds, double r,
                 double extent, Eigen::Vector3d* m, Eigen::Vector3d sides[2], double* speed) {
  *speed = d_omega_ds.norm();
  if (!(*speed > 0.0) || !std::isfinite(*speed)) return false;
  *m = omega.cross(d_omega_ds / *speed);
  const double eps = kSecondarySideOffset * extent / r;
  if (!std::isfinite(eps)) return false;
  sides[0] = (omega - eps * *m).normalized();
  sides[1] = (omega + eps * *m).normalized();
  return true;
}

// The point a + s(b − a) whose direction from x is at angle ξ·Θ from (a − x) in the plane of x
// and the segment, Θ the angle the segment subtends at x. False when degenerate (x on the
// segment's line, zero angle).
bool AngleUniformEdgePoint(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& x, double xi, double* s, double* subtended) {
  const Eigen::Vector3d da = a - x, db = b - x;
  const Eigen::Vector3d k = da.cross(db);
  const double k_norm = k.norm();
  if (!(k_norm > 0.0) || !std::isfinite(k_norm)) return false;
  *subtended = std::atan2(k_norm, da.dot(db));
  if (!(*subtended > 0.0)) return false;
  const Eigen::Vector3d ua = da.normalized();
  const Eigen::Vector3d w = (k / k_norm).cross(ua);  // in the plane, ⊥ ua, towards b.
  const double theta = xi * *subtended;
  const Eigen::Vector3d omega = std::cos(theta) * ua + std::sin(theta) * w;
  // (a − x + s(b − a)) × ω = 0 along k.
  const double denominator = (b - a).cross(omega).dot(k);
  if (!(std::abs(denominator) > 0.0)) return false;
  *s = std::clamp(-da.cross(omega).dot(k) / denominator, 0.0, 1.0);
  return std::isfinite(*s);
}

// One (segment, point) pair drawn for a secondary sample by resampled importance sampling
// (Talbot et al. 2005), see (A) below: kSecondaryCandidates segments drawn from `table` (pdf
// weights[c]/total), each with a point uniform in the angle it subtends at x, weighted
// w_k = p̂_k·Θ_k/p_k with p̂ = `target`(ω_k), one kept ∝ w_k. `ends(c, &a, &b)` gives candidate
// c's endpoints, or false where it cannot be a jump seen from x (p̂ = 0). The first candidate
// uses (u_index, u_point), the rest `sampler`.
struct ResampledPoint {
  int index = -1;        // the kept candidate; −1 when none had a positive weight.
  double s = 0.0;        // its point a + s(b − a).
  double inv_pdf = 0.0;  // Θ/(p·p̂) replaced by (1/K)Σ_k w_k/p̂: the estimate's weight/jump.
};

template <typename Ends, typename Target>
ResampledPoint ResampleSegmentPoint(const AliasTable& table, const std::vector<double>& weights,
                                    const Eigen::Vector3d& x, double u_index, double u_point,
                                    Sampler* sampler, const Ends& ends, const Target& target) {
  ResampledPoint out;
  double w_sum = 0.0, kept_target = 0.0;
  for (int k = 0; k < kSecondaryCandidates; ++k) {
    const int c = table.Sample(k == 0 ? u_index : sampler->Next1D());
    const double xi = k == 0 ? u_point : sampler->Next1D();
    const double pick = sampler->Next1D();
    Eigen::Vector3d a, b;
    if (!ends(c, &a, &b)) continue;
    double s_k = 0.0, subtended = 0.0;
    if (!AngleUniformEdgePoint(a, b, x, xi, &s_k, &subtended)) continue;
    const double p_hat = target((a + s_k * (b - a) - x).normalized());
    const double w = p_hat * subtended * table.total() / weights[c];
    if (!(w > 0.0) || !std::isfinite(w)) continue;
    w_sum += w;
    if (pick * w_sum < w) {
      out.index = c;
      out.s = s_k;
      kept_target = p_hat;
    }
  }
  if (out.index >= 0) out.inv_pdf = w_sum / (kept_target * kSecondaryCandidates);
  return out;
}

void AddSecondaryEdgeSamples(const Context& ctx, const Sampler& path_sampler, int depth, int face,
                             const Eigen::Vector3d& throughput, const Eigen::Vector3d& x,
                             const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                             const BsdfParams& params, PathDerivatives* path, RenderStats* stats) {
  const SecondaryEdges& secondary = *ctx.secondary;
  const RenderScene& scene = ctx.scene;
  const bool lit_here = depth > 0 || ctx.options.effects.direct;
  const bool environment = secondary.environment && lit_here && ctx.environment != nullptr;
  const bool indirect = depth + 1 < ctx.max_segments;
  if (!environment && !indirect) return;
  // secondary_edge_samples = r samples per vertex on average: ⌊r⌋, plus one more with
  // probability r − ⌊r⌋, each weighted 1/r (unbiased: the expected count is r).
  const double num_samples = ctx.request->secondary_edge_samples;
  int count = static_cast<int>(num_samples);
  if (count < num_samples &&
      path_sampler.Fork(kSecondaryEdgeKey - 1).Next1D() < num_samples - count) {
    ++count;
  }
  const double offset = RayOffset(ctx, face, x);
  const double extent = scene.extent();
  const auto& positions = scene.positions();
  // g(ω) = f·(n·ω)·L_in for the incoming radiance `l_in` along ω (0 below the horizon).
  auto integrand = [&](const Eigen::Vector3d& omega, const Eigen::Vector3d& l_in) {
    const double cosine = n.dot(omega);
    if (!(cosine > 0.0)) return Eigen::Vector3d::Zero().eval();
    return (EvalBsdf(params, n, wo, omega).cwiseProduct(l_in) * cosine).eval();
  };
  for (int i = 0; i < count; ++i) {
    Sampler sampler = path_sampler.Fork(kSecondaryEdgeKey + 64 * static_cast<uint64_t>(depth) + i);
    double u1, u2, u3, u4;
    sampler.Next2D(&u1, &u2);
    sampler.Next2D(&u3, &u4);

    // (A) Silhouettes (and creases) of mesh edges seen from x.
    // The (edge, point) pair is chosen by resampled importance sampling (Talbot et al. 2005):
    // kSecondaryCandidates pairs are drawn, the edge ∝ length (pdf p_k) and the point uniformly
    // in the angle Θ_k the edge subtends at x (not uniformly in s: the sphere arc length
    // |dω/ds| ds is then Θ_k·dξ, where uniform s would weight points near x by 1/r — infinite
    // variance for edges touching x's face). Each pair gets the target p̂_k = Σ_rgb f·(n·ω_k) at
    // its direction where the edge can be a jump seen from x (silhouette or crease test) and 0
    // elsewhere, the weight w_k = p̂_k·Θ_k/p_k, and one is kept ∝ w_k. The estimate
    // g_jump·Θ/(p̂·Θ)·(1/K)Σ_k w_k is unbiased because p̂ > 0 wherever the integrand g = f·(n·ω)·L
    // can be non-zero. The BSDF factor in p̂ matters for glossy lobes: without it, the few
    // points that land in a narrow lobe carry weights in the hundreds (heavy-tailed noise that
    // hid the derivative on bunny_point_ggx_gi at two bounces).
    // Target: the BSDF·cosine towards the point.
    auto bsdf_cosine = [&](const Eigen::Vector3d& omega) {
      return integrand(omega, Eigen::Vector3d::Ones()).sum();
    };
    ResampledPoint kept;
    if (!secondary.edges.empty()) {
      auto edge_ends = [&](int c, Eigen::Vector3d* a, Eigen::Vector3d* b) {
        const MeshEdge& edge = scene.edges()[secondary.edges[c]];
        if (edge.f0 == face || edge.f1 == face) return false;
        *a = positions[edge.v0];
        *b = positions[edge.v1];
        if (!(std::max(n.dot(*a - x), n.dot(*b - x)) > 0.0)) return false;
        return IsDiscontinuityEdge(scene, edge, x, /*creases=*/indirect);
      };
      kept = ResampleSegmentPoint(secondary.by_length, secondary.lengths, x, u1, u2, &sampler,
                                  edge_ends, bsdf_cosine);
    }
    const int chosen = kept.index;
    const double s_edge = kept.s;
    if (chosen >= 0) {
      const MeshEdge& edge = scene.edges()[secondary.edges[chosen]];
      const Eigen::Vector3d& a = positions[edge.v0];
      const Eigen::Vector3d& b = positions[edge.v1];
      const Eigen::Vector3d y = a + s_edge * (b - a);
      const Eigen::Vector3d to_y = y - x;
      const double r = to_y.norm();
      const Eigen::Vector3d omega = to_y / r;
      if (r > offset && n.dot(omega) > 0.0) {
        const Eigen::Matrix3d tangent_projection =
            (Eigen::Matrix3d::Identity() - omega * omega.transpose()) / r;
        Eigen::Vector3d m, sides[2];
        double speed;
        if (SphereSides(omega, tangent_projection * (b - a), r, extent, &m, sides, &speed)) {
          RayHit hits[2];
          for (int k = 0; k < 2; ++k) hits[k] = scene.Intersect(x, sides[k], offset, kInfinity);
          stats->bounce_rays += 2;
          const bool same =
              hits[0].hit == hits[1].hit && (!hits[0].hit || hits[0].face == hits[1].face);
          if (!same && (indirect || !hits[0].hit || !hits[1].hit)) {
            Eigen::Vector3d g[2];
            for (int k = 0; k < 2; ++k) {
              Eigen::Vector3d l_in = Eigen::Vector3d::Zero();
              if (!hits[k].hit) {
                if (environment) {
                  l_in = ctx.view.environment_scale * ctx.environment->Radiance(sides[k]);
                }
              } else if (indirect) {
                Sampler copy = sampler;
                l_in = TraceRadiance(ctx, &copy, sides[k], hits[k], stats, nullptr, depth + 1);
              }
              g[k] = integrand(sides[k], l_in);
            }
            const Eigen::Vector3d jump = g[0] - g[1];
            if (!jump.isZero() && jump.allFinite()) {
              const double inv_pdf = kept.inv_pdf / num_samples;
              const Eigen::Vector3d m_row = m / r;  // m·∂ω/∂y.
              BoundaryRows rows;
              AddEdgePointRows(scene, edge, s_edge, m_row, &rows);
              path->AddBoundary(throughput.cwiseProduct(jump) * inv_pdf, rows.vertices, rows.rows,
                                rows.count, -m_row);
            }
          }
        }
      }
    }

    // (C) Texel boundaries on the surfaces a further bounce sees: L_in jumps where the material
    // of the surface hit along ω does. Sampled like (A): kSecondaryCandidates (segment, point)
    // pairs, the segment ∝ 3D length × material jump, the point uniform in its subtended angle,
    // one kept by resampling with target f·(n·ω); the jump counts only where the two side rays
    // see the segment's faces (one each; both the same face for a grid line inside a face).
    Sampler texel_sampler = sampler.Fork(1);
    if (indirect && !secondary.texels.empty() &&
        texel_sampler.Next1D() < kSecondaryTexelProbability) {
      auto ends = [&](const TexelSegment& segment, Eigen::Vector3d* y0, Eigen::Vector3d* y1) {
        const Eigen::Vector3i& corners = scene.faces()[segment.face];
        y0->setZero();
        y1->setZero();
        for (int k = 0; k < 3; ++k) {
          *y0 += segment.b0[k] * positions[corners[k]];
          *y1 += segment.b1[k] * positions[corners[k]];
        }
      };
      auto texel_ends = [&](int c, Eigen::Vector3d* y0, Eigen::Vector3d* y1) {
        const TexelSegment& segment = secondary.texels[c];
        if (segment.face == face || segment.other == face) return false;  // x's plane: cos = 0.
        ends(segment, y0, y1);
        return std::max(n.dot(*y0 - x), n.dot(*y1 - x)) > 0.0;
      };
      const double u_index = texel_sampler.Next1D(), u_point = texel_sampler.Next1D();
      const ResampledPoint kept_texel =
          ResampleSegmentPoint(secondary.texels_by_weight, secondary.texel_weights, x, u_index,
                               u_point, &texel_sampler, texel_ends, bsdf_cosine);
      const int chosen_texel = kept_texel.index;
      const double t_s = kept_texel.s;
      if (chosen_texel >= 0) {
        const TexelSegment& segment = secondary.texels[chosen_texel];
        Eigen::Vector3d y0, y1;
        ends(segment, &y0, &y1);
        const Eigen::Vector3d to_y = y0 + t_s * (y1 - y0) - x;
        const double r = to_y.norm();
        const Eigen::Vector3d omega = to_y / r;
        const Eigen::Matrix3d tangent_projection =
            (Eigen::Matrix3d::Identity() - omega * omega.transpose()) / r;
        Eigen::Vector3d m, sides[2];
        double speed;
        if (r > offset && n.dot(omega) > 0.0 &&
            SphereSides(omega, tangent_projection * (y1 - y0), r, extent, &m, sides, &speed)) {
          RayHit hits[2];
          for (int k = 0; k < 2; ++k) hits[k] = scene.Intersect(x, sides[k], offset, kInfinity);
          stats->bounce_rays += 2;
          const bool seen = hits[0].hit && hits[1].hit &&
                            ((hits[0].face == segment.face && hits[1].face == segment.other) ||
                             (hits[0].face == segment.other && hits[1].face == segment.face));
          if (seen) {
            Eigen::Vector3d g[2];
            for (int k = 0; k < 2; ++k) {
              Sampler copy = texel_sampler;
              g[k] = integrand(sides[k], TraceRadiance(ctx, &copy, sides[k], hits[k], stats,
                                                       nullptr, depth + 1));
            }
            const Eigen::Vector3d jump = g[0] - g[1];
            if (!jump.isZero() && jump.allFinite()) {
              const double inv_pdf =
                  kept_texel.inv_pdf / (num_samples * kSecondaryTexelProbability);
              const Eigen::Vector3d m_row = m / r;  // m·∂ω/∂y; ∂y/∂p_k = b_k·I.
              const Eigen::Vector3d b = segment.b0 + t_s * (segment.b1 - segment.b0);
              const Eigen::Vector3d c = segment.c0 + t_s * (segment.c1 - segment.c0);
              BoundaryRows rows;
              AddTexelPointRows(scene, segment.face, segment.other, b, c, m_row, &rows);
              path->AddBoundary(throughput.cwiseProduct(jump) * inv_pdf, rows.vertices, rows.rows,
                                rows.count, -m_row);
            }
          }
        }
      }
    }

    // (B) Point-light shadow boundaries on the surfaces a further bounce sees.
    const int num_lights = static_cast<int>(secondary.shadow_candidates.size());
    if (indirect && num_lights > 0) {
      const int l = std::min(static_cast<int>(u3 * num_lights), num_lights - 1);
      const std::vector<double>& cumulative = secondary.shadow_cumulative[l];
      if (cumulative.empty()) continue;
      // Reuse u3's fraction within the light's slot for the edge choice.
      const double u_edge = u3 * num_lights - l;
      const int c = PickCandidate(cumulative, u_edge);
      const EdgeCandidate& candidate = secondary.shadow_candidates[l][c];
      const MeshEdge& edge = scene.edges()[candidate.edge];
      const PointLight& light = ctx.view.point_lights[l];
      ShadowPoint shadow;
      if (!CastShadowPoint(ctx, light.position, edge, u4, stats, &shadow)) continue;
      if (shadow.receiver == face) continue;
      const Eigen::Vector3d to_y = shadow.y - x;
      const double r = to_y.norm();
      const Eigen::Vector3d omega = to_y / r;
      if (!(r > offset) || !(n.dot(omega) > 0.0)) continue;
      const Eigen::Matrix3d tangent_projection =
          (Eigen::Matrix3d::Identity() - omega * omega.transpose()) / r;
      Eigen::Vector3d m, sides[2];
      double speed;
      if (!SphereSides(
              omega,
              tangent_projection * shadow.d_y_d_point * (positions[edge.v1] - positions[edge.v0]),
              r, extent, &m, sides, &speed)) {
        continue;
      }
      Eigen::Vector3d direct[2];
      bool seen = true;
      for (int k = 0; k < 2 && seen; ++k) {
        seen =
            DirectAtReceiver(ctx, light, x, sides[k], offset, shadow.receiver, stats, &direct[k]);
      }
      if (!seen) continue;
      const Eigen::Vector3d jump = integrand(sides[0], direct[0]) - integrand(sides[1], direct[1]);
      if (jump.isZero() || !jump.allFinite()) continue;
      const double inv_pdf = num_lights * cumulative.back() / candidate.weight / num_samples;
      const Eigen::Vector3d m_row = m / r;
      BoundaryRows rows;
      ShadowPointRows(shadow, scene, edge, u4, m_row, &rows);
      path->AddBoundary(throughput.cwiseProduct(jump) * (speed * inv_pdf), rows.vertices, rows.rows,
                        rows.count, -m_row);
    }
  }
}

// Appends the entries jump·(row_j·∂q/∂vertex_j) for the moving vertices of one sample.
void EmitBoundary(int pixel, const Eigen::Vector3d& jump, double scale, const BoundaryRows& rows,
                  std::vector<EdgeEntry>* out) {
  for (int j = 0; j < rows.count; ++j) {
    for (int k = 0; k < 3; ++k) {
      const double w = rows.rows[j][k] * scale;
      if (w == 0.0 || !std::isfinite(w)) continue;
      out->push_back({pixel, 3 * rows.vertices[j] + k, jump * w});
    }
  }
}

// Draws `num_samples` samples over the candidates in parallel chunks and returns the entries in
// chunk order. `sample_one(candidate, s, sampler, out)` evaluates one sample at parameter s.
template <typename Candidate, typename SampleOne>
void SampleCandidates(const RenderOptions& options, const std::vector<Candidate>& candidates,
                      int64_t num_samples, uint64_t key, uint64_t view_index,
                      const SampleOne& sample_one, std::vector<EdgeEntry>* entries) {
  if (candidates.empty() || num_samples <= 0) return;
  std::vector<double> cumulative(candidates.size());
  double total = 0.0;
  for (size_t i = 0; i < candidates.size(); ++i) cumulative[i] = total += candidates[i].weight;
  if (!(total > 0.0) || !std::isfinite(total)) return;
  const int64_t num_chunks = (num_samples + kEdgeChunk - 1) / kEdgeChunk;
  std::vector<std::vector<EdgeEntry>> chunks(num_chunks);
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(int64_t{0}, num_chunks, [&](int64_t chunk) {
      _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
      _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
      const int64_t end = std::min(num_samples, (chunk + 1) * kEdgeChunk);
      for (int64_t i = chunk * kEdgeChunk; i < end; ++i) {
        Sampler sampler(options.seed, view_index, key + static_cast<uint64_t>(i), 0);
        // Stratified over the concatenated curves: sample i lies in the i-th of N equal slices
        // of the total weight, so the points are spread evenly along all edges (the per-edge
        // integrals, which often cancel between opposite edges, then converge like a
        // quadrature rather than like independent Monte Carlo).
        const double u = (static_cast<double>(i) + sampler.Next1D()) / num_samples;
        const int c = PickCandidate(cumulative, u);
        const Candidate& candidate = candidates[c];
        const double before = c > 0 ? cumulative[c - 1] : 0.0;
        const double local = std::clamp((u * total - before) / candidate.weight, 0.0, 1.0);
        const double s = candidate.s0 + local * (candidate.s1 - candidate.s0);
        // 1/pdf of (candidate, s) over the number of samples.
        const double inv_pdf = total / candidate.weight * (candidate.s1 - candidate.s0) /
                               static_cast<double>(num_samples);
        sample_one(candidate, s, inv_pdf, sampler, &chunks[chunk]);
      }
    });
  });
  for (const auto& chunk : chunks) entries->insert(entries->end(), chunk.begin(), chunk.end());
}

// Boundary terms of one view (primary edges, point-light shadow edges, texel boundaries),
// pixel-major lists of entries scaled for MergeDerivatives' 1/spp.
void AddEdgeTerms(const Context& ctx, std::vector<DerivativeList>* pixel_lists,
                  RenderStats* stats) {
  const RenderScene& scene = ctx.scene;
  const ViewSetup& view = ctx.view;
  const Camera& camera = view.camera;
  const RenderOptions& options = ctx.options;
  const DerivativeRequest& request = *ctx.request;
  const Rigid3d world_from_cam = view.cam_from_world.Inverse();
  const Eigen::Vector3d center = world_from_cam.translation;
  const Eigen::Matrix3d world_from_cam_rotation = world_from_cam.rotation.toRotationMatrix();
  const Eigen::Matrix3d cam_from_world_rotation = world_from_cam_rotation.transpose();
  const auto& positions = scene.positions();
  const auto& edges = scene.edges();
  const auto& faces = scene.faces();
  const double pixels = static_cast<double>(camera.width) * camera.height;
  std::vector<EdgeEntry> entries;
  tbb::enumerable_thread_specific<RenderStats> thread_stats;

  // Image point and m·∂q/∂y of a world point y (false when behind the camera or off the image).
  auto project = [&](const Eigen::Vector3d& y, Eigen::Vector2d* q,
                     Eigen::Matrix<double, 2, 3>* d_q_d_y, int* pixel) {
    const Eigen::Vector3d p_in_cam = view.cam_from_world * y;
    if (!(p_in_cam.z() > 0.0)) return false;
    *q = camera.ImageFromCam(p_in_cam);
    if (!(q->x() >= 0.0 && q->y() >= 0.0 && q->x() < camera.width && q->y() < camera.height)) {
      return false;
    }
    *d_q_d_y = camera.ImageFromCamJacobian(p_in_cam) * cam_from_world_rotation;
    *pixel = static_cast<int>(q->y()) * camera.width + static_cast<int>(q->x());
    return true;
  };

  const double primary_ratio = request.primary_edge_ratio;
  const double shadow_ratio = request.shadow_edge_ratio;
  const double texel_ratio = request.texel_edge_ratio;
  const FrustumBounds frustum = ViewFrustum(ctx);
  // Primary edges.
  if (primary_ratio > 0.0) {
    std::vector<EdgeCandidate> candidates;
    for (size_t e = 0; e < edges.size(); ++e) {
      const MeshEdge& edge = edges[e];
      const Eigen::Vector3d& a = positions[edge.v0];
      const Eigen::Vector3d& b = positions[edge.v1];
      if (a == b || !IsDiscontinuityEdge(scene, edge, center, /*creases=*/true)) continue;
      const Eigen::Vector3d a_cam = view.cam_from_world * a, b_cam = view.cam_from_world * b;
      double s0, s1;
      if (!ClipSegment(a_cam, b_cam, frustum, &s0, &s1)) continue;
      const Eigen::Vector2d q0 = camera.ImageFromCam(a_cam + s0 * (b_cam - a_cam));
      const Eigen::Vector2d q1 = camera.ImageFromCam(a_cam + s1 * (b_cam - a_cam));
      const double length = (q1 - q0).norm();
      if (!std::isfinite(length)) continue;
      candidates.push_back({static_cast<int>(e), s0, s1,
                            (length + 1e-3) * PrimaryEdgeImportance(scene, edge, center)});
    }
    const auto sample_primary = [&](const EdgeCandidate& candidate, double s, double inv_pdf,
                                    const Sampler& sampler, std::vector<EdgeEntry>* out) {
      RenderStats& local = thread_stats.local();
      const MeshEdge& edge = edges[candidate.edge];
      const Eigen::Vector3d& a = positions[edge.v0];
      const Eigen::Vector3d& b = positions[edge.v1];
      const Eigen::Vector3d y = a + s * (b - a);
      Eigen::Vector2d q;
      Eigen::Matrix<double, 2, 3> d_q;
      int pixel;
      if (!project(y, &q, &d_q, &pixel)) return;
      const Eigen::Vector2d tangent = d_q * (b - a);  // dq/ds
      const double speed = tangent.norm();
      if (!(speed > 0.0) || !std::isfinite(speed)) return;
      const Eigen::Vector2d m(-tangent.y() / speed, tangent.x() / speed);
      const Eigen::Vector3d jump =
          PrimaryJump(ctx, world_from_cam_rotation, center, edge, q, m, sampler, &local);
      if (jump.isZero()) return;
      const Eigen::Vector3d m_row = d_q.transpose() * m;  // m·∂q/∂y
      BoundaryRows rows;
      AddEdgePointRows(scene, edge, s, m_row, &rows);
      EmitBoundary(pixel, jump, speed * inv_pdf * options.spp, rows, out);
    };
    const int64_t num_samples =
        static_cast<int64_t>(std::ceil(primary_ratio * options.spp * pixels));
    SampleCandidates(options, candidates, num_samples, kPrimaryEdgeKey, view.view_index,
                     sample_primary, &entries);
  }

  // Shadow edges of point lights, on surfaces the camera sees directly.
  if (shadow_ratio > 0.0 && options.effects.shadows && options.effects.direct) {
    for (size_t l = 0; l < view.point_lights.size(); ++l) {
      const Eigen::Vector3d light = view.point_lights[l].position;
      const std::vector<EdgeCandidate> candidates = ShadowEdgeCandidates(scene, light);
      const auto sample_shadow = [&](const EdgeCandidate& candidate, double s, double inv_pdf,
                                     const Sampler& /*sampler*/, std::vector<EdgeEntry>* out) {
        RenderStats& local = thread_stats.local();
        const MeshEdge& edge = edges[candidate.edge];
        ShadowPoint shadow;
        if (!CastShadowPoint(ctx, light, edge, s, &local, &shadow)) return;
        Eigen::Vector2d q;
        Eigen::Matrix<double, 2, 3> d_q;
        int pixel;
        if (!project(shadow.y, &q, &d_q, &pixel)) return;
        const Eigen::Vector2d tangent =
            d_q * shadow.d_y_d_point * (positions[edge.v1] - positions[edge.v0]);
        const double speed = tangent.norm();
        if (!(speed > 0.0) || !std::isfinite(speed)) return;
        const Eigen::Vector2d m(-tangent.y() / speed, tangent.x() / speed);
        const Eigen::Vector3d jump =
            ShadowJump(ctx, world_from_cam_rotation, center, view.point_lights[l], shadow.receiver,
                       q, m, &local);
        if (jump.isZero()) return;
        const Eigen::Vector3d m_row = d_q.transpose() * m;  // m·∂q/∂y
        BoundaryRows rows;
        ShadowPointRows(shadow, scene, edge, s, m_row, &rows);
        EmitBoundary(pixel, jump, speed * inv_pdf * options.spp, rows, out);
      };
      const int64_t num_samples =
          static_cast<int64_t>(std::ceil(shadow_ratio * options.spp * pixels));
      SampleCandidates(options, candidates, num_samples, kShadowEdgeKey + (l << 40),
                       view.view_index, sample_shadow, &entries);
    }
  }

  // Texel boundaries seen directly.
  if (texel_ratio > 0.0) {
    const Material& material = ctx.material;
    const bool glossy = material.specular * ctx.specular_scale > 0.0;
    std::vector<TexelCandidate> candidates;
    // Adds the segment (of its face, from barycentrics b0 to b1), clipped to the view, weighted
    // by projected length × material jump.
    auto add_segment = [&](const TexelSegment& segment) {
      const int face = segment.face;
      const Eigen::Vector3d &b0 = segment.b0, &b1 = segment.b1;
      const Eigen::Vector3i& corners = faces[face];
      Eigen::Vector3d y0 = Eigen::Vector3d::Zero(), y1 = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        y0 += b0[k] * positions[corners[k]];
        y1 += b1[k] * positions[corners[k]];
      }
      const Eigen::Vector3d a_cam = view.cam_from_world * y0, b_cam = view.cam_from_world * y1;
      double s0, s1;
      if (!ClipSegment(a_cam, b_cam, frustum, &s0, &s1)) return;
      const Eigen::Vector2d q0 = camera.ImageFromCam(a_cam + s0 * (b_cam - a_cam));
      const Eigen::Vector2d q1 = camera.ImageFromCam(a_cam + s1 * (b_cam - a_cam));
      const double weight = (q1 - q0).norm() * segment.size;
      if (!(weight > 0.0) || !std::isfinite(weight)) return;
      candidates.push_back({face, segment.other, b0, b1, segment.c0, segment.c1, s0, s1, weight});
    };
    for (const TexelSegment& segment : TexelSegments(scene, material, glossy)) {
      // A coplanar edge seen edge-on from the camera is a primary edge there.
      if (segment.edge >= 0 &&
          IsDiscontinuityEdge(scene, edges[segment.edge], center, /*creases=*/true)) {
        continue;
      }
      add_segment(segment);
    }
    const auto sample_texel = [&](const TexelCandidate& candidate, double s, double inv_pdf,
                                  const Sampler& sampler, std::vector<EdgeEntry>* out) {
      RenderStats& local = thread_stats.local();
      const Eigen::Vector3i& corners = faces[candidate.face];
      const Eigen::Vector3d b = candidate.b0 + s * (candidate.b1 - candidate.b0);
      const Eigen::Vector3d db_ds = candidate.b1 - candidate.b0;
      Eigen::Vector3d y = Eigen::Vector3d::Zero(), dy_ds = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        y += b[k] * positions[corners[k]];
        dy_ds += db_ds[k] * positions[corners[k]];
      }
      Eigen::Vector2d q;
      Eigen::Matrix<double, 2, 3> d_q;
      int pixel;
      if (!project(y, &q, &d_q, &pixel)) return;
      const Eigen::Vector2d tangent = d_q * dy_ds;  // dq/ds
      const double speed = tangent.norm();
      if (!(speed > 0.0) || !std::isfinite(speed)) return;
      const Eigen::Vector2d m(-tangent.y() / speed, tangent.x() / speed);
      const Eigen::Vector3d jump = TexelJump(ctx, world_from_cam_rotation, center, q, m,
                                             candidate.face, candidate.other, sampler, &local);
      if (jump.isZero()) return;
      const Eigen::Vector3d m_row = d_q.transpose() * m;  // m·∂q/∂y; ∂y/∂p_k = b_k·I.
      const Eigen::Vector3d c = candidate.c0 + s * (candidate.c1 - candidate.c0);
      BoundaryRows rows;
      AddTexelPointRows(scene, candidate.face, candidate.other, b, c, m_row, &rows);
      EmitBoundary(pixel, jump, speed * inv_pdf * options.spp, rows, out);
    };
    const int64_t num_samples = static_cast<int64_t>(std::ceil(texel_ratio * options.spp * pixels));
    SampleCandidates(options, candidates, num_samples, kTexelEdgeKey, view.view_index, sample_texel,
                     &entries);
  }

  for (const EdgeEntry& entry : entries) {
    (*pixel_lists)[entry.pixel].emplace_back(entry.param, entry.d);
  }
  for (const RenderStats& s : thread_stats) {
    stats->camera_rays += s.camera_rays;
    stats->shadow_rays += s.shadow_rays;
    stats->bounce_rays += s.bounce_rays;
  }
}

// Camera samples are traced in fixed kTile × kTile pixel tiles (RenderImpl).
constexpr int kTile = 8;

void RenderImpl(const RenderScene& scene, const Material& material, const ViewSetup& view,
                const RenderOptions& options, const DerivativeRequest* request,
                const ParameterLayout* layout, Image* image, DerivativeOutput* output,
                RenderStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const EnvironmentMap* environment = options.effects.environment ? view.environment : nullptr;
  const int max_segments = options.effects.bounces ? options.bounces : 1;
  std::optional<SecondaryEdges> secondary;
  if (request != nullptr && (request->jacobian_rows || request->adjoint_weights != nullptr) &&
      request->params.vertices && options.pass == RenderPass::kColor &&
      request->secondary_edge_samples > 0 &&
      ((environment != nullptr && options.effects.shadows) || max_segments > 1)) {
    secondary =
        BuildSecondaryEdges(scene, material, view, options, environment != nullptr, max_segments);
  }
  const Context ctx{scene,
                    material,
                    options.sampling_material != nullptr ? *options.sampling_material : material,
                    view,
                    options,
                    environment,
                    max_segments,
                    options.effects.specular ? 1.0 : 0.0,
                    request,
                    layout,
                    secondary ? &*secondary : nullptr};
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
  const int tiles_x = (width + kTile - 1) / kTile;
  const int tiles_y = (height + kTile - 1) / kTile;
  const int num_tiles = tiles_x * tiles_y;
  std::vector<std::vector<JacobianEntry>> pixel_rows(want_rows ? static_cast<size_t>(width) * height
                                                               : 0);
  std::vector<std::vector<std::pair<int, double>>> tile_gradients(weights != nullptr ? num_tiles
                                                                                     : 0);
  tbb::enumerable_thread_specific<RenderStats> thread_stats;
  tbb::enumerable_thread_specific<std::array<RowAccumulator, kTile>> thread_rows;
  // Boundary (edge) terms of vertex derivatives land at random pixels: gathered first, per pixel.
  std::vector<DerivativeList> edge_lists;
  RenderStats edge_stats;
  if (want_derivatives && request->params.vertices && options.pass == RenderPass::kColor) {
    edge_lists.resize(static_cast<size_t>(width) * height);
    AddEdgeTerms(ctx, &edge_lists, &edge_stats);
  }
  auto render_tile = [&](int tile) {
    // Embree wants flush-to-zero / denormals-are-zero in every tracing thread.
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    RenderStats& local = thread_stats.local();
    const int x0 = (tile % tiles_x) * kTile;
    const int y0 = (tile / tiles_x) * kTile;
    const int count = std::min(kTile, width - x0);
    std::array<RowAccumulator, kTile>& rows = thread_rows.local();
    std::optional<PathDerivatives> path;
    if (want_derivatives) path.emplace(ctx);
    std::vector<JacobianEntry> merged;
    for (int y = y0; y < std::min(y0 + kTile, height); ++y) {
      Eigen::Vector3d sums[kTile];
      int hits[kTile] = {0};
      for (int i = 0; i < count; ++i) sums[i].setZero();
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
          if (path) path->Reset(&rows[i]);
          const Eigen::Vector3d value =
              options.pass == RenderPass::kColor
                  ? TraceRadiance(ctx, &samplers[i], dirs[i], first_hits[i], &local,
                                  path ? &*path : nullptr)
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
        if (!edge_lists.empty()) {
          for (const auto& [param, d] : edge_lists[static_cast<size_t>(y) * width + x]) {
            rows[i].Add(param, d);
          }
        }
        rows[i].Flush(inv_spp, &merged);
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
    if (options.on_tile_done) options.on_tile_done();
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
    *stats = edge_stats;
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
