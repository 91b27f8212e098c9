#include "src/render/bsdf.h"

#include <ceres/jet.h>

#include <algorithm>
#include <cmath>

namespace sft {
namespace {

constexpr double kPi = M_PI;

Eigen::Vector3d ToLocal(const Eigen::Vector3d& w, const Eigen::Vector3d& t,
                        const Eigen::Vector3d& b, const Eigen::Vector3d& n) {
  return {w.dot(t), w.dot(b), w.dot(n)};
}

// Cosine-weighted hemisphere direction in the local frame (z up), Malley's method.
Eigen::Vector3d SampleCosineHemisphere(double u1, double u2) {
  const double r = std::sqrt(u1);
  const double phi = 2.0 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1))};
}

// GGX visible-normal sample (Heitz 2018, "Sampling the GGX Distribution of Visible Normals"),
// isotropic α, local frame with wo.z > 0. Returns the microfacet normal h.
Eigen::Vector3d SampleGgxVisibleNormal(const Eigen::Vector3d& wo, double alpha, double u1,
                                       double u2) {
  // Stretch to the hemisphere configuration.
  const Eigen::Vector3d vh = Eigen::Vector3d(alpha * wo.x(), alpha * wo.y(), wo.z()).normalized();
  const double lensq = vh.x() * vh.x() + vh.y() * vh.y();
  const Eigen::Vector3d t1 =
      lensq > 0 ? Eigen::Vector3d(-vh.y(), vh.x(), 0) / std::sqrt(lensq) : Eigen::Vector3d(1, 0, 0);
  const Eigen::Vector3d t2 = vh.cross(t1);
  const double r = std::sqrt(u1);
  const double phi = 2.0 * kPi * u2;
  const double p1 = r * std::cos(phi);
  double p2 = r * std::sin(phi);
  const double s = 0.5 * (1.0 + vh.z());
  p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
  const Eigen::Vector3d nh =
      p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  // Unstretch.
  return Eigen::Vector3d(alpha * nh.x(), alpha * nh.y(), std::max(1e-12, nh.z())).normalized();
}

// The glossy term g of f = albedo/π + g as a function of (n, wo, wi), templated so that
// ceres::Jet gives its exact gradient (EvalGlossyWithGradient) and T = double its value
// (EvalBsdf). Zero below the surface, for specular ≤ 0, and for wi = −wo.
template <typename T>
T GlossyTerm(const Eigen::Matrix<T, 3, 1>& n, const Eigen::Vector3d& wo,
             const Eigen::Matrix<T, 3, 1>& wi, double alpha, double specular, FresnelMode mode) {
  using std::sqrt;
  const T cos_o = n.dot(wo.cast<T>());
  const T cos_i = n.dot(wi);
  if (cos_o <= 0.0 || cos_i <= 0.0 || specular <= 0.0) return T(0.0);
  const Eigen::Matrix<T, 3, 1> sum = wi + wo.cast<T>();
  const T len = sqrt(sum.squaredNorm());
  if (!(len > 1e-12)) return T(0.0);
  const Eigen::Matrix<T, 3, 1> h = sum / len;
  const T fresnel =
      mode == FresnelMode::kSchlick ? SchlickFresnel<T>(specular, wi.dot(h)) : T(specular);
  return fresnel * GgxD<T>(n.dot(h), alpha) * GgxG1<T>(cos_i, alpha) * GgxG1<T>(cos_o, alpha) /
         (4.0 * cos_i * cos_o);
}

double Luminance(const Eigen::Vector3d& c) { return (c.x() + c.y() + c.z()) / 3.0; }

}  // namespace

double BsdfParams::Alpha() const { return std::max(kMinGgxAlpha, roughness * roughness); }

double GlossySelectionProbability(const BsdfParams& params) {
  const double diffuse = std::max(0.0, Luminance(params.albedo));
  const double glossy = std::max(0.0, params.specular);
  if (glossy <= 0.0) return 0.0;
  if (diffuse <= 0.0) return 1.0;
  // Keep both lobes sampled with at least 10% so MIS never faces a near-zero pdf.
  return std::clamp(glossy / (glossy + diffuse), 0.1, 0.9);
}

Eigen::Vector3d EvalBsdf(const BsdfParams& params, const Eigen::Vector3d& n,
                         const Eigen::Vector3d& wo, const Eigen::Vector3d& wi) {
  const double cos_o = n.dot(wo);
  const double cos_i = n.dot(wi);
  if (cos_o <= 0.0 || cos_i <= 0.0) return Eigen::Vector3d::Zero();
  Eigen::Vector3d f = params.albedo / kPi;
  if (params.specular > 0.0) {
    f.array() += GlossyTerm<double>(n, wo, wi, params.Alpha(), params.specular, params.fresnel);
  }
  return f;
}

double GgxDAlphaDerivative(double cos_h, double alpha) {
  if (cos_h <= 0.0) return 0.0;
  const double cos2 = cos_h * cos_h;
  const double q = std::max(0.0, 1.0 - cos2) + cos2 * alpha * alpha;
  // D = α²/(π q²), q = sin² + cos²·α²:  dD/dα = 2α/(π q²) · (1 − 2α² cos²/q).
  return 2.0 * alpha / (kPi * q * q) * (1.0 - 2.0 * alpha * alpha * cos2 / q);
}

double GgxG1AlphaDerivative(double cos_w, double alpha) {
  if (cos_w <= 0.0) return 0.0;
  const double cos2 = cos_w * cos_w;
  const double tan2 = std::max(0.0, 1.0 - cos2) / cos2;
  const double root = std::sqrt(1.0 + alpha * alpha * tan2);
  // G1 = 2/(1 + R), R = √(1 + α² tan²):  dG1/dα = −2/(1 + R)² · α tan²/R.
  return -2.0 / ((1.0 + root) * (1.0 + root)) * alpha * tan2 / root;
}

BsdfDerivatives EvalBsdfDerivatives(const BsdfParams& params, const Eigen::Vector3d& n,
                                    const Eigen::Vector3d& wo, const Eigen::Vector3d& wi,
                                    double specular_scale) {
  BsdfDerivatives d;
  const double cos_o = n.dot(wo);
  const double cos_i = n.dot(wi);
  if (cos_o <= 0.0 || cos_i <= 0.0) return d;
  d.d_albedo = 1.0 / kPi;
  if (specular_scale <= 0.0) return d;
  const Eigen::Vector3d sum = wi + wo;
  const double len = sum.norm();
  if (!(len > 1e-12)) return d;
  const Eigen::Vector3d h = sum / len;
  const double alpha = params.Alpha();
  const double cos_h = n.dot(h);
  const double dist = GgxD(cos_h, alpha);
  const double g_i = GgxG1(cos_i, alpha), g_o = GgxG1(cos_o, alpha);
  const double inv = 1.0 / (4.0 * cos_i * cos_o);
  double fresnel = params.specular;
  double d_fresnel_d_specular = 1.0;
  if (params.fresnel == FresnelMode::kSchlick) {
    fresnel = SchlickFresnel(params.specular, wi.dot(h));
    const double m = std::clamp(1.0 - wi.dot(h), 0.0, 1.0);
    d_fresnel_d_specular = 1.0 - m * m * m * m * m;
  }
  d.d_specular = specular_scale * d_fresnel_d_specular * dist * g_i * g_o * inv;
  const double r = params.roughness;
  if (r * r > kMinGgxAlpha) {
    const double d_dgg = GgxDAlphaDerivative(cos_h, alpha) * g_i * g_o +
                         dist * GgxG1AlphaDerivative(cos_i, alpha) * g_o +
                         dist * g_i * GgxG1AlphaDerivative(cos_o, alpha);
    d.d_roughness = fresnel * d_dgg * (2.0 * r) * inv;
  }
  return d;
}

double EvalGlossyWithGradient(const BsdfParams& params, const Eigen::Vector3d& n,
                              const Eigen::Vector3d& wo, const Eigen::Vector3d& wi,
                              Eigen::Vector3d* d_n, Eigen::Vector3d* d_wi) {
  using Jet = ceres::Jet<double, 6>;
  Eigen::Matrix<Jet, 3, 1> n_jet, wi_jet;
  for (int k = 0; k < 3; ++k) {
    n_jet[k] = Jet(n[k], k);
    wi_jet[k] = Jet(wi[k], 3 + k);
  }
  const Jet g = GlossyTerm<Jet>(n_jet, wo, wi_jet, params.Alpha(), params.specular, params.fresnel);
  *d_n = g.v.head<3>();
  *d_wi = g.v.tail<3>();
  return g.a;
}

double BsdfPdf(const BsdfParams& params, const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
               const Eigen::Vector3d& wi) {
  const double cos_o = n.dot(wo);
  const double cos_i = n.dot(wi);
  if (cos_o <= 0.0 || cos_i <= 0.0) return 0.0;
  const double p_glossy = GlossySelectionProbability(params);
  double pdf = (1.0 - p_glossy) * cos_i / kPi;
  if (p_glossy > 0.0) {
    const Eigen::Vector3d sum = wi + wo;
    const double len = sum.norm();
    if (len > 1e-12) {
      const Eigen::Vector3d h = sum / len;
      const double alpha = params.Alpha();
      const double cos_oh = wo.dot(h);
      if (cos_oh > 0.0) {
        // Visible-normal density D_wo(h) = G1(wo)·max(0, wo·h)·D(h)/(n·wo), and dwi/dh = 4·wo·h.
        const double d_visible = GgxG1(cos_o, alpha) * cos_oh * GgxD(n.dot(h), alpha) / cos_o;
        pdf += p_glossy * d_visible / (4.0 * cos_oh);
      }
    }
  }
  return pdf;
}

bool SampleBsdf(const BsdfParams& params, const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                const Eigen::Vector3d& u, BsdfSample* sample) {
  if (n.dot(wo) <= 0.0) return false;
  if (params.albedo.maxCoeff() <= 0.0 && params.specular <= 0.0) return false;
  Eigen::Vector3d t, b;
  OrthonormalBasis(n, &t, &b);
  const double p_glossy = GlossySelectionProbability(params);
  Eigen::Vector3d wi;
  if (u.x() < p_glossy) {
    const Eigen::Vector3d wo_local = ToLocal(wo, t, b, n);
    const Eigen::Vector3d h_local = SampleGgxVisibleNormal(wo_local, params.Alpha(), u.y(), u.z());
    const Eigen::Vector3d h = h_local.x() * t + h_local.y() * b + h_local.z() * n;
    wi = 2.0 * wo.dot(h) * h - wo;
  } else {
    const Eigen::Vector3d local = SampleCosineHemisphere(u.y(), u.z());
    wi = local.x() * t + local.y() * b + local.z() * n;
  }
  wi.normalize();
  if (n.dot(wi) <= 0.0) return false;
  sample->wi = wi;
  sample->pdf = BsdfPdf(params, n, wo, wi);
  if (!(sample->pdf > 0.0) || !std::isfinite(sample->pdf)) return false;
  sample->f = EvalBsdf(params, n, wo, wi);
  return true;
}

void OrthonormalBasis(const Eigen::Vector3d& n, Eigen::Vector3d* t, Eigen::Vector3d* b) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double bb = n.x() * n.y() * a;
  *t = Eigen::Vector3d(1.0 + sign * n.x() * n.x() * a, sign * bb, -sign * n.x());
  *b = Eigen::Vector3d(bb, sign + n.y() * n.y() * a, -n.y());
}

}  // namespace sft
