#include "src/render/environment.h"

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

}  // namespace

EnvironmentMap::EnvironmentMap(const Image& rgb, const Eigen::Matrix3d& world_from_env,
                               double scale)
    : width_(rgb.width), height_(rgb.height), world_from_env_(world_from_env) {
  texels_.resize(static_cast<size_t>(width_) * height_);
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      Eigen::Vector3f c;
      for (int k = 0; k < 3; ++k) {
        const float v = rgb.at(x, y, std::min(k, rgb.channels - 1)) * static_cast<float>(scale);
        c[k] = std::isfinite(v) ? std::max(0.0f, v) : 0.0f;
      }
      texels_[static_cast<size_t>(y) * width_ + x] = c;
    }
  }
  // Texel weights ∝ luminance · sin θ (the solid angle of a texel row).
  texel_pdf_.assign(texels_.size(), 0.0);
  row_cdf_.assign(height_ + 1, 0.0);
  column_cdf_.assign(static_cast<size_t>(height_) * (width_ + 1), 0.0);

  for (int y = 0; y < height_; ++y) {
    const double sin_theta = std::sin(kPi * (y + 0.5) / height_);
    double* cdf = &column_cdf_[static_cast<size_t>(y) * (width_ + 1)];
    for (int x = 0; x < width_; ++x) {
      const Eigen::Vector3f& c = texels_[static_cast<size_t>(y) * width_ + x];
      const double w = sin_theta * (c.x() + c.y() + c.z()) / 3.0;
      texel_pdf_[static_cast<size_t>(y) * width_ + x] = w;
      cdf[x + 1] = cdf[x] + w;
    }
    row_cdf_[y + 1] = row_cdf_[y] + cdf[width_];
    if (cdf[width_] > 0) {
      for (int x = 1; x <= width_; ++x) cdf[x] /= cdf[width_];
    }
  }
  const double total = row_cdf_[height_];
  black_ = !(total > 0.0);
  if (!black_) {
    for (double& r : row_cdf_) r /= total;
    for (double& p : texel_pdf_) p /= total;
  }
}

void EnvironmentMap::TexelOf(const Eigen::Vector3d& dir, int* x, int* y) const {
  const Eigen::Vector3d d = world_from_env_.transpose() * dir;
  const double u = 0.5 - std::atan2(d.y(), d.x()) / (2.0 * kPi);
  const double v = std::acos(std::clamp(d.z(), -1.0, 1.0)) / kPi;
  *x = std::clamp(static_cast<int>(std::floor(u * width_)), 0, width_ - 1);
  *y = std::clamp(static_cast<int>(std::floor(v * height_)), 0, height_ - 1);
}

Eigen::Vector3d EnvironmentMap::Radiance(const Eigen::Vector3d& dir) const {
  // A zero or non-finite direction is no ray (Camera::CamFromImage past a distortion's fold).
  if (!(dir.squaredNorm() > 0.0) || !dir.allFinite()) return Eigen::Vector3d::Zero();
  int x, y;
  TexelOf(dir, &x, &y);
  return texels_[static_cast<size_t>(y) * width_ + x].cast<double>();
}

bool EnvironmentMap::Sample(double u1, double u2, Eigen::Vector3d* dir, Eigen::Vector3d* radiance,
                            double* pdf) const {
  if (black_) return false;
  const int y = SampleCdf(row_cdf_.data(), height_, u1);
  const double row_width = row_cdf_[y + 1] - row_cdf_[y];
  if (!(row_width > 0)) return false;
  const double du1 = std::clamp((u1 - row_cdf_[y]) / row_width, 0.0, 1.0 - 1e-12);
  const double* cdf = &column_cdf_[static_cast<size_t>(y) * (width_ + 1)];
  const int x = SampleCdf(cdf, width_, u2);
  const double col_width = cdf[x + 1] - cdf[x];
  if (!(col_width > 0)) return false;
  const double du2 = std::clamp((u2 - cdf[x]) / col_width, 0.0, 1.0 - 1e-12);
  // Uniform within the texel in (u, v); the reused remainders are uniform and independent.
  const double u = (x + du2) / width_;
  const double v = (y + du1) / height_;
  const double theta = v * kPi;
  const double phi = (0.5 - u) * 2.0 * kPi;
  const double sin_theta = std::sin(theta);
  if (!(sin_theta > 0)) return false;
  const Eigen::Vector3d d_env(sin_theta * std::cos(phi), sin_theta * std::sin(phi),
                              std::cos(theta));
  *dir = (world_from_env_ * d_env).normalized();
  *radiance = texels_[static_cast<size_t>(y) * width_ + x].cast<double>();
  // p(u, v) = texel_pdf · W · H; dω = 2π² sin θ du dv.
  *pdf = texel_pdf_[static_cast<size_t>(y) * width_ + x] * width_ * height_ /
         (2.0 * kPi * kPi * sin_theta);
  return *pdf > 0 && std::isfinite(*pdf);
}

double EnvironmentMap::Pdf(const Eigen::Vector3d& dir) const {
  if (black_) return 0.0;
  int x, y;
  TexelOf(dir, &x, &y);
  const Eigen::Vector3d d = world_from_env_.transpose() * dir;
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - d.z() * d.z()));
  if (!(sin_theta > 1e-12)) return 0.0;
  return texel_pdf_[static_cast<size_t>(y) * width_ + x] * width_ * height_ /
         (2.0 * kPi * kPi * sin_theta);
}

Eigen::Vector3d EnvironmentMap::MeanRadiance() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0.0;
  for (int y = 0; y < height_; ++y) {
    // Exact solid angle of the row band: 2π (cos θ0 − cos θ1) / width per texel.
    const double w = std::cos(kPi * y / height_) - std::cos(kPi * (y + 1) / height_);
    for (int x = 0; x < width_; ++x) {
      sum += w * texels_[static_cast<size_t>(y) * width_ + x].cast<double>();
      weight += w;
    }
  }
  return weight > 0 ? Eigen::Vector3d(sum / weight) : Eigen::Vector3d::Zero();
}

}  // namespace sft
