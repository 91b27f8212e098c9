// Internal to src/render: the derivatives of the unit vertex normals of smooth shading
// (vertex_normals.h) with respect to the vertex coordinates, per mesh state.
#ifndef SFT_RENDER_INTERNAL_VERTEX_NORMAL_JACOBIAN_H_
#define SFT_RENDER_INTERNAL_VERTEX_NORMAL_JACOBIAN_H_

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "src/render/scene.h"

namespace sft {
namespace render_internal {

// ∂N̂_w/∂p_v for every welded vertex w and the vertices v of the faces around it (w itself and
// its one-ring): N̂ = S/|S|, S = Σ θ·n̂ (vertex_normals.h), so ∂N̂ = (I − N̂N̂ᵀ)/|S| · ∂S, and
// ∂S sums the corner terms' derivatives (ceres::Jet, exact). A vertex whose sum vanishes has no
// entries (its normal is zero, SmoothNormal falls back to the face normal). The table depends on
// the mesh state only: Of returns the last build while scene.state_id() is unchanged.
class VertexNormalJacobian {
 public:
  struct Entry {
    int vertex = 0;     // an original vertex index (a face corner).
    Eigen::Matrix3d d;  // ∂N̂_w/∂p_vertex.
  };

  static std::shared_ptr<const VertexNormalJacobian> Of(const RenderScene& scene);

  explicit VertexNormalJacobian(const RenderScene& scene);

  // The entries of vertex v's normal (those of its welded vertex), sorted by vertex.
  const Entry* begin(int v) const { return entries_.data() + offsets_[welded_[v]]; }
  const Entry* end(int v) const { return entries_.data() + offsets_[welded_[v] + 1]; }

 private:
  std::vector<int> welded_;
  std::vector<int> offsets_;  // per vertex index (+1), into entries_; only welded ones non-empty.
  std::vector<Entry> entries_;
};

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_VERTEX_NORMAL_JACOBIAN_H_
