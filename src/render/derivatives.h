// Derivative outputs of the renderer: for one view, from the same sample paths as the image, (a)
// sparse Jacobian rows — per pixel, the list of (parameter, ∂R, ∂G, ∂B) of the pixel's expected
// value, duplicates merged — and/or (b) the adjoint gradient Jᵀw for a per-pixel RGB weight image
// w, without storing the Jacobian.
//
// Parameters live in one flat index space (ParameterLayout): vertex coordinates, albedo texels
// (RGB), roughness texels, the specular weight, and one intensity scale per dataset light (the
// light's radiance/intensity is multiplied by it; derivatives are taken at scale 1). The texels
// are those of the material's active representation (Material::AlbedoValues): mesh colors, where
// a hit uses one texel, or UV textures (texel y·W + x, uv_texture.h), where a hit blends four
// bilinearly and each gets its bilinear weight times the derivative with respect to the blended
// value. UV textures have no texel-boundary terms (internal/texel_edges.h says why).
// UV textures also add an interior vertex term: a bilinear texture varies continuously inside a
// face, so as a face moves under a fixed ray the hit's UV slides and its albedo and roughness
// change (∇_uv T · ∂uv/∂δ · ∂δ/∂p, with δ the hit's motion relative to its face as in
// internal/shading_normal.h; PathDerivatives::MapSlide). Seams are the one part left out
// (internal/texel_edges.h).
//
// What is differentiated (the estimator treats sampled directions, lobe choices, pdfs and MIS
// weights as constants — "detached sampling" — which is unbiased for the derivative of the
// expected image because the integration domain does not depend on these parameters):
//   albedo, roughness, specular: every BSDF factor of every path vertex, all effects; exact (no
//     visibility depends on them);
//   light scales: every contribution of that light;
//   light positions (point lights, ParameterLayout::light_positions): every next-event
//     contribution of that light at every path vertex, through wi = (L − x)/d, the factor
//     c = (n·wi)/d² (the 1/d² falloff and the cosine) and the BSDF's dependence on wi (the
//     negated position terms of the vertex x below); a camera-frame light (a flash) is chained
//     through L = C + Rᵀ·offset. Point lights are delta lights: no BSDF-sampled (MIS) term. The
//     shadow boundaries the light casts move with it, with ∂y/∂L = (1 − τ)(I − d̂n_rᵀ/(n_r·d̂))
//     (internal/shadow_edges.h): seen directly by the camera in the shadow-edge term, through a
//     bounce in secondary edges (B) (both run for light positions without vertex derivatives
//     too, and follow the same budgets). Nothing of the light's visibility is left out;
//   light directions (directional lights, ParameterLayout::light_directions): every next-event
//     contribution of that light at every path vertex, through wi = −d — the cosine c = n·wi and
//     the BSDF's dependence on wi — chained through d = M·v/|v| (M = I, or Rᵀ for a camera-frame
//     light); a delta light too, so no BSDF-sampled term. The shadow boundaries the light casts
//     move with ∂y/∂d = t(I − d n_rᵀ/(n_r·d)) (t from the edge point to the shadow point;
//     internal/shadow_edges.h), seen directly and through a bounce, as for light positions;
//   environment rotations (given probes, ParameterLayout::environment_rotations): every
//   contribution of the probe's radiance — camera rays that escape, BSDF-sampled escapes (MIS),
//   next-event samples — through the lookup direction e = world_from_envᵀ·exp(−[θ]×)·d
//   (EnvironmentMap::RotationJacobian); the probe is at infinity, so turning it moves no
//   visibility boundary and there are no edge terms;
//   vertices, interior terms (geometry_derivatives.h): through every path vertex's shading
//     normal (BSDF, cosines) — the face normal, or under smooth shading the interpolated vertex
//     normals with their two-ring and the hit's sliding barycentrics (internal/shading_normal.h)
//     — and, for point lights, its position (light direction and 1/d²), chained through the hit
//     points of earlier bounces; all effects;
//   vertices, boundary terms (edge sampling, src/render/internal/*_edges.cc): see the table.
//
// Vertex derivative terms present per Effects setting (✓ present, — not needed):
//   effect on      interior  primary edges     texel boundaries  point-light shadow  secondary (A)
//   direct         ✓         ✓                 ✓ seen directly   —                   —
//   + shadows      ✓         ✓                 ✓ seen directly   ✓ seen directly     —
//   + bounces      ✓         ✓                 ✓ via bounce (C)  ✓ via bounce (B)    ✓ silhouettes,
//                                                                                      creases
//                                                                                      (flat)
//   + environment  ✓         ✓ (vs background) ✓ seen directly   —                   ✓ occlusion
//                                                                                      (with
//                                                                                      shadows)
//   + specular     ✓         ✓                 as above          as above            as above
// Secondary edges (internal/secondary_edges.cc; secondary_edge_samples per path vertex):
// (A) mesh edges seen from a path vertex — silhouettes against the environment (when it is lit
// with shadows) or against farther surfaces, and creases under flat shading, when a further
// bounce is traced;
// (B) point- and directional-light shadow boundaries on the surface a bounce reaches; (C) texel
// boundaries on the surface a bounce reaches. Their sampling is unbiased: (A) and (C) draw (edge,
// point) pairs — (A) from a mixture of the edges around the vertex's face and all edges ∝ length,
// (C) ∝ length × material jump — uniform in the angle they subtend, and keep one by resampling with
// the BSDF·cosine towards it; (B) resamples a per-view pool of cast shadow points with the
// BSDF·cosine times the curve's angular speed.
// Primary edges cover silhouettes, boundary and non-manifold edges and, under flat shading,
// creases between non-coplanar faces (smooth shading is continuous across them: Shading in
// render.h). Texel boundaries are where piecewise-constant albedo or
// roughness (mesh colors) jumps: grid lines inside faces and edges between coplanar faces, moving
// with the vertices. Their jump in the full path radiance (direct and indirect light, shadowed or
// not) is included where the camera sees them directly, and through a bounce by secondary edges
// (C) (a texel boundary seen in a reflection, or the indirect light it sends to other surfaces).
// Shadow rays do not depend on the material, so texel boundaries cast no shadows.
#ifndef SFT_RENDER_DERIVATIVES_H_
#define SFT_RENDER_DERIVATIVES_H_

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "src/core/image.h"

namespace sft {

enum class ParameterKind {
  kVertex,
  kAlbedo,
  kRoughness,
  kSpecular,
  kLight,
  kEnvironment,
  kLightPosition,
  kLightDirection,
  kEnvironmentRotation
};

struct ParameterLayout {
  int num_vertices = 0;
  int num_albedo_texels = 0;
  int num_roughness_texels = 0;
  int num_lights = 0;
  // A fitted environment (lighting as parameters): the texels (RGB, linear radiance before the
  // map's scale and the light's scale parameter) of dataset light `environment_light`'s map, in
  // the map's order y·width + x. 0 texels: no environment parameters.
  int num_environment_texels = 0;
  int environment_light = -1;
  // Point-light positions as parameters: 3 per dataset light (coordinate k of light l at
  // LightPositionOffset() + 3l + k). For a world-frame light they are its world position; for a
  // camera-frame light (PointLight::camera_frame, a flash) its offset in the camera frame, shared
  // by every view. Entries of lights that are not point lights get no derivatives.
  bool light_positions = false;
  // Directional-light directions as parameters: 3 per dataset light (component k of light l at
  // LightDirectionOffset() + 3l + k), a vector v in the light's frame (world, or the camera frame
  // for DirectionalLight::camera_frame) whose direction v/|v| is the direction the light travels.
  // Three numbers normalized inside the render rather than two tangent-plane coordinates: they
  // need no per-evaluation re-anchoring, so Ceres' plain parameter blocks, Adam's flat steps and
  // lights.json all hold the same three numbers, and the normalization's Jacobian (I − d dᵀ)/|v|
  // (DirectionalLight::parameter_norm) makes the one free direction, the length, a null direction
  // of every row. Entries of lights that are not directional get no derivatives.
  bool light_directions = false;
  // Environment rotations as parameters: 3 per dataset light (component k of light l at
  // EnvironmentRotationOffset() + 3l + k), a rotation vector θ (axis·angle, radians) that turns
  // the environment map as world_from_env ← exp([θ]×)·world_from_env — for a camera-fixed
  // environment in the camera frame (cam_from_env ← exp([θ]×)·cam_from_env, shared by every
  // view). The render's map is turned by the current θ (EnvironmentMap::Rotated); the rows are
  // ∂/∂θ through the world-frame turn δ of that map, exp([θ + dθ]×) = exp([J_l(θ)·dθ]×)·exp([θ]×)
  // to first order (J_l the left Jacobian of SO(3); ViewSetup::environment_rotation_jacobian).
  // Entries of lights that are not environments get no derivatives.
  bool environment_rotations = false;

  // Index ranges, in this order: vertex v coordinate k at 3v + k; albedo texel t channel c;
  // roughness texel t; the specular weight; light l's scale; environment texel t channel c;
  // light l's position coordinate k; light l's direction component k; light l's environment
  // rotation component k.
  int VertexOffset() const { return 0; }
  int AlbedoOffset() const { return 3 * num_vertices; }
  int RoughnessOffset() const { return AlbedoOffset() + 3 * num_albedo_texels; }
  int SpecularIndex() const { return RoughnessOffset() + num_roughness_texels; }
  int LightOffset() const { return SpecularIndex() + 1; }
  int EnvironmentOffset() const { return LightOffset() + num_lights; }
  int LightPositionOffset() const { return EnvironmentOffset() + 3 * num_environment_texels; }
  int LightDirectionOffset() const {
    return LightPositionOffset() + (light_positions ? 3 * num_lights : 0);
  }
  int EnvironmentRotationOffset() const {
    return LightDirectionOffset() + (light_directions ? 3 * num_lights : 0);
  }
  int size() const {
    return EnvironmentRotationOffset() + (environment_rotations ? 3 * num_lights : 0);
  }
  // Whether dataset light `light`'s environment texels are parameters.
  bool FitsEnvironment(int light) const {
    return num_environment_texels > 0 && light >= 0 && light == environment_light;
  }

  ParameterKind KindOf(int index) const;
  // Whether dataset light `light`'s position coordinates are parameters.
  bool FitsLightPosition(int light) const {
    return light_positions && light >= 0 && light < num_lights;
  }
  // Whether dataset light `light`'s direction components are parameters.
  bool FitsLightDirection(int light) const {
    return light_directions && light >= 0 && light < num_lights;
  }
  // Whether dataset light `light`'s environment rotation components are parameters.
  bool FitsEnvironmentRotation(int light) const {
    return environment_rotations && light >= 0 && light < num_lights;
  }

  // "vertex[12].y", "albedo[40].g", "roughness[3]", "specular", "light[0]", "environment[7].b",
  // "light_position[0].z", "light_direction[0].x", "environment_rotation[0].x".
  std::string Describe(int index) const;
};

// "vertices", "albedo", "roughness", "specular", "light", "environment", "light_position",
// "light_direction", "environment_rotation" (the names of `--param`).
bool ParameterKindFromName(const std::string& name, ParameterKind* kind);
const char* ParameterKindName(ParameterKind kind);

// Which parameter kinds get derivatives.
struct ParameterSelection {
  bool vertices = false;
  bool albedo = true;
  bool roughness = true;
  bool specular = true;
  bool lights = true;
  bool environment = true;            // fitted environment texels (when the layout has them).
  bool light_positions = true;        // point-light positions (when the layout has them).
  bool light_directions = true;       // directional-light directions (when the layout has them).
  bool environment_rotations = true;  // environment rotations (when the layout has them).

  static ParameterSelection Only(ParameterKind kind);
  bool Selected(ParameterKind kind) const;
};

// One Jacobian entry: ∂(pixel RGB)/∂(parameter).
struct JacobianEntry {
  int32_t param;
  float d[3];
};

// Sparse rows of one view, pixel-major (pixel = y·width + x): the entries of pixel p are
// entries[offsets[p] .. offsets[p + 1]), sorted by parameter, no duplicates.
struct JacobianRows {
  int width = 0;
  int height = 0;
  std::vector<uint64_t> offsets;
  std::vector<JacobianEntry> entries;

  size_t MemoryBytes() const {
    return offsets.capacity() * sizeof(uint64_t) + entries.capacity() * sizeof(JacobianEntry);
  }
};

struct DerivativeRequest {
  ParameterSelection params;
  bool jacobian_rows = false;              // fill DerivativeOutput::rows.
  const Image* adjoint_weights = nullptr;  // when set (width × height, ≥ 3 channels): fill
                                           // DerivativeOutput::gradient = Σ_p Σ_c w_pc ∂I_pc/∂θ.
  // Visibility (edge) terms of vertex derivatives (the shadow terms also of point-light
  // positions), sampled per view in proportion to the forward work: primary edge samples = ratio ×
  // spp × pixels (each traces two paths, one on either side of the edge, unless both sides see the
  // same face); point-light shadow edge samples likewise (each traces up to four rays). Range [0,
  // 16]; 0 turns the edge terms off (interior terms only, a biased derivative near
  // silhouettes/shadows). The defaults keep the derivative pass within a few times the forward pass
  // (`sft bench gradient`); raise them when the edge terms' noise dominates (e.g. few views, large
  // silhouette derivatives).
  double primary_edge_ratio = 0.25;
  double shadow_edge_ratio = 0.125;
  // Secondary edges (Li et al. 2018 §5: visibility seen from path vertices): edge samples per
  // path vertex whose hemisphere integral has jumps — occlusion of the environment light (with
  // shadows), silhouettes and creases of what an indirect bounce sees, and point-light shadow
  // boundaries seen through a bounce. Each sample draws a few (edge, point) candidates from an
  // edge hierarchy, keeps a few points by resampling on BSDF·cosine × subtended angle and, with
  // point lights, one shadow-casting edge point; most are rejected by cheap tests. Expected samples
  // per vertex (a fraction r − ⌊r⌋ is one more sample with that probability), range [0, 16]; 0
  // turns them off.
  double secondary_edge_samples = 1.0;
  // Texel-boundary samples = ratio × spp × pixels, each tracing two camera rays and, when both
  // see the boundary's faces, one path whose first vertex is shaded with both sides' materials
  // (two paths where the faces' normals differ). Only boundaries whose two texels differ visibly
  // are candidates (albedo; roughness when the glossy lobe is on), so constant materials cost
  // nothing. Default 1/8: with the jump size in the sampling weight and the samples stratified
  // along the lines the term converges fast (measurements: docs/design-notes.md, "Texel
  // boundaries").
  double texel_edge_ratio = 0.125;
  // Smooth shading only: include the sliding term of the shading normal (the hit's barycentrics
  // change as its face moves under the ray; internal/shading_normal.h). It is part of the exact
  // derivative, but its per-sample values scale with the normal field's change across a face
  // over the face's height and with 1/cos of the incidence, so on fine, curved meshes it carries
  // most of the variance (docs/design-notes.md, "Smooth shading"). false: left out (biased,
  // quieter).
  bool normal_sliding = true;
  // With adjoint_weights: also fill DerivativeOutput::gradient_parts, the gradient split by
  // derivative term (GradientParts). Off, the pass does no per-term work.
  bool gradient_parts = false;

  // True when valid; else *why names the field.
  bool Check(std::string* why) const;
};

// The terms of the vertex derivatives that DerivativeRequest switches separately: the interior
// terms together with everything that is not a vertex derivative (kRest), and each edge term.
enum class DerivativeTerm { kRest, kPrimaryEdges, kShadowEdges, kTexelEdges, kSecondaryEdges };
constexpr int kNumDerivativeTerms = 5;
// "rest", "primary_edges", "shadow_edges", "texel_edges", "secondary_edges" (the edge terms'
// names are the effect planner's switches).
const char* DerivativeTermName(DerivativeTerm term);
// The term of a name of DerivativeTermName; false for any other name.
bool DerivativeTermFromName(const std::string& name, DerivativeTerm* term);

// One adjoint gradient split by term: part(t)[i] is term t's share of gradient entry i, so the
// parts sum to the gradient (up to rounding: the gradient sums each pixel's derivatives as floats,
// the edge parts in double; kRest is the gradient minus the edge parts, so it takes that
// rounding). An edge term's part is the change of the gradient when that term's budget is 0 at
// the same seed: every edge term draws its random numbers from streams of its own (primary,
// shadow and texel edges from per-sample keys, secondary edges from forks of the path's sampler
// that do not advance it), so switching one off changes no other term's samples. The exception
// is a camera sample dropped as not finite (RenderStats::nonfinite_samples), which takes its
// secondary edge terms with it.
struct GradientParts {
  std::array<std::vector<double>, kNumDerivativeTerms> parts;  // layout.size() entries each.

  std::vector<double>& part(DerivativeTerm term) { return parts[static_cast<int>(term)]; }
  const std::vector<double>& part(DerivativeTerm term) const {
    return parts[static_cast<int>(term)];
  }
  bool empty() const { return parts[0].empty(); }
  // Every part with `size` zero entries.
  void Reset(size_t size);
};

struct DerivativeOutput {
  ParameterLayout layout;
  JacobianRows rows;
  std::vector<double> gradient;  // layout.size() entries when requested.
  GradientParts gradient_parts;  // DerivativeRequest::gradient_parts (with the gradient).
};

}  // namespace sft

#endif  // SFT_RENDER_DERIVATIVES_H_
