// Internal to src/render: point- and directional-light shadow boundaries — the shadow that a
// silhouette edge as seen from the light casts on the first surface behind it. Seen directly by the
// camera they are image curves (AddShadowEdgeTerms, the receiver's motion included); seen through a
// bounce, secondary edges (B) (secondary_edges.cc).
#ifndef SFT_RENDER_INTERNAL_SHADOW_EDGES_H_
#define SFT_RENDER_INTERNAL_SHADOW_EDGES_H_

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "src/render/internal/context.h"
#include "src/render/internal/edge_sampling.h"

namespace sft {
namespace render_internal {

// A point of a mesh edge lit by a point light, and the shadow point it casts: the first surface
// behind the edge point along the light's ray.
struct ShadowPoint {
  int receiver = -1;             // face of the shadow point.
  Eigen::Vector3d y;             // the shadow point.
  Eigen::Vector3d barycentrics;  // of y on the receiver.
  Eigen::Matrix3d d_y_d_point;   // ∂y/∂(edge point).
  Eigen::Matrix3d along;         // ∂y/∂p_j = barycentrics_j·along (receiver corners p_j).
  Eigen::Matrix3d d_y_d_light;   // ∂y/∂(light position), or ∂y/∂(direction) (directional).
};

// Casts the shadow of point a + s(b − a) of `edge` from the light at `light`; false when the
// light does not reach the edge point, nothing lies behind it, or the receiver is grazed.
// y = light + τ·d on the receiver's plane, d = point − light, τ = (|d| + t)/|d|:
//   ∂y/∂point = τ(I − d̂ n_rᵀ/(n_r·d̂)),  ∂y/∂p_j = b_j·d̂ n_rᵀ/(n_r·d̂),
//   ∂y/∂light = (1 − τ)(I − d̂ n_rᵀ/(n_r·d̂)) (y = (1 − τ)·light + τ·point, slid along d̂ back
//   onto the plane).
bool CastShadowPoint(const RenderScene& scene, const Eigen::Vector3d& light, const MeshEdge& edge,
                     double s, RenderStats* stats, ShadowPoint* out);

// The same for a directional light travelling along the unit `direction`: the light must reach
// the edge point from −direction, and y = point + t·direction on the receiver's plane:
//   ∂y/∂point = I − d n_rᵀ/(n_r·d),  ∂y/∂p_j as above,  ∂y/∂direction = t(I − d n_rᵀ/(n_r·d)).
bool CastDirectionalShadowPoint(const RenderScene& scene, const Eigen::Vector3d& direction,
                                const MeshEdge& edge, double s, RenderStats* stats,
                                ShadowPoint* out);

// The vertices that move a shadow point of `edge` at parameter s, and rows_j = (∂y/∂p_j)ᵀ·row for
// a row vector `row` (= some linear functional of y's motion): the edge's two ends (their copies,
// AddEdgePointRows) through the edge point, the receiver's three corners through its plane.
void ShadowPointRows(const ShadowPoint& shadow, const RenderScene& scene, const MeshEdge& edge,
                     double s, const Eigen::Vector3d& row, BoundaryRows* out);

// What the shadow terms need of each light kind (point or directional), for templates over it:
// its shadow point (CastShadowPoint, CastDirectionalShadowPoint), its candidates
// (ShadowEdgeCandidates), and the first of its three moving parameters with
// ∂(light position or direction)/∂(parameters) in *jacobian when the request differentiates
// them (−1 otherwise).
bool CastLightShadow(const RenderScene& scene, const PointLight& light, const MeshEdge& edge,
                     double s, RenderStats* stats, ShadowPoint* out);
bool CastLightShadow(const RenderScene& scene, const DirectionalLight& light, const MeshEdge& edge,
                     double s, RenderStats* stats, ShadowPoint* out);
std::shared_ptr<const std::vector<EdgeCandidate>> LightCandidates(const RenderScene& scene,
                                                                  const PointLight& light);
std::shared_ptr<const std::vector<EdgeCandidate>> LightCandidates(const RenderScene& scene,
                                                                  const DirectionalLight& light);
int LightShadowParams(const Context& ctx, const PointLight& light, Eigen::Matrix3d* jacobian);
int LightShadowParams(const Context& ctx, const DirectionalLight& light, Eigen::Matrix3d* jacobian);

// How many (mesh state, light position) builds ShadowEdgeCandidates keeps: camera-attached lights
// move with the view, so an evaluation meets one position per view; a few entries serve the
// callers and passes of the views in flight without holding a list per view.
constexpr size_t kShadowCandidateBuildsKept = 8;

// Shadow-casting edges of a point light at `light`: every edge that can be a silhouette from it,
// weighted by the angle it subtends there (shadow samples are spread ∝ angle at the light). With
// `directional`, `light` is a directional light's travel direction, and the weight is the edge's
// length across it (its length projected on the plane normal to the direction). Built once per
// mesh state (RenderScene::state_id) and light: the few most recent builds are kept, so that the
// shadow and secondary edges of a view, and the passes that render the same view, share one.
std::shared_ptr<const std::vector<EdgeCandidate>> ShadowEdgeCandidates(const RenderScene& scene,
                                                                       const Eigen::Vector3d& light,
                                                                       bool directional = false);

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_SHADOW_EDGES_H_
