#include "src/render/internal/shadow_edges.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include "src/render/geometry_derivatives.h"
#include "src/render/internal/integrator.h"

namespace sft {
namespace render_internal {
namespace {

// The jump across the shadow that light `light` (point or directional) casts on face `receiver`
// seen directly at image point q: only that light's direct term at the first vertex is
// discontinuous there (the rest of the paths varies smoothly with the same random numbers), so the
// jump is C(y⁻)V(y⁻) − C(y⁺)V(y⁺) with C the unshadowed direct term and V the shadow ray's
// visibility at the receiver points y± seen through q ∓ εm. Zero when a side does not see the
// receiver (the shadow boundary meets a primary edge there: a set of measure zero).
template <typename Light>
Eigen::Vector3d ShadowJump(const EdgeView& view, const Light& light, int receiver,
                           const Eigen::Vector2d& q, const Eigen::Vector2d& m, RenderStats* stats) {
  const Context& ctx = view.ctx;
  const Eigen::Vector3d& center = view.center;
  Eigen::Vector3d dirs[2];
  view.SideDirections(q, m, dirs);
  Eigen::Vector3d direct[2];
  for (int i = 0; i < 2; ++i) {
    if (!DirectAtReceiver(ctx, light, center, dirs[i], 0.0, receiver, stats, &direct[i])) {
      return Eigen::Vector3d::Zero();
    }
  }
  return direct[0] - direct[1];
}

// ShadowEdgeCandidates without the cache.
std::vector<EdgeCandidate> BuildShadowEdgeCandidates(const RenderScene& scene,
                                                     const Eigen::Vector3d& light,
                                                     bool directional) {
  std::vector<EdgeCandidate> candidates;
  const auto& positions = scene.positions();
  const auto& edges = scene.edges();
  for (size_t e = 0; e < edges.size(); ++e) {
    const MeshEdge& edge = edges[e];
    double weight = 0.0;
    if (directional) {
      // Seen from infinitely far against the direction: the eye one unit towards the light.
      const Eigen::Vector3d eye = positions[edge.v0] - light;
      if (!IsDiscontinuityEdge(scene, edge, eye, /*creases=*/false)) continue;
      const Eigen::Vector3d ab = positions[edge.v1] - positions[edge.v0];
      weight = (ab - ab.dot(light) * light).norm();
    } else {
      const Eigen::Vector3d a = positions[edge.v0] - light, b = positions[edge.v1] - light;
      if (a == b || !IsDiscontinuityEdge(scene, edge, light, /*creases=*/false)) continue;
      weight = std::atan2(a.cross(b).norm(), a.dot(b));
    }
    if (!(weight > 0.0) || !std::isfinite(weight)) continue;
    candidates.push_back({static_cast<int>(e), 0.0, 1.0, weight});
  }
  return candidates;
}

// The receiver of the shadow ray from `point` along `dir` and the derivatives shared by both
// light kinds: false when nothing lies behind the edge point or the receiver is grazed. Sets
// everything but d_y_d_light; *t is the distance from the point to y.
bool ReceiveShadow(const RenderScene& scene, const MeshEdge& edge, const Eigen::Vector3d& point,
                   const Eigen::Vector3d& dir, double offset, RenderStats* stats, ShadowPoint* out,
                   double* t) {
  ++stats->shadow_rays;
  const RayHit hit = scene.Intersect(point, dir, offset, kInfinity);
  if (!hit.hit || hit.face == edge.f0 || hit.face == edge.f1) return false;
  const Eigen::Vector3d n_r = scene.FaceNormal(hit.face);
  const double cosine = n_r.dot(dir);
  if (!(std::abs(cosine) > kMinHitCosine)) return false;
  out->receiver = hit.face;
  out->y = scene.Point(hit.face, hit.u, hit.v);
  out->barycentrics = Eigen::Vector3d(1.0 - hit.u - hit.v, hit.u, hit.v);
  out->along = dir * n_r.transpose() / cosine;
  *t = hit.t;
  return true;
}

// The largest surface scale of the faces of `edge` at its point `point`.
double EdgePointScale(const RenderScene& scene, const MeshEdge& edge,
                      const Eigen::Vector3d& point) {
  double scale = SurfaceScale(scene, edge.f0, point);
  if (edge.f1 >= 0) scale = std::max(scale, SurfaceScale(scene, edge.f1, point));
  return scale;
}

}  // namespace

bool CastShadowPoint(const RenderScene& scene, const Eigen::Vector3d& light, const MeshEdge& edge,
                     double s, RenderStats* stats, ShadowPoint* out) {
  const Eigen::Vector3d& a = scene.positions()[edge.v0];
  const Eigen::Vector3d& b = scene.positions()[edge.v1];
  const Eigen::Vector3d point = a + s * (b - a);
  const Eigen::Vector3d d = point - light;
  const double dist = d.norm();
  // The edge point lies on all of the edge's faces: the largest of their scales.
  const double scale = EdgePointScale(scene, edge, point);
  if (!(dist > kMinRelativeLightDistance * scale)) return false;
  const Eigen::Vector3d dir = d / dist;
  const double offset = kRelativeRayOffset * scale;
  // The light must reach the edge, and the ray grazing it must land on a receiver. A hit on the
  // edge's own faces before the edge point is float noise of the grazing ray (a plane containing
  // the point cannot be crossed on the way to it).
  ++stats->shadow_rays;
  const RayHit blocker = scene.Intersect(light, dir, 0.0, dist - offset);
  if (blocker.hit && blocker.face != edge.f0 && blocker.face != edge.f1) return false;
  double t = 0.0;
  if (!ReceiveShadow(scene, edge, point, dir, offset, stats, out, &t)) return false;
  const double tau = (dist + t) / dist;
  out->d_y_d_point = tau * (Eigen::Matrix3d::Identity() - out->along);
  out->d_y_d_light = (1.0 - tau) * (Eigen::Matrix3d::Identity() - out->along);
  return true;
}

bool CastDirectionalShadowPoint(const RenderScene& scene, const Eigen::Vector3d& direction,
                                const MeshEdge& edge, double s, RenderStats* stats,
                                ShadowPoint* out) {
  const Eigen::Vector3d& a = scene.positions()[edge.v0];
  const Eigen::Vector3d& b = scene.positions()[edge.v1];
  const Eigen::Vector3d point = a + s * (b - a);
  const double offset = kRelativeRayOffset * EdgePointScale(scene, edge, point);
  // The light must reach the edge point from infinity (hits on the edge's own faces: float noise
  // of the grazing ray, as in CastShadowPoint).
  ++stats->shadow_rays;
  const RayHit blocker = scene.Intersect(point, -direction, offset, kInfinity);
  if (blocker.hit && blocker.face != edge.f0 && blocker.face != edge.f1) return false;
  double t = 0.0;
  if (!ReceiveShadow(scene, edge, point, direction, offset, stats, out, &t)) return false;
  out->d_y_d_point = Eigen::Matrix3d::Identity() - out->along;
  out->d_y_d_light = t * out->d_y_d_point;
  return true;
}

void ShadowPointRows(const ShadowPoint& shadow, const RenderScene& scene, const MeshEdge& edge,
                     double s, const Eigen::Vector3d& row, BoundaryRows* out) {
  const Eigen::Vector3d point_row = shadow.d_y_d_point.transpose() * row;
  const Eigen::Vector3d receiver_row = shadow.along.transpose() * row;
  const Eigen::Vector3i& corners = scene.faces()[shadow.receiver];
  AddEdgePointRows(scene, edge, s, point_row, out);
  for (int j = 0; j < 3; ++j) out->Add(corners[j], shadow.barycentrics[j] * receiver_row);
}

std::shared_ptr<const std::vector<EdgeCandidate>> ShadowEdgeCandidates(const RenderScene& scene,
                                                                       const Eigen::Vector3d& light,
                                                                       bool directional) {
  // Keyed exactly: the mesh state, the light's kind and its position's (direction's) bits.
  struct Entry {
    uint64_t state;
    bool directional;
    std::array<uint64_t, 3> light_bits;
    std::shared_ptr<const std::vector<EdgeCandidate>> candidates;
  };
  static std::mutex mutex;
  static std::deque<Entry> recent;  // most recently used first.
  std::array<uint64_t, 3> light_bits;
  std::memcpy(light_bits.data(), light.data(), sizeof(light_bits));
  const uint64_t state = scene.state_id();
  // Moves the entry with the key to the front and returns its candidates, or null.
  const auto find = [&]() -> std::shared_ptr<const std::vector<EdgeCandidate>> {
    for (auto it = recent.begin(); it != recent.end(); ++it) {
      if (it->state == state && it->directional == directional && it->light_bits == light_bits) {
        Entry entry = std::move(*it);
        recent.erase(it);
        recent.push_front(std::move(entry));
        return recent.front().candidates;
      }
    }
    return nullptr;
  };
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto found = find()) return found;
  }
  auto built = std::make_shared<const std::vector<EdgeCandidate>>(
      BuildShadowEdgeCandidates(scene, light, directional));
  std::lock_guard<std::mutex> lock(mutex);
  if (auto found = find()) return found;  // built meanwhile by another thread: the same list.
  recent.push_front({state, directional, light_bits, built});
  if (recent.size() > kShadowCandidateBuildsKept) recent.pop_back();
  return built;
}

bool CastLightShadow(const RenderScene& scene, const PointLight& light, const MeshEdge& edge,
                     double s, RenderStats* stats, ShadowPoint* out) {
  return CastShadowPoint(scene, light.position, edge, s, stats, out);
}
bool CastLightShadow(const RenderScene& scene, const DirectionalLight& light, const MeshEdge& edge,
                     double s, RenderStats* stats, ShadowPoint* out) {
  return CastDirectionalShadowPoint(scene, light.direction, edge, s, stats, out);
}
std::shared_ptr<const std::vector<EdgeCandidate>> LightCandidates(const RenderScene& scene,
                                                                  const PointLight& light) {
  return ShadowEdgeCandidates(scene, light.position);
}
std::shared_ptr<const std::vector<EdgeCandidate>> LightCandidates(const RenderScene& scene,
                                                                  const DirectionalLight& light) {
  return ShadowEdgeCandidates(scene, light.direction, /*directional=*/true);
}
int LightShadowParams(const Context& ctx, const PointLight& light, Eigen::Matrix3d* jacobian) {
  if (!ctx.request->params.light_positions || !ctx.layout->FitsLightPosition(light.light_index)) {
    return -1;
  }
  *jacobian = LightPositionJacobian(ctx.view, light);
  return ctx.layout->LightPositionOffset() + 3 * light.light_index;
}
int LightShadowParams(const Context& ctx, const DirectionalLight& light,
                      Eigen::Matrix3d* jacobian) {
  if (!ctx.request->params.light_directions || !ctx.layout->FitsLightDirection(light.light_index)) {
    return -1;
  }
  *jacobian = LightDirectionJacobian(ctx.view, light);
  return ctx.layout->LightDirectionOffset() + 3 * light.light_index;
}

namespace {

// The shadow-edge samples of one light (point or directional); `stream` tells its samples'
// random streams apart from the other lights'.
template <typename Light>
void AddLightShadowEdges(const EdgeView& view, const Light& light, uint64_t stream,
                         std::vector<EdgeEntry>* entries) {
  const Context& ctx = view.ctx;
  const RenderOptions& options = ctx.options;
  const RenderScene& scene = ctx.scene;
  const auto& positions = scene.positions();
  const bool vertices = ctx.request->params.vertices;
  // The light's parameters, when they are differentiated: the boundary moves with
  // ∂y/∂(parameters) = ∂y/∂light · ∂light/∂(parameters).
  Eigen::Matrix3d d_light_d_param = Eigen::Matrix3d::Identity();
  const int light_param = LightShadowParams(ctx, light, &d_light_d_param);
  if (!vertices && light_param < 0) return;
  const auto sample_shadow = [&](const EdgeCandidate& candidate, double s, double inv_pdf,
                                 const Sampler& /*sampler*/, std::vector<EdgeEntry>* out) {
    RenderStats& local = view.thread_stats.local();
    const MeshEdge& edge = scene.edges()[candidate.edge];
    ShadowPoint shadow;
    if (!CastLightShadow(scene, light, edge, s, &local, &shadow)) return;
    EmitCurveSample(
        view, shadow.y, inv_pdf, options.spp,
        [&](const Eigen::Matrix<double, 2, 3>& d_q) {
          return (d_q * shadow.d_y_d_point * (positions[edge.v1] - positions[edge.v0])).eval();
        },
        [&](const Eigen::Vector2d& q, const Eigen::Vector2d& m) {
          return ShadowJump(view, light, shadow.receiver, q, m, &local);
        },
        [&](const Eigen::Vector3d& m_row, BoundaryRows* rows) {
          if (vertices) ShadowPointRows(shadow, scene, edge, s, m_row, rows);
          if (light_param >= 0) {
            rows->light_param = light_param;
            rows->light_row = (shadow.d_y_d_light * d_light_d_param).transpose() * m_row;
          }
        },
        &local, out);
  };
  const int64_t num_samples =
      static_cast<int64_t>(std::ceil(ctx.request->shadow_edge_ratio * options.spp * view.pixels));
  SampleCandidates(options, *LightCandidates(scene, light), num_samples,
                   kShadowEdgeKey + (stream << 40), ctx.view.view_index, sample_shadow, entries);
}

}  // namespace

void AddShadowEdgeTerms(const EdgeView& view, std::vector<EdgeEntry>* entries) {
  const Context& ctx = view.ctx;
  const RenderOptions& options = ctx.options;
  const double ratio = ctx.request->shadow_edge_ratio;
  if (!(ratio > 0.0 && options.effects.shadows && options.effects.direct)) return;
  const size_t num_point = ctx.view.point_lights.size();
  for (size_t l = 0; l < num_point; ++l) {
    AddLightShadowEdges(view, ctx.view.point_lights[l], l, entries);
  }
  for (size_t l = 0; l < ctx.view.directional_lights.size(); ++l) {
    AddLightShadowEdges(view, ctx.view.directional_lights[l], num_point + l, entries);
  }
}

}  // namespace render_internal
}  // namespace sft
