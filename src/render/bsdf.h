// The surface BSDF: Lambert plus a Torrance–Sparrow microfacet lobe with the GGX distribution
// (Walter et al. 2007), α = roughness², separable Smith masking G1(wi)·G1(wo), and Fresnel equal
// to the constant `specular` weight (optionally Schlick with F0 = specular):
//
//   f(wo, wi) = albedo/π + F · D(h)·G1(wi)·G1(wo) / (4·|n·wi|·|n·wo|),   h = normalize(wi + wo).
//
// This is exactly Blender's Diffuse BSDF + Glossy BSDF (GGX) joined by an Add Shader, so Cycles
// renders are references (docs/design-notes.md, "Platform facts").
//
// Direction convention, used everywhere in sft: `wo` points from the surface towards the viewer
// (the previous path vertex or the camera), `wi` from the surface towards the light (the next path
// vertex); both are unit vectors in world space. `n` is the unit shading normal already flipped
// to the side of `wo` (two-sided shading, as Cycles' Diffuse BSDF): only reflection is modelled,
// so f = 0 whenever n·wi ≤ 0 or n·wo ≤ 0.
#ifndef SFT_RENDER_BSDF_H_
#define SFT_RENDER_BSDF_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "src/geometry/material.h"

namespace sft {

// α below this is clamped: D(h) then peaks at 1/(π·kMinAlpha²) = 3.2e7, large but finite, and
// roughness → 0 stays finite (a perfect mirror would need a singular, unsampleable lobe).
constexpr double kMinGgxAlpha = 1e-4;

struct BsdfParams {
  Eigen::Vector3d albedo = Eigen::Vector3d::Constant(0.7);
  double roughness = 0.5;
  double specular = 0.0;
  FresnelMode fresnel = FresnelMode::kConstant;

  double Alpha() const;
};

// The lobe's factors, templated on the scalar so that one definition serves the values (T =
// double) and, with T = ceres::Jet, their exact gradients with respect to the directions
// (EvalGlossyWithGradient). Comparisons use the scalar part.

// max(0, x), with max(0, NaN) = 0 as std::max(0.0, x).
template <typename T>
T ClampNonNegative(const T& x) {
  return 0.0 < x ? x : T(0.0);
}

// GGX normal distribution D(h) with cos_h = n·h, α as above; 0 for cos_h ≤ 0.
template <typename T>
T GgxD(const T& cos_h, double alpha) {
  if (cos_h <= 0.0) return T(0.0);
  const double a2 = alpha * alpha;
  const T cos2 = cos_h * cos_h;
  // 1 + cos²(α² − 1) written as sin² + cos²·α² so it stays accurate for tiny α.
  const T denom = ClampNonNegative<T>(1.0 - cos2) + cos2 * a2;
  return a2 / (M_PI * denom * denom);
}

// Smith G1 for GGX of a direction with cosine `cos_w` to the normal.
template <typename T>
T GgxG1(const T& cos_w, double alpha) {
  if (cos_w <= 0.0) return T(0.0);
  using std::sqrt;
  const T cos2 = cos_w * cos_w;
  const T tan2 = ClampNonNegative<T>(1.0 - cos2) / cos2;
  return 2.0 / (1.0 + sqrt(1.0 + alpha * alpha * tan2));
}

// Schlick's Fresnel with F0 = f0 at cos_d = wi·h.
template <typename T>
T SchlickFresnel(double f0, const T& cos_d) {
  T m = 1.0 - cos_d;  // clamped to [0, 1] as std::clamp.
  if (m < 0.0) {
    m = T(0.0);
  } else if (1.0 < m) {
    m = T(1.0);
  }
  const T m2 = m * m;
  return f0 + (1.0 - f0) * m2 * m2 * m;
}

// f(wo, wi) (no cosine factor). Returns zero for directions below the surface.
Eigen::Vector3d EvalBsdf(const BsdfParams& params, const Eigen::Vector3d& n,
                         const Eigen::Vector3d& wo, const Eigen::Vector3d& wi);

// Partial derivatives of f(wo, wi) with respect to the material parameters of the shading point
// (same directions and normal; zero below the surface):
//   ∂f_c/∂albedo_c = 1/π (and ∂f_c/∂albedo_k = 0 for k ≠ c);
//   ∂f/∂roughness = F·∂(D·G1·G1)/∂α · dα/dr / (4|n·wi||n·wo|), the same in every channel,
//                   zero where α is clamped at kMinGgxAlpha;
//   ∂f/∂specular = D·G1·G1/(4|n·wi||n·wo|) for constant Fresnel, times (1 − (1 − wi·h)⁵) for
//                  Schlick — the same in every channel.
// `specular_scale` is the factor the renderer applies to the material's specular weight (0 when
// the specular effect is off), so ∂f/∂specular is scaled by it.
struct BsdfDerivatives {
  double d_albedo = 0.0;     // per channel, on its own channel only.
  double d_roughness = 0.0;  // all channels.
  double d_specular = 0.0;   // all channels.
};
BsdfDerivatives EvalBsdfDerivatives(const BsdfParams& params, const Eigen::Vector3d& n,
                                    const Eigen::Vector3d& wo, const Eigen::Vector3d& wi,
                                    double specular_scale);

// The glossy term g of f = albedo/π + g (the same in every channel; zero below the surface or
// when specular ≤ 0), with its gradients with respect to the normal and to wi (as free 3-vectors:
// the caller projects them onto the unit sphere's tangent space through its own chain rule).
// Used for vertex derivatives, where n and (for point lights) wi move with the geometry.
double EvalGlossyWithGradient(const BsdfParams& params, const Eigen::Vector3d& n,
                              const Eigen::Vector3d& wo, const Eigen::Vector3d& wi,
                              Eigen::Vector3d* d_n, Eigen::Vector3d* d_wi);

// dD/dα and dG1/dα of the functions above (for derivative tests and EvalBsdfDerivatives).
double GgxDAlphaDerivative(double cos_h, double alpha);
double GgxG1AlphaDerivative(double cos_w, double alpha);

struct BsdfSample {
  Eigen::Vector3d wi;
  Eigen::Vector3d f;  // f(wo, wi)
  double pdf = 0.0;   // solid-angle density of the mixture (both lobes), > 0 when valid.
};

// Probability of choosing the glossy lobe when sampling (the rest goes to the cosine lobe):
// proportional to the lobes' weights (specular vs mean albedo).
double GlossySelectionProbability(const BsdfParams& params);

// Samples wi from the lobe mixture: cosine-weighted hemisphere for Lambert, GGX visible normals
// (Heitz 2018) for the glossy lobe. `u` holds three uniform numbers in [0, 1). Returns false when
// no direction can be produced (black material, wo below the surface, sample below the surface).
bool SampleBsdf(const BsdfParams& params, const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                const Eigen::Vector3d& u, BsdfSample* sample);

// The solid-angle pdf with which SampleBsdf produces wi.
double BsdfPdf(const BsdfParams& params, const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
               const Eigen::Vector3d& wi);

// An orthonormal basis (t, b, n) around unit n (Duff et al. 2017).
void OrthonormalBasis(const Eigen::Vector3d& n, Eigen::Vector3d* t, Eigen::Vector3d* b);

}  // namespace sft

#endif  // SFT_RENDER_BSDF_H_
