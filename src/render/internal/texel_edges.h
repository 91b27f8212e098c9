// Internal to src/render: texel boundaries — where the mesh-colors albedo or roughness differs on
// the two sides of a texel grid line inside a face (α or β = k/r) or of an edge between coplanar
// faces (not a primary edge). The points y = Σ_k b_k·p_k of such a line have fixed barycentrics
// b, so ∂y/∂p_k = b_k·I, and the jump is that of the full paths across the line. Seen directly
// they are image curves (AddTexelEdgeTerms); seen through a bounce, secondary edges (C).
//
// UV-texture materials (uv_texture.h) have none: their bilinear interpolant is continuous inside
// every face, so its texel grid lines are not discontinuities. Their only possible jumps are at
// UV seams, which are mesh edges: where two faces meet with different UVs the textures' values on
// the two sides may differ (an atlas baked with dilated gutters makes them nearly equal, not
// exactly). Seam edges between coplanar faces are not sampled, so vertex derivatives miss that
// (small) jump there; across non-coplanar faces under flat shading, or at silhouettes, the
// primary and secondary edge terms already include the material on both sides.
#ifndef SFT_RENDER_INTERNAL_TEXEL_EDGES_H_
#define SFT_RENDER_INTERNAL_TEXEL_EDGES_H_

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "src/geometry/material.h"
#include "src/render/internal/edge_sampling.h"
#include "src/render/scene.h"

namespace sft {
namespace render_internal {

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

// Rows of the texel-boundary point with barycentrics b on `face` and c on `other` (∂y/∂p_k =
// b_k·I). On an edge between two coplanar faces the motion is shared half and half between each
// face's own corners, as for mesh edges (EdgeCopy); where the faces share a vertex the halves add
void AddTexelPointRows(const RenderScene& scene, int face, int other, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c, const Eigen::Vector3d& row, BoundaryRows* out);

// Every texel boundary of the material on the mesh: grid lines inside faces whose texels vary
// and edges between coplanar, equally oriented faces, each cut where other grid lines cross so
// that a piece separates two texels, kept where the two sides' materials differ (roughness only
// counts with the glossy lobe on). They depend on the mesh state (faces, and positions through
// coplanarity) and the material, not on the view: the last set is kept (keyed by the scene's
// state_id and a fingerprint of the material) and shared until they change.
std::shared_ptr<const std::vector<TexelSegment>> TexelSegments(const RenderScene& scene,
                                                               const Material& material,
                                                               bool glossy);

// The ends Σ_k b0_k·p_k and Σ_k b1_k·p_k of a texel segment, world frame.
void TexelSegmentEnds(const RenderScene& scene, const TexelSegment& segment, Eigen::Vector3d* y0,
                      Eigen::Vector3d* y1);

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_TEXEL_EDGES_H_
