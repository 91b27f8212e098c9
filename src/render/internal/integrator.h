// Internal to src/render: the path tracer of one camera sample — next-event estimation to point,
// directional and environment lights, BSDF sampling with multiple importance sampling (power
// heuristic) against the environment — and the auxiliary first-hit passes.
#ifndef SFT_RENDER_INTERNAL_INTEGRATOR_H_
#define SFT_RENDER_INTERNAL_INTEGRATOR_H_

#include <Eigen/Core>

#include "src/core/rng.h"
#include "src/render/internal/context.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {
namespace render_internal {

class PathDerivatives;

// The MIS weight of a sample drawn with pdf_a against a technique with pdf_b.
double PowerHeuristic(double pdf_a, double pdf_b);

// Direction, distance, cosine and BSDF value of a point light seen from a shading point.
struct PointLightSample {
  Eigen::Vector3d wi;
  double dist = 0.0;
  double cos_i = 0.0;
  Eigen::Vector3d f;
};

// Point light `light`'s next-event sample at p (face `face`, normal n facing wo, BSDF `params`):
// false when it contributes nothing — the light is below the surface or closer than
// kMinRelativeLightDistance, f = 0 and `skip_black`, or (with `shadows`) the shadow ray,
// started `offset` along it, is blocked.
bool SamplePointLightVisible(const Context& ctx, const PointLight& light, int face,
                             const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                             const Eigen::Vector3d& wo, const BsdfParams& params, double offset,
                             bool shadows, bool skip_black, RenderStats* stats,
                             PointLightSample* sample);

// Directional light `light`'s next-event sample at p (as SamplePointLightVisible; dist = ∞ is
// not used): false when the light is below the surface, f = 0 and `skip_black`, or (with
// `shadows`) the shadow ray towards the light, to infinity, is blocked.
bool SampleDirectionalLightVisible(const Context& ctx, const DirectionalLight& light,
                                   const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                   const Eigen::Vector3d& wo, const BsdfParams& params,
                                   double offset, bool shadows, bool skip_black, RenderStats* stats,
                                   PointLightSample* sample);

// The direct term of point light `light`, shadow ray included, at the first hit of the ray from
// `origin` along the unit direction `dir` (from t_near `t_near` on), as TraceRadiance computes
// it there. False when that hit is not on face `receiver`.
bool DirectAtReceiver(const Context& ctx, const PointLight& light, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& dir, double t_near, int receiver, RenderStats* stats,
                      Eigen::Vector3d* radiance);
// The same for directional light `light`.
bool DirectAtReceiver(const Context& ctx, const DirectionalLight& light,
                      const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_near,
                      int receiver, RenderStats* stats, Eigen::Vector3d* radiance);

// Radiance along the camera ray with direction `dir` whose first intersection is `hit` (traced
// by the caller, in packets). When `path` is non-null (its Reset called by the caller), the
// path's parameter derivatives are added to it. `first_depth` > 0 continues a path whose first
// first_depth segments were traced elsewhere (the ray along `dir` is then segment
// first_depth + 1): the radiance leaving `hit` towards −dir with the remaining depth.
Eigen::Vector3d TraceRadiance(const Context& ctx, Sampler* sampler, Eigen::Vector3d dir, RayHit hit,
                              RenderStats* stats, PathDerivatives* path, int first_depth = 0);

// L(dirs[0]) − L(dirs[1]) for two camera rays whose first hits lie a side offset apart on faces
// with the same normal (a texel boundary seen directly), from one path for both sides: its first
// vertex is shaded with each side's material, with the same light samples and the same BSDF
// sample (drawn with side 0's sampling material, whose diffuse lobe covers the hemisphere), and
// the rest of the path is traced once. The sides differ by the offset only, which the two-path
// estimate neglects as well. False (nothing written) when the hits do not qualify (a miss,
// different normals, a sampling material without a diffuse lobe): then trace both sides.
bool TraceSharedSideJump(const Context& ctx, const Sampler& sampler, const Eigen::Vector3d dirs[2],
                         const RayHit hits[2], RenderStats* stats, Eigen::Vector3d* jump);

// First-hit auxiliary passes (albedo, roughness, normal, depth).
Eigen::Vector3d TraceAuxiliary(const Context& ctx, const Eigen::Vector3d& dir, const RayHit& hit);

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_INTEGRATOR_H_
