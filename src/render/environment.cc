#include "src/render/environment.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace sft {
namespace {

constexpr double kPi = M_PI;

// Index i with cdf[i] <= u < cdf[i + 1], skipping zero-width intervals.
int SampleCdf(const double* cdf, int n, double u) {
  const double* it = std::upper_bound(cdf, cdf + n + 1, u);
  int i = static_cast<int>(it - cdf) - 1;
  return std::clamp(i, 0, n - 1);
}

// The x in [0, 1] with F(x) = u for the density ∝ a·(1 − x) + b·x (a, b ≥ 0, a + b > 0):
// F(x) = (2a·x + (b − a)·x²)/(a + b), inverted in the form that is stable when a ≈ b.
double InvertLinear(double a, double b, double u) {
  const double denominator = a + std::sqrt(std::max(0.0, a * a + u * (b * b - a * a)));
  if (!(denominator > 0.0)) return u;
  return std::clamp(u * (a + b) / denominator, 0.0, 1.0);
}

}  // namespace

EnvironmentMap::EnvironmentMap(const Image& rgb, const Eigen::Matrix3d& world_from_env,
                               double scale)
    : width_(rgb.width), height_(rgb.height), world_from_env_(world_from_env), scale_(scale) {
  texels_.resize(static_cast<size_t>(width_) * height_);
  value_.resize(texels_.size());
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      Eigen::Vector3f c;
      for (int k = 0; k < 3; ++k) {
        const float v = rgb.at(x, y, std::min(k, rgb.channels - 1)) * static_cast<float>(scale);
        c[k] = std::isfinite(v) ? std::max(0.0f, v) : 0.0f;
      }
      const size_t index = static_cast<size_t>(y) * width_ + x;
      texels_[index] = c;
      value_[index] = (static_cast<double>(c.x()) + c.y() + c.z()) / 3.0;
    }
  }
  // Bands between row centres; θ(t) = π (v0 + t·dv), and the sin θ moments in closed form.
  bands_.resize(height_ + 1);
  for (int j = 0; j <= height_; ++j) {
    Band& band = bands_[j];
    band.v0 = std::max(0.0, (j - 0.5) / height_);
    band.dv = std::min(1.0, (j + 0.5) / height_) - band.v0;
    band.row0 = std::clamp(j - 1, 0, height_ - 1);
    band.row1 = std::clamp(j, 0, height_ - 1);
    const double alpha = kPi * band.dv, beta = kPi * band.v0;
    band.sin0 = (std::cos(beta) - std::cos(beta + alpha)) / alpha;
    band.sin1 = -std::cos(beta + alpha) / alpha +
                (std::sin(beta + alpha) - std::sin(beta)) / (alpha * alpha);
  }
  band_cdf_.assign(height_ + 2, 0.0);
  column_cdf_.assign(static_cast<size_t>(height_ + 1) * (width_ + 1), 0.0);
  for (int j = 0; j <= height_; ++j) {
    double* cdf = &column_cdf_[static_cast<size_t>(j) * (width_ + 1)];
    for (int i = 0; i < width_; ++i) cdf[i + 1] = cdf[i] + CellWeight(i, j);
    band_cdf_[j + 1] = band_cdf_[j] + cdf[width_];
    if (cdf[width_] > 0) {
      for (int i = 1; i <= width_; ++i) cdf[i] /= cdf[width_];
    }
  }
  total_weight_ = band_cdf_[height_ + 1];
  black_ = !(total_weight_ > 0.0);
  if (!black_) {
    for (double& c : band_cdf_) c /= total_weight_;
  }
}

Eigen::Vector4d EnvironmentMap::Corners(int i, int j) const {
  const Band& band = bands_[j];
  const int i1 = i + 1 == width_ ? 0 : i + 1;
  const size_t top = static_cast<size_t>(band.row0) * width_;
  const size_t bottom = static_cast<size_t>(band.row1) * width_;
  return {value_[top + i], value_[top + i1], value_[bottom + i], value_[bottom + i1]};
}

double EnvironmentMap::CellWeight(int i, int j) const {
  const Eigen::Vector4d f = Corners(i, j);
  const Band& band = bands_[j];
  // ∫₀¹∫₀¹ f(s, t) sin θ(t) ds dt with f bilinear: the s-mean is linear in t.
  const double top = 0.5 * (f[0] + f[1]), bottom = 0.5 * (f[2] + f[3]);
  return (top * (band.sin0 - band.sin1) + bottom * band.sin1) * band.dv / width_;
}

EnvironmentMap::CellPoint EnvironmentMap::CellOf(double u, double v) const {
  CellPoint p;
  const double x = u * width_ - 0.5;
  const double fx = std::floor(x);
  p.s = std::clamp(x - fx, 0.0, 1.0);
  p.i = static_cast<int>(fx) % width_;
  if (p.i < 0) p.i += width_;
  p.j = std::clamp(static_cast<int>(std::floor(v * height_ - 0.5)) + 1, 0, height_);
  const Band& band = bands_[p.j];
  p.t = std::clamp((v - band.v0) / band.dv, 0.0, 1.0);
  return p;
}

EnvironmentMap::CellPoint EnvironmentMap::CellOfDirection(const Eigen::Vector3d& dir) const {
  const Eigen::Vector3d d = world_from_env_.transpose() * dir;
  const double u = 0.5 - std::atan2(d.y(), d.x()) / (2.0 * kPi);
  const double v = std::acos(std::clamp(d.z(), -1.0, 1.0)) / kPi;
  return CellOf(u, v);
}

Eigen::Vector3d EnvironmentMap::Interpolate(const CellPoint& p) const {
  const Band& band = bands_[p.j];
  const int i1 = p.i + 1 == width_ ? 0 : p.i + 1;
  const size_t top = static_cast<size_t>(band.row0) * width_;
  const size_t bottom = static_cast<size_t>(band.row1) * width_;
  const Eigen::Vector3d upper =
      (1.0 - p.s) * texels_[top + p.i].cast<double>() + p.s * texels_[top + i1].cast<double>();
  const Eigen::Vector3d lower = (1.0 - p.s) * texels_[bottom + p.i].cast<double>() +
                                p.s * texels_[bottom + i1].cast<double>();
  return (1.0 - p.t) * upper + p.t * lower;
}

double EnvironmentMap::UvPdf(const CellPoint& p) const {
  const Eigen::Vector4d f = Corners(p.i, p.j);
  const double mean = 0.25 * f.sum();  // ∫∫ f ds dt over the cell.
  if (!(mean > 0.0)) return 0.0;
  const double value =
      (1.0 - p.t) * ((1.0 - p.s) * f[0] + p.s * f[1]) + p.t * ((1.0 - p.s) * f[2] + p.s * f[3]);
  const double cell_area = bands_[p.j].dv / width_;
  return CellWeight(p.i, p.j) / total_weight_ * (value / mean) / cell_area;
}

Eigen::Vector3d EnvironmentMap::Radiance(const Eigen::Vector3d& dir) const {
  // A zero or non-finite direction is no ray (Camera::CamFromImage past a distortion's fold).
  if (!(dir.squaredNorm() > 0.0) || !dir.allFinite()) return Eigen::Vector3d::Zero();
  return Interpolate(CellOfDirection(dir));
}

void EnvironmentMap::TexelWeights(const Eigen::Vector3d& dir, int texel[4],
                                  double weight[4]) const {
  if (!(dir.squaredNorm() > 0.0) || !dir.allFinite()) {
    for (int k = 0; k < 4; ++k) texel[k] = 0, weight[k] = 0.0;
    return;
  }
  const CellPoint p = CellOfDirection(dir);
  const Band& band = bands_[p.j];
  const int i1 = p.i + 1 == width_ ? 0 : p.i + 1;
  texel[0] = band.row0 * width_ + p.i;
  texel[1] = band.row0 * width_ + i1;
  texel[2] = band.row1 * width_ + p.i;
  texel[3] = band.row1 * width_ + i1;
  weight[0] = (1.0 - p.t) * (1.0 - p.s);
  weight[1] = (1.0 - p.t) * p.s;
  weight[2] = p.t * (1.0 - p.s);
  weight[3] = p.t * p.s;
}

Eigen::Matrix3d EnvironmentMap::RotationJacobian(const Eigen::Vector3d& dir) const {
  const double norm = dir.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) return Eigen::Matrix3d::Zero();
  const Eigen::Vector3d d = dir / norm;
  const Eigen::Vector3d e = world_from_env_.transpose() * d;
  const CellPoint p = CellOf(0.5 - std::atan2(e.y(), e.x()) / (2.0 * kPi),
                             std::acos(std::clamp(e.z(), -1.0, 1.0)) / kPi);
  const Band& band = bands_[p.j];
  const int i1 = p.i + 1 == width_ ? 0 : p.i + 1;
  const size_t top = static_cast<size_t>(band.row0) * width_;
  const size_t bottom = static_cast<size_t>(band.row1) * width_;
  const Eigen::Vector3d t00 = texels_[top + p.i].cast<double>();
  const Eigen::Vector3d t01 = texels_[top + i1].cast<double>();
  const Eigen::Vector3d t10 = texels_[bottom + p.i].cast<double>();
  const Eigen::Vector3d t11 = texels_[bottom + i1].cast<double>();
  // L = (1 − t)·((1 − s)·t00 + s·t01) + t·((1 − s)·t10 + s·t11), s = u·W − 0.5 − i and
  // t = (v − v0)/dv within the cell.
  const Eigen::Vector3d d_du = width_ * ((1.0 - p.t) * (t01 - t00) + p.t * (t11 - t10));
  const Eigen::Vector3d d_dv = ((1.0 - p.s) * (t10 - t00) + p.s * (t11 - t01)) / band.dv;
  // u = 0.5 − atan2(y, x)/(2π): ∂u/∂e = (y, −x, 0)/(2π ρ²); v = acos(z)/π: ∂v/∂e = (0, 0,
  // −1/(π ρ)), with ρ = |e_xy| = sin of the polar angle (e is a unit vector, de ⟂ e).
  const double rho2 = e.x() * e.x() + e.y() * e.y();
  Eigen::Matrix<double, 3, 3> d_de = Eigen::Matrix3d::Zero();
  if (rho2 > 1e-24) {
    const double rho = std::sqrt(rho2);
    const Eigen::RowVector3d du_de(e.y() / (2.0 * kPi * rho2), -e.x() / (2.0 * kPi * rho2), 0.0);
    const Eigen::RowVector3d dv_de(0.0, 0.0, -1.0 / (kPi * rho));
    d_de = d_du * du_de + d_dv * dv_de;
  }
  // e = Mᵀ·exp(−[θ]×)·d ≈ Mᵀ·(d − θ × d) = Mᵀ·(d + [d]×θ).
  Eigen::Matrix3d cross;
  cross << 0.0, -d.z(), d.y(), d.z(), 0.0, -d.x(), -d.y(), d.x(), 0.0;
  return d_de * (world_from_env_.transpose() * cross);
}

EnvironmentMap EnvironmentMap::Rotated(const Eigen::Matrix3d& rotation) const {
  EnvironmentMap out = *this;
  out.world_from_env_ = rotation * world_from_env_;
  return out;
}

bool EnvironmentMap::Sample(double u1, double u2, Eigen::Vector3d* dir, Eigen::Vector3d* radiance,
                            double* pdf) const {
  if (black_) return false;
  CellPoint p;
  p.j = SampleCdf(band_cdf_.data(), height_ + 1, u1);
  const double band_width = band_cdf_[p.j + 1] - band_cdf_[p.j];
  if (!(band_width > 0)) return false;
  const double* cdf = &column_cdf_[static_cast<size_t>(p.j) * (width_ + 1)];
  p.i = SampleCdf(cdf, width_, u2);
  const double cell_width = cdf[p.i + 1] - cdf[p.i];
  if (!(cell_width > 0)) return false;
  // The remainders within the chosen intervals are uniform and independent of the choice.
  const double r1 = std::clamp((u1 - band_cdf_[p.j]) / band_width, 0.0, 1.0 - 1e-12);
  const double r2 = std::clamp((u2 - cdf[p.i]) / cell_width, 0.0, 1.0 - 1e-12);
  const Eigen::Vector4d f = Corners(p.i, p.j);
  p.t = InvertLinear(f[0] + f[1], f[2] + f[3], r1);
  p.s = InvertLinear((1.0 - p.t) * f[0] + p.t * f[2], (1.0 - p.t) * f[1] + p.t * f[3], r2);
  double u = (p.i + 0.5 + p.s) / width_;
  if (u >= 1.0) u -= 1.0;
  const Band& band = bands_[p.j];
  const double theta = (band.v0 + p.t * band.dv) * kPi;
  const double phi = (0.5 - u) * 2.0 * kPi;
  const double sin_theta = std::sin(theta);
  if (!(sin_theta > 0)) return false;
  const Eigen::Vector3d d_env(sin_theta * std::cos(phi), sin_theta * std::sin(phi),
                              std::cos(theta));
  *dir = (world_from_env_ * d_env).normalized();
  *radiance = Interpolate(p);
  // dω = 2π² sin θ du dv.
  *pdf = UvPdf(p) / (2.0 * kPi * kPi * sin_theta);
  return *pdf > 0 && std::isfinite(*pdf);
}

double EnvironmentMap::Pdf(const Eigen::Vector3d& dir) const {
  if (black_) return 0.0;
  const Eigen::Vector3d d = world_from_env_.transpose() * dir;
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - d.z() * d.z()));
  if (!(sin_theta > 1e-12)) return 0.0;
  return UvPdf(CellOfDirection(dir)) / (2.0 * kPi * kPi * sin_theta);
}

Eigen::Matrix3d RotationFromVector(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (!(angle > 0.0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, theta / angle).toRotationMatrix();
}

Eigen::Matrix3d RotationLeftJacobian(const Eigen::Vector3d& theta) {
  const double a = theta.norm();
  Eigen::Matrix3d k;
  k << 0.0, -theta.z(), theta.y(), theta.z(), 0.0, -theta.x(), -theta.y(), theta.x(), 0.0;
  // (1 − cos a)/a² = 1/2 − a²/24 + …, (a − sin a)/a³ = 1/6 − a²/120 + ….
  const double a2 = a * a;
  const double c1 = a < 1e-4 ? 0.5 - a2 / 24.0 : (1.0 - std::cos(a)) / a2;
  const double c2 = a < 1e-4 ? 1.0 / 6.0 - a2 / 120.0 : (a - std::sin(a)) / (a2 * a);
  return Eigen::Matrix3d::Identity() + c1 * k + c2 * k * k;
}

Eigen::Vector3d EnvironmentMap::MeanRadiance() const {
  // Σ over cells of ∫∫ L sin θ (2π²) du dv, each channel bilinear like f, over 4π.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int j = 0; j <= height_; ++j) {
    const Band& band = bands_[j];
    const size_t top = static_cast<size_t>(band.row0) * width_;
    const size_t bottom = static_cast<size_t>(band.row1) * width_;
    for (int i = 0; i < width_; ++i) {
      const int i1 = i + 1 == width_ ? 0 : i + 1;
      const Eigen::Vector3d upper =
          0.5 * (texels_[top + i].cast<double>() + texels_[top + i1].cast<double>());
      const Eigen::Vector3d lower =
          0.5 * (texels_[bottom + i].cast<double>() + texels_[bottom + i1].cast<double>());
      sum += (upper * (band.sin0 - band.sin1) + lower * band.sin1) * band.dv / width_;
    }
  }
  return sum * (2.0 * kPi * kPi) / (4.0 * kPi);
}

}  // namespace sft
