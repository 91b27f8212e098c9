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
  // Directions and pdfs of environment sampling: `environment`, or RenderOptions'
  // sampling_environment (detached sampling); null exactly when `environment` is.
  const EnvironmentMap* sampling_environment;
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

// The texels whose values a hit's material parameter blends, and their weights (the parameter is
// Σ weight·texel, so ∂parameter/∂texel = weight): one texel of weight 1 for mesh colors (the
// nearest texel), up to four bilinear texels for UV textures (zero weights left out).
struct TexelWeights {
  int count = 0;
  int texel[4] = {0, 0, 0, 0};
  double weight[4] = {0.0, 0.0, 0.0, 0.0};
};

// The texels of a hit, and the BSDF parameters there.
struct SurfaceMaterial {
  TexelWeights albedo_texels;
  TexelWeights roughness_texels;
  BsdfParams params;
  // UV textures with vertex derivatives requested: how albedo (rows: channels) and roughness
  // change with δ = dx − Σ_j b_j·dp_j, the hit point's motion relative to its face (the texture
  // slides under the hit as the face moves; shading_normal.h derives db from δ). Mesh colors are
  // constant inside a texel: `slides` false, their jumps are texel-boundary terms.
  bool slides = false;
  Eigen::Matrix3d d_albedo_d_delta = Eigen::Matrix3d::Zero();
  Eigen::RowVector3d d_roughness_d_delta = Eigen::RowVector3d::Zero();
};

// The material at barycentrics (1 − u − v, u, v) of `face`: the one place where the renderer reads
// albedo and roughness, from mesh colors or from UV textures (material.h).
SurfaceMaterial LookUpMaterial(const Context& ctx, const Material& material, int face, double u,
                               double v);

inline double RayOffset(const Context& ctx, int face, const Eigen::Vector3d& p) {
  return SurfaceRayOffset(ctx.scene, face, p);
}

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_CONTEXT_H_
