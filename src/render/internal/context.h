// Internal to src/render: what every part of one view's render shares — the scene, material,
// view and options, the derivative request — and the material look-up at a hit.
#ifndef SFT_RENDER_INTERNAL_CONTEXT_H_
#define SFT_RENDER_INTERNAL_CONTEXT_H_

#include <Eigen/Core>
#include <limits>

#include "src/geometry/material.h"
#include "src/render/bsdf.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {
namespace render_internal {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct SecondaryEdges;
class VertexNormalJacobian;

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
  // Smooth shading with vertex derivatives: the vertex normals' Jacobian; null otherwise.
  const VertexNormalJacobian* normal_jacobian;
};

// Texel indices of a hit, and the BSDF parameters there.
struct SurfaceMaterial {
  int albedo_texel = 0;
  int roughness_texel = 0;
  BsdfParams params;
};

SurfaceMaterial LookUpMaterial(const Context& ctx, const Material& material, int face, double u,
                               double v);

inline double RayOffset(const Context& ctx, int face, const Eigen::Vector3d& p) {
  return SurfaceRayOffset(ctx.scene, face, p);
}

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_CONTEXT_H_
