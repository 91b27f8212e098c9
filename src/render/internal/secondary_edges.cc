#include "src/render/internal/secondary_edges.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "src/render/bsdf.h"
#include "src/render/internal/integrator.h"
#include "src/render/internal/path_derivatives.h"
#include "src/render/internal/shadow_edges.h"

namespace sft {
namespace render_internal {
namespace {

// Directions closer than this (relative to extent/r) to a curve on the sphere are its sides.
constexpr double kSecondarySideOffset = 1e-5;
constexpr uint64_t kSecondaryEdgeKey = 0x5EC0DE0000000000ull;
// A hit closer than (1 − this)·r hides a curve point at distance r (faces through the point
// itself are hit at r up to float rounding).
constexpr double kHiddenMargin = 1e-3;
// (A): (edge, point) candidates drawn per secondary sample, and the points kept from them by
// systematic resampling; see docs/design-notes.md for the measured choice.
constexpr int kSecondaryCandidates = 4;
constexpr int kSecondaryKeptPoints = 4;
// (C): (texel segment, point) candidates drawn before one is kept (its proposal knows no
// distance, so it needs more than (A)).
constexpr int kTexelCandidates = 16;
// Side paths of the kept point at candidate entry e: Fork(kKeptPointKey + e).
constexpr uint64_t kKeptPointKey = 64;
// Probability that a secondary sample also samples a texel boundary (C) (weighted by its
// inverse): (C) traces two paths where it is seen, and the indirect light's texel jumps are
// usually a small part of the derivative (docs/design-notes.md).
constexpr double kSecondaryTexelProbability = 0.25;
// (B)'s shadow pools: attempts per expected secondary sample of the view (pixels × spp × rate),
// clamped; entries weighed per (B) sample. See docs/design-notes.md for the measured choice.
constexpr double kShadowPoolAttemptsPerSample = 0.015625;
constexpr int64_t kMinShadowPoolAttempts = 256;
constexpr int64_t kMaxShadowPoolAttempts = 65536;
constexpr int kShadowPoolCandidates = 8;
constexpr uint64_t kShadowPoolKey = 0x5AD0B001ull << 20;

// Texel boundaries with a positive weight (3D length × material jump), and the weights.
SecondaryTexels BuildSecondaryTexels(const RenderScene& scene,
                                     const std::vector<TexelSegment>& all) {
  SecondaryTexels out;
  std::vector<double> weights;
  for (const TexelSegment& segment : all) {
    const Eigen::Vector3i& corners = scene.faces()[segment.face];
    Eigen::Vector3d along = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      along += (segment.b1[k] - segment.b0[k]) * scene.positions()[corners[k]];
    }
    const double weight = along.norm() * segment.size;
    if (!(weight > 0.0) || !std::isfinite(weight)) continue;
    out.segments.push_back(segment);
    weights.push_back(weight);
  }
  if (!out.segments.empty()) out.by_weight = DiscreteDistribution(weights);
  return out;
}

// The secondary texel boundaries of the mesh state and material: the last set is kept while
// TexelSegments returns the same set (its key covers the faces, positions and material), so the
// views of a pass share one build instead of copying every segment per view.
std::shared_ptr<const SecondaryTexels> SecondaryTexelsOf(const RenderScene& scene,
                                                         const Material& material, bool glossy) {
  static std::mutex mutex;
  static std::shared_ptr<const std::vector<TexelSegment>> cached_key;
  static std::shared_ptr<const SecondaryTexels> cached;
  const std::shared_ptr<const std::vector<TexelSegment>> all =
      TexelSegments(scene, material, glossy);
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (cached != nullptr && cached_key == all) return cached;
  }
  auto built = std::make_shared<const SecondaryTexels>(BuildSecondaryTexels(scene, *all));
  std::lock_guard<std::mutex> lock(mutex);
  cached_key = all;
  cached = built;
  return built;
}

// A path vertex x where secondary edges are sampled, and what its samples share.
struct SecondaryVertex {
  const Context& ctx;
  int depth;
  int face;
  const Eigen::Vector3d& throughput;
  const Eigen::Vector3d& x;
  const Eigen::Vector3d& n;
  const Eigen::Vector3d& wo;
  const BsdfParams& params;
  bool environment;    // the environment is lit at x with visibility.
  bool indirect;       // a further bounce is traced from x.
  double offset;       // ray offset at x.
  double num_samples;  // expected samples per vertex (each weighted by its inverse).

  // g(ω) = f·(n·ω)·L_in for the incoming radiance `l_in` along ω (0 below the horizon).
  Eigen::Vector3d Integrand(const Eigen::Vector3d& omega, const Eigen::Vector3d& l_in) const {
    const double cosine = n.dot(omega);
    if (!(cosine > 0.0)) return Eigen::Vector3d::Zero().eval();
    return (EvalBsdf(params, n, wo, omega).cwiseProduct(l_in) * cosine).eval();
  }
  // The resampling target: the BSDF·cosine towards ω.
  double BsdfCosine(const Eigen::Vector3d& omega) const {
    return Integrand(omega, Eigen::Vector3d::Ones()).sum();
  }
};

// A point y of a curve on x's sphere of directions: ω = (y − x)/r, the curve's unit normal m
// there and the side directions ω ∓ εm (index 0: −); speed = |dω/ds|.
struct SphereCurvePoint {
  Eigen::Vector3d omega, m, sides[2];
  double r = 0.0, speed = 0.0;
};

// The two side directions ω ∓ εm of a curve point in direction ω (unit) at distance r from x,
// and the curve's unit normal m given its tangent dω/ds (false when degenerate).
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

// The curve point at to_y = y − x, whose motion dω/ds = `tangent`((I − ωωᵀ)/r) (the projection
// of dy/ds onto the sphere). False when y is not above x's surface, too close, or degenerate.
template <typename Tangent>
bool SphereCurveAt(const SecondaryVertex& v, const Eigen::Vector3d& to_y, const Tangent& tangent,
                   SphereCurvePoint* out) {
  out->r = to_y.norm();
  out->omega = to_y / out->r;
  if (!(out->r > v.offset) || !(v.n.dot(out->omega) > 0.0)) return false;
  const Eigen::Matrix3d tangent_projection =
      (Eigen::Matrix3d::Identity() - out->omega * out->omega.transpose()) / out->r;
  return SphereSides(out->omega, tangent(tangent_projection), out->r, v.ctx.scene.extent(), &out->m,
                     out->sides, &out->speed);
}

// (A), (C): "two sides, two rays, two paths, jump". Traces the rays from x along both sides of
// the curve point; when `accept`(hits) (the two sides see the curve's jump), *jump = g(ω⁻) −
// g(ω⁺) with L_in the environment where a side misses (when lit) and the path continued with a
// copy of `sampler` where it hits (when a further bounce is traced). `reject_first`(hit) may
// reject after the first side's ray alone. False when rejected or the jump is zero (a jump that
// is not finite is returned: it drops the path's sample).
template <typename RejectFirst, typename Accept>
bool TwoSidedJump(const SecondaryVertex& v, const SphereCurvePoint& point, const Sampler& sampler,
                  const RejectFirst& reject_first, const Accept& accept, RenderStats* stats,
                  Eigen::Vector3d* jump) {
  const Context& ctx = v.ctx;
  RayHit hits[2];
  hits[0] = ctx.scene.Intersect(v.x, point.sides[0], v.offset, kInfinity);
  ++stats->bounce_rays;
  if (reject_first(hits[0])) return false;
  hits[1] = ctx.scene.Intersect(v.x, point.sides[1], v.offset, kInfinity);
  ++stats->bounce_rays;
  if (!accept(hits)) return false;
  Eigen::Vector3d g[2];
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector3d l_in = Eigen::Vector3d::Zero();
    if (!hits[k].hit) {
      if (v.environment && !ctx.view.support.Hides(v.x, point.sides[k])) {
        l_in = ctx.view.environment_scale * ctx.environment->Radiance(point.sides[k]);
      }
    } else if (v.indirect) {
      Sampler copy = sampler;
      l_in = TraceRadiance(ctx, &copy, point.sides[k], hits[k], stats, nullptr, v.depth + 1);
    }
    g[k] = v.Integrand(point.sides[k], l_in);
  }
  *jump = g[0] - g[1];
  return !jump->isZero();
}

// (A)'s estimate at one kept (edge, point) pair, times `scale`: "two sides, two rays, two
// paths, jump" at the point, credited to the edge's ends and to x.
void AddMeshEdgePoint(const SecondaryVertex& v, const ResampledPoint& kept, double scale,
                      const Sampler& sampler, PathDerivatives* path, RenderStats* stats) {
  const RenderScene& scene = v.ctx.scene;
  const MeshEdge& edge = scene.edges()[v.ctx.secondary->mesh_edges->edge(kept.index)];
  const Eigen::Vector3d& a = scene.positions()[edge.v0];
  const Eigen::Vector3d& b = scene.positions()[edge.v1];
  const Eigen::Vector3d y = a + kept.s * (b - a);
  SphereCurvePoint point;
  if (!SphereCurveAt(
          v, y - v.x, [&](const Eigen::Matrix3d& t) { return (t * (b - a)).eval(); }, &point)) {
    return;
  }
  auto accept = [&](const RayHit hits[2]) {
    const bool same = hits[0].hit == hits[1].hit && (!hits[0].hit || hits[0].face == hits[1].face);
    return !same && (v.indirect || !hits[0].hit || !hits[1].hit);
  };
  // A surface in front of the edge point (not one of the edge's faces) hides it from x: the
  // other side's ray meets the same surface, except within ε of that surface's own edges, whose
  // jumps their own samples count.
  auto hidden = [&](const RayHit& hit) {
    return hit.hit && hit.face != edge.f0 && hit.face != edge.f1 &&
           hit.t < (1.0 - kHiddenMargin) * point.r;
  };
  Eigen::Vector3d jump;
  if (!TwoSidedJump(v, point, sampler, hidden, accept, stats, &jump)) return;
  const double inv_pdf = kept.inv_pdf * scale / v.num_samples;
  const Eigen::Vector3d m_row = point.m / point.r;  // m·∂ω/∂y.
  BoundaryRows rows;
  AddEdgePointRows(scene, edge, kept.s, m_row, &rows);
  path->AddBoundary(v.throughput.cwiseProduct(jump) * inv_pdf, rows.vertices, rows.rows, rows.count,
                    -m_row);
}

// (A) Silhouettes (and creases) of mesh edges seen from x. (Edge, point) pairs are chosen by
// resampled importance sampling (Talbot et al. 2005): kSecondaryCandidates pairs are drawn, the
// edge from NearEdgeMixture (pdf p_k) and the point uniformly in the angle Θ_k the edge subtends at
// x (not uniformly in s: the sphere arc length |dω/ds| ds is then Θ_k·dξ, where uniform s would
// weight points near x by 1/r — infinite variance for edges touching x's face). Each pair gets the
// target p̂_k = Σ_rgb f·(n·ω_k) at its direction where the edge can be a jump seen from x
// (silhouette or crease test) and 0 elsewhere, the weight w_k = p̂_k·Θ_k/p_k, and
// kSecondaryKeptPoints are kept ∝ w_k by systematic resampling, each estimate weighted by 1/M.
// The estimate g_jump·Θ/(p̂·Θ)·(1/K)Σ_k w_k is unbiased because p̂ > 0 wherever the integrand
// g = f·(n·ω)·L can be non-zero. The BSDF factor in p̂ matters for glossy lobes: without it, the
// few points that land in a narrow lobe carry heavy-tailed weights. Several kept points share
// one candidate draw: about three in four kept points are hidden from x (the target does not
// know visibility), and a hidden one costs one ray, less than a draw's tree descents.
void SampleMeshEdge(const SecondaryVertex& v, double u_index, double u_point, Sampler* sampler,
                    PathDerivatives* path, RenderStats* stats) {
  const MeshEdgeTable& table = *v.ctx.secondary->mesh_edges;
  if (table.empty()) return;
  // Creases jump only under flat shading (smooth normals are continuous across them).
  const bool flat = v.ctx.options.shading == Shading::kFlat;
  auto edge_ends = [&](int c, Eigen::Vector3d* a, Eigen::Vector3d* b) {
    const MeshEdgeTable::Record& r = table.record(c);
    if (r.f0 == v.face || r.f1 == v.face) return false;
    *a = r.a.cast<double>();
    *b = r.b.cast<double>();
    if (!(std::max(v.n.dot(*a - v.x), v.n.dot(*b - v.x)) > 0.0)) return false;
    return table.IsDiscontinuity(c, v.x, /*creases=*/v.indirect && flat);
  };
  const SegmentCandidates candidates = DrawSegmentCandidates(
      NearEdgeMixture(table, v.face, v.x, v.n), kSecondaryCandidates, v.x, u_index, u_point,
      sampler, edge_ends, [&](const Eigen::Vector3d& omega) { return v.BsdfCosine(omega); });
  if (candidates.num_weighted == 0) return;
  const double u_pick = sampler->Next1D();
  // Equal picks are adjacent: each distinct one is evaluated once, weighted by its count.
  int entry = candidates.PickEntry(u_pick / kSecondaryKeptPoints), count = 1;
  for (int j = 1; j <= kSecondaryKeptPoints; ++j) {
    const int next =
        j < kSecondaryKeptPoints ? candidates.PickEntry((j + u_pick) / kSecondaryKeptPoints) : -2;
    if (next == entry) {
      ++count;
      continue;
    }
    AddMeshEdgePoint(v, candidates.Point(entry), static_cast<double>(count) / kSecondaryKeptPoints,
                     sampler->Fork(kKeptPointKey + entry), path, stats);
    entry = next;
    count = 1;
  }
}

// (C) Texel boundaries on the surfaces a further bounce sees: L_in jumps where the material of
// the surface hit along ω does. Sampled like (A): kTexelCandidates (segment, point) pairs,
// the segment ∝ 3D length × material jump, the point uniform in its subtended angle, one kept by
// resampling with target f·(n·ω); the jump counts only where the two side rays see the
// segment's faces (one each; both the same face for a grid line inside a face).
void SampleTexelBoundary(const SecondaryVertex& v, Sampler* texel_sampler, PathDerivatives* path,
                         RenderStats* stats) {
  const SecondaryEdges& secondary = *v.ctx.secondary;
  const RenderScene& scene = v.ctx.scene;
  auto texel_ends = [&](int c, Eigen::Vector3d* y0, Eigen::Vector3d* y1) {
    const TexelSegment& segment = secondary.texels->segments[c];
    if (segment.face == v.face || segment.other == v.face) return false;  // x's plane: cos = 0.
    TexelSegmentEnds(scene, segment, y0, y1);
    return std::max(v.n.dot(*y0 - v.x), v.n.dot(*y1 - v.x)) > 0.0;
  };
  const double u_index = texel_sampler->Next1D(), u_point = texel_sampler->Next1D();
  const ResampledPoint kept = ResampleSegmentPoint(
      secondary.texels->by_weight, kTexelCandidates, v.x, u_index, u_point, texel_sampler,
      texel_ends, [&](const Eigen::Vector3d& omega) { return v.BsdfCosine(omega); });
  if (kept.index < 0) return;
  const TexelSegment& segment = secondary.texels->segments[kept.index];
  Eigen::Vector3d y0, y1;
  TexelSegmentEnds(scene, segment, &y0, &y1);
  SphereCurvePoint point;
  if (!SphereCurveAt(
          v, y0 + kept.s * (y1 - y0) - v.x,
          [&](const Eigen::Matrix3d& t) { return (t * (y1 - y0)).eval(); }, &point)) {
    return;
  }
  auto accept = [&](const RayHit hits[2]) {
    return hits[0].hit && hits[1].hit &&
           ((hits[0].face == segment.face && hits[1].face == segment.other) ||
            (hits[0].face == segment.other && hits[1].face == segment.face));
  };
  auto off_segment = [&](const RayHit& hit) {  // accept needs both sides on its faces.
    return !hit.hit || (hit.face != segment.face && hit.face != segment.other);
  };
  Eigen::Vector3d jump;
  if (!TwoSidedJump(v, point, *texel_sampler, off_segment, accept, stats, &jump)) return;
  const double inv_pdf = kept.inv_pdf / (v.num_samples * kSecondaryTexelProbability);
  const Eigen::Vector3d m_row = point.m / point.r;  // m·∂ω/∂y; ∂y/∂p_k = b_k·I.
  const Eigen::Vector3d b = segment.b0 + kept.s * (segment.b1 - segment.b0);
  const Eigen::Vector3d c = segment.c0 + kept.s * (segment.c1 - segment.c0);
  BoundaryRows rows;
  AddTexelPointRows(scene, segment.face, segment.other, b, c, m_row, &rows);
  path->AddBoundary(v.throughput.cwiseProduct(jump) * inv_pdf, rows.vertices, rows.rows, rows.count,
                    -m_row);
}

// (B) Point- and directional-light shadow boundaries on the surfaces a further bounce sees: a light
// uniformly (u_light), then one of its pool's shadow points by resampled importance sampling:
// kShadowPoolCandidates entries drawn uniformly, target p̂ = Σ_rgb f·(n·ω)·|dω/ds|/p (the
// integrand's geometry: the jump is left out), one kept ∝ p̂. The estimate of the pool's sum
// over entries, F_kept/p̂_kept·(1/K)Σ_k p̂_k·n, divided by the pool's attempts, is unbiased for
// the curve integral given the pool, and the pool is unbiased.
void SampleShadowBoundary(const SecondaryVertex& v, double u_light, Sampler* sampler,
                          PathDerivatives* path, RenderStats* stats) {
  const SecondaryEdges& secondary = *v.ctx.secondary;
  const RenderScene& scene = v.ctx.scene;
  const int num_lights = static_cast<int>(secondary.shadow_pools.size());
  const int l = std::min(static_cast<int>(u_light * num_lights), num_lights - 1);
  const ShadowPool& pool = secondary.shadow_pools[l];
  const int n = static_cast<int>(pool.points.size());
  if (n == 0) return;
  // All candidates are drawn and prefetched before any is weighed (the loads overlap).
  int index[kShadowPoolCandidates];
  double pick[kShadowPoolCandidates];
  for (int k = 0; k < kShadowPoolCandidates; ++k) {
    index[k] = std::min(static_cast<int>(sampler->Next1D() * n), n - 1);
    pick[k] = sampler->Next1D();
    __builtin_prefetch(&pool.points[index[k]]);
  }
  int kept = -1;
  double w_sum = 0.0, kept_target = 0.0;
  for (int k = 0; k < kShadowPoolCandidates; ++k) {
    const ShadowPoolPoint& p = pool.points[index[k]];
    if (p.receiver == v.face) continue;
    const Eigen::Vector3d to_y = p.y - v.x;
    const double r = to_y.norm();
    const Eigen::Vector3d omega = to_y / r;
    if (!(r > v.offset) || !(v.n.dot(omega) > 0.0)) continue;
    const double speed = (p.dy_ds - omega * omega.dot(p.dy_ds)).norm() / r;
    const double target = v.BsdfCosine(omega) * speed * p.inverse_probability;
    if (!(target > 0.0) || !std::isfinite(target)) continue;
    w_sum += target;
    if (pick[k] * w_sum < target) {
      kept = index[k];
      kept_target = target;
    }
  }
  if (kept < 0) return;
  const ShadowPoolPoint& p = pool.points[kept];
  const ShadowPoolEntry& e = pool.entries[kept];
  const MeshEdge& edge = scene.edges()[e.edge];
  SphereCurvePoint point;
  if (!SphereCurveAt(
          v, p.y - v.x, [&](const Eigen::Matrix3d& t) { return (t * p.dy_ds).eval(); }, &point)) {
    return;
  }
  const size_t num_point = v.ctx.view.point_lights.size();
  // The pools are the point lights' and then the directional lights'.
  const auto finish = [&](const auto& light) {
    Eigen::Vector3d direct[2];
    for (int k = 0; k < 2; ++k) {
      if (!DirectAtReceiver(v.ctx, light, v.x, point.sides[k], v.offset, e.shadow.receiver, stats,
                            &direct[k])) {
        return;
      }
    }
    const Eigen::Vector3d jump =
        v.Integrand(point.sides[0], direct[0]) - v.Integrand(point.sides[1], direct[1]);
    if (jump.isZero()) return;
    // F/p̂ = jump·speed·(1/p)/p̂, times (1/K)Σ p̂_k·n, over the attempts, lights and samples.
    const double resampling = w_sum * n / (kept_target * kShadowPoolCandidates);
    const double weight = point.speed * p.inverse_probability * resampling * num_lights /
                          (static_cast<double>(pool.attempts) * v.num_samples);
    const Eigen::Vector3d m_row = point.m / point.r;
    BoundaryRows rows;
    if (secondary.vertices) ShadowPointRows(e.shadow, scene, edge, e.s, m_row, &rows);
    // The light's parameters move y too (∂y/∂light, shadow_edges.h).
    Eigen::Matrix3d d_light_d_param;
    const int light_param = LightShadowParams(v.ctx, light, &d_light_d_param);
    if (light_param >= 0) {
      rows.light_param = light_param;
      rows.light_row = (e.shadow.d_y_d_light * d_light_d_param).transpose() * m_row;
    }
    path->AddBoundary(v.throughput.cwiseProduct(jump) * weight, rows.vertices, rows.rows,
                      rows.count, -m_row, rows.light_param, rows.light_row);
  };
  if (static_cast<size_t>(l) < num_point) {
    finish(v.ctx.view.point_lights[l]);
  } else {
    finish(v.ctx.view.directional_lights[l - num_point]);
  }
}

// The shadow pool of `light` (ShadowPool; a PointLight or a DirectionalLight), drawn with
// `pool_sampler`; rays counted in *stats.
template <typename Light>
ShadowPool BuildShadowPool(const RenderScene& scene, const Light& light, int64_t attempts,
                           const Sampler& pool_sampler, RenderStats* stats) {
  ShadowPool pool;
  const std::shared_ptr<const std::vector<EdgeCandidate>> shared = LightCandidates(scene, light);
  const std::vector<EdgeCandidate>& candidates = *shared;
  std::vector<double> angles;
  for (const EdgeCandidate& c : candidates) angles.push_back(c.weight);
  const DiscreteDistribution by_angle(angles);
  if (by_angle.empty()) return pool;
  pool.attempts = attempts;
  Sampler sampler = pool_sampler;
  for (int64_t j = 0; j < attempts; ++j) {
    // Stratified over the edges' cumulative angle: every edge of a large angle gets its share.
    const int c = by_angle.SampleInverse((j + sampler.Next1D()) / attempts);
    ShadowPoolEntry e;
    e.edge = candidates[c].edge;
    e.s = sampler.Next1D();
    const MeshEdge& edge = scene.edges()[e.edge];
    if (!CastLightShadow(scene, light, edge, e.s, stats, &e.shadow)) continue;
    ShadowPoolPoint p;
    p.y = e.shadow.y;
    p.dy_ds = e.shadow.d_y_d_point * (scene.positions()[edge.v1] - scene.positions()[edge.v0]);
    p.inverse_probability = by_angle.InverseProbability(c);
    p.receiver = e.shadow.receiver;
    pool.points.push_back(p);
    pool.entries.push_back(e);
  }
  return pool;
}

}  // namespace

SecondaryEdges BuildSecondaryEdges(const RenderScene& scene, const Material& material,
                                   const ViewSetup& view, const RenderOptions& options,
                                   const DerivativeRequest& request, bool environment,
                                   int max_segments, RenderStats* stats) {
  SecondaryEdges out;
  out.vertices = request.params.vertices;
  if (max_segments > 1 && out.vertices) {
    out.texels =
        SecondaryTexelsOf(scene, material, options.effects.specular && material.specular > 0.0);
  }
  out.environment = environment && options.effects.shadows;
  if (out.vertices) out.mesh_edges = MeshEdgeTable::Of(scene);
  if (options.effects.shadows && max_segments > 1) {
    const double expected = static_cast<double>(view.camera.width) * view.camera.height *
                            options.spp * request.secondary_edge_samples;
    const int64_t attempts = std::clamp<int64_t>(
        static_cast<int64_t>(std::ceil(expected * kShadowPoolAttemptsPerSample)),
        kMinShadowPoolAttempts, kMaxShadowPoolAttempts);
    const size_t num_point = view.point_lights.size();
    for (size_t l = 0; l < num_point; ++l) {
      const Sampler pool_sampler(options.seed, view.view_index, kShadowPoolKey + l, 0);
      out.shadow_pools.push_back(
          BuildShadowPool(scene, view.point_lights[l], attempts, pool_sampler, stats));
    }
    for (size_t l = 0; l < view.directional_lights.size(); ++l) {
      const Sampler pool_sampler(options.seed, view.view_index, kShadowPoolKey + num_point + l, 0);
      out.shadow_pools.push_back(
          BuildShadowPool(scene, view.directional_lights[l], attempts, pool_sampler, stats));
    }
  }
  return out;
}

void AddSecondaryEdgeSamples(const Context& ctx, const Sampler& path_sampler, int depth, int face,
                             const Eigen::Vector3d& throughput, const Eigen::Vector3d& x,
                             const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                             const BsdfParams& params, PathDerivatives* path, RenderStats* stats) {
  const SecondaryEdges& secondary = *ctx.secondary;
  const bool lit_here = depth > 0 || ctx.options.effects.direct;
  const SecondaryVertex v{ctx,
                          depth,
                          face,
                          throughput,
                          x,
                          n,
                          wo,
                          params,
                          secondary.environment && lit_here && ctx.environment != nullptr,
                          depth + 1 < ctx.max_segments,
                          RayOffset(ctx, face, x),
                          ctx.request->secondary_edge_samples};
  if (!v.environment && !v.indirect) return;
  // secondary_edge_samples = r samples per vertex on average: ⌊r⌋, plus one more with
  // probability r − ⌊r⌋, each weighted 1/r (unbiased: the expected count is r).
  int count = static_cast<int>(v.num_samples);
  if (count < v.num_samples &&
      path_sampler.Fork(kSecondaryEdgeKey - 1).Next1D() < v.num_samples - count) {
    ++count;
  }
  for (int i = 0; i < count; ++i) {
    Sampler sampler = path_sampler.Fork(kSecondaryEdgeKey + 64 * static_cast<uint64_t>(depth) + i);
    double u1, u2, u3, u4;
    sampler.Next2D(&u1, &u2);
    sampler.Next2D(&u3, &u4);
    if (secondary.vertices) SampleMeshEdge(v, u1, u2, &sampler, path, stats);  // (A)
    Sampler texel_sampler = sampler.Fork(1);
    if (secondary.vertices && v.indirect && secondary.texels != nullptr &&
        !secondary.texels->segments.empty() &&
        texel_sampler.Next1D() < kSecondaryTexelProbability) {
      SampleTexelBoundary(v, &texel_sampler, path, stats);  // (C)
    }
    if (v.indirect && !secondary.shadow_pools.empty()) {
      Sampler shadow_sampler = sampler.Fork(2);
      SampleShadowBoundary(v, u3, &shadow_sampler, path, stats);  // (B)
    }
  }
}

}  // namespace render_internal
}  // namespace sft
