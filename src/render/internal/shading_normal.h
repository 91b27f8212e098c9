// Internal to src/render: the shading normal of a path vertex (flat or smooth, render.h's
// Shading) and the chain rule that takes gradients with respect to it to vertex coordinates.
#ifndef SFT_RENDER_INTERNAL_SHADING_NORMAL_H_
#define SFT_RENDER_INTERNAL_SHADING_NORMAL_H_

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "src/render/geometry_derivatives.h"
#include "src/render/internal/vertex_normal_jacobian.h"
#include "src/render/scene.h"

namespace sft {
namespace render_internal {

// (vertex, G·∂n/∂p_vertex) pairs, rows = colour channels; a vertex may appear more than once
// (the accumulators sum them).
using VertexGradients = std::vector<std::pair<int, Eigen::Matrix3d>>;

// Flat: n = σ·n̂ of the hit face; its derivative reaches the face's three corners (NormalChain).
//
// Smooth: n = σ·m/|m|, m = Σ_j b_j N̂_j over the face's corners, N̂_j their unit vertex normals
// and b the hit's barycentrics. Two things move m when vertices move (directions detached):
//  - the vertex normals, each through the faces around its vertex (VertexNormalJacobian), so a
//    hit's normal depends on the two-ring of its face;
//  - the barycentrics, as the face slides under the hit point x: with δ = dx − Σ_j b_j dp_j (the
//    motion of x relative to the face, in its plane to first order) and the dual basis
//    g1 = (e2 × N)/|N|², g2 = (N × e1)/|N|² (e1 = p1 − p0, e2 = p2 − p0, N = e1 × e2),
//    db_k = g_k·δ (k = 1, 2) and db_0 = −db_1 − db_2, so dm = K·δ with
//    K = (N̂_1 − N̂_0)g1ᵀ + (N̂_2 − N̂_0)g2ᵀ. dx comes from the path's PointJacobian (the hit
//    moves with this face and, through the ray's origin, with the faces hit before).
// When the point Jacobian is undefined (a grazing hit earlier on the path) the barycentric term
// is left out, as the path's other position terms are.
class ShadingNormalChain {
 public:
  // A flat-shaded vertex on `face` with n = sign·n̂.
  void SetFlat(const RenderScene& scene, int face, double sign);
  // A smooth-shaded vertex on `face` at `barycentrics` with n = sign·SmoothNormal. Falls back to
  // flat where SmoothNormal does (vanishing interpolated normal).
  // `sliding`: keep the barycentric term (DerivativeRequest::normal_sliding).
  void SetSmooth(const RenderScene& scene, const VertexNormalJacobian& jacobian, int face,
                 const Eigen::Vector3d& barycentrics, double sign, bool sliding);

  // The face's unit geometric normal n̂ (unflipped; what the hit point's motion depends on).
  const Eigen::Vector3d& face_normal() const { return flat_.unit_normal(); }

  // Appends G·∂n/∂(vertex coordinates) to *out for G: 3 rows (channels) × 3 (∂/∂n). `point` is
  // the current hit's Jacobian (used by the smooth barycentric term).
  void Map(const Eigen::Matrix3d& g, const PointJacobian& point, VertexGradients* out) const;

 private:
  bool smooth_ = false;
  Eigen::Vector3i corners_ = Eigen::Vector3i::Zero();
  NormalChain flat_;
  // Smooth only.
  const VertexNormalJacobian* jacobian_ = nullptr;
  Eigen::Vector3d barycentrics_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d projection_ = Eigen::Matrix3d::Zero();  // ∂n/∂m = σ(I − n̂n̂ᵀ)/|m|.
  Eigen::Matrix3d sliding_ = Eigen::Matrix3d::Zero();     // K = ∂m/∂δ.
  bool use_sliding_ = true;
};

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_SHADING_NORMAL_H_
