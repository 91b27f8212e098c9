// Internal to src/render: secondary edges (Li et al. 2018 §5), the boundary terms of the
// hemisphere integrals at path vertices.
// Secondary edges (Li et al. 2018 §5). A path vertex x estimates the hemisphere integral
//   H(x) = ∫ f(wo, ω)·(n·ω)·L_in(x, ω) dω,
// and L_in jumps along curves on x's sphere of directions that move with the vertices:
//   (A) the directions of mesh edges that are silhouettes seen from x (behind them: the
//       environment, when it is lit with shadows, or a farther surface, when a further bounce
//       is traced) and, when a further bounce is traced, creases (flat shading);
//   (B) when a further bounce is traced with shadows, the directions of the shadow points that
//       point lights' silhouette edges cast (the next vertex's direct term jumps there), drawn
//       from a per-view pool of cast shadow points;
//   (C) when a further bounce is traced, the directions of texel boundaries (TexelSegments) on
//       the surfaces seen (the material, hence the radiance leaving them, jumps there).
// Boundary term: ∂H/∂θ += ∫_curve (g(ω⁻) − g(ω⁺))·(m·∂ω/∂θ) dl, g = f·(n·ω)·L_in, m the unit
// normal of the curve on the sphere and ω± = normalize(ω ± εm). For a curve point y seen from x,
// ω = (y − x)/r and m·∂ω/∂θ = mᵀ(∂y/∂θ − ∂x/∂θ)/r; dl = |dω/ds| ds along the curve parameter s.
// Estimator per sample: (A) edges chosen by resampling among candidates drawn from a mixture
// of the edges around x's face and an edge hierarchy's draw ∝ length·cosine/distance²
// (NearEdgeMixture, EdgeTree), a point uniform in the angle each subtends at x, several kept
// from one draw; (B) a light uniformly, a
// pool entry chosen by resampling with target f·(n·ω)·|dω/ds|/p; weight (g⁻ − g⁺)·(arc
// length)/pdf, times the path throughput, credited to the path's pixel. Both sides trace with the
// same random numbers. Other radiance leaving the next vertex is continuous along ω (its own
// hemisphere integrals smooth out their jumps), so (A) and (B) are all the curves for flat-shaded,
// untextured surfaces; (C) adds the texel boundaries of mesh-colors materials on the surfaces a
// further bounce sees.
#ifndef SFT_RENDER_INTERNAL_SECONDARY_EDGES_H_
#define SFT_RENDER_INTERNAL_SECONDARY_EDGES_H_

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "src/core/rng.h"
#include "src/render/internal/context.h"
#include "src/render/internal/edge_sampling.h"
#include "src/render/internal/mesh_edge_table.h"
#include "src/render/internal/sampling.h"
#include "src/render/internal/shadow_edges.h"
#include "src/render/internal/texel_edges.h"

namespace sft {
namespace render_internal {

class PathDerivatives;

// (B)'s shadow points of one point light: `attempts` draws of a silhouette edge of the light
// (∝ its angle at the light, stratified) and a point uniform on it, cast onto the surface
// behind; the casts that land are kept. A path vertex then draws its shadow point from the pool
// by resampling (the pool's mean over attempts is an unbiased estimate of the curve integral,
// failed attempts contributing zero), so the two rays of a cast are paid once per pool entry,
// not once per path vertex.
struct ShadowPoolEntry {
  int edge = -1;   // the casting edge (index into scene.edges()).
  double s = 0.0;  // its point a + s(b − a).
  ShadowPoint shadow;
};
// What weighing an entry reads, one cache line each (the pool outgrows the caches).
struct alignas(64) ShadowPoolPoint {
  Eigen::Vector3d y;                 // the shadow point.
  Eigen::Vector3d dy_ds;             // its motion along the edge, ∂y/∂point·(b − a).
  double inverse_probability = 0.0;  // 1 / the attempt's density in (edge, s).
  int receiver = -1;
};
struct ShadowPool {
  int64_t attempts = 0;
  std::vector<ShadowPoolPoint> points;
  std::vector<ShadowPoolEntry> entries;  // parallel to points.
};

// The texel boundaries a further bounce can see, with a distribution over them ∝ 3D length ×
// material jump. They depend on the mesh state and the material, not on the view.
struct SecondaryTexels {
  std::vector<TexelSegment> segments;
  DiscreteDistribution by_weight;
};

// The candidates of one view's secondary edge samples.
struct SecondaryEdges {
  // Whether vertex derivatives are requested: without them only the (B) samples run, for the
  // point lights' positions and directional lights' directions (their shadow boundaries move
  // with the light).
  bool vertices = true;
  // Mesh edges where radiance can jump for some viewpoint (per mesh state).
  std::shared_ptr<const MeshEdgeTable> mesh_edges;
  bool environment = false;  // the environment is lit with visibility (shadows on).
  // Texel boundaries (when a further bounce is traced and the material has any), per mesh
  // state and material (shared by every view).
  std::shared_ptr<const SecondaryTexels> texels;
  // Per point light of the view, then per directional light (when shadows and a further bounce
  // exist): shadow points its silhouette edges cast, drawn once per view (ShadowPool) and shared
  // by the view's (B) samples.
  std::vector<ShadowPool> shadow_pools;
};

// The view's secondary-edge candidates for `request`; the rays that build the shadow pools are
// counted in *stats.
SecondaryEdges BuildSecondaryEdges(const RenderScene& scene, const Material& material,
                                   const ViewSetup& view, const RenderOptions& options,
                                   const DerivativeRequest& request, bool environment,
                                   int max_segments, RenderStats* stats);

// The secondary edge samples (request->secondary_edge_samples of them on average) at path vertex
// x (segment depth + 1 of the path, face `face`, normal n facing wo, BSDF `params`, path
// throughput up to x), added to the path's derivatives.
void AddSecondaryEdgeSamples(const Context& ctx, const Sampler& path_sampler, int depth, int face,
                             const Eigen::Vector3d& throughput, const Eigen::Vector3d& x,
                             const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                             const BsdfParams& params, PathDerivatives* path, RenderStats* stats);

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_SECONDARY_EDGES_H_
