#include "src/geometry/uv_texture.h"

#include <glog/logging.h>

#include <cmath>

namespace sft {
namespace {

// i mod n in [0, n) for any finite i (a non-finite coordinate maps to 0).
int Wrap(double i, int n) {
  if (!std::isfinite(i)) return 0;
  const double m = std::fmod(i, static_cast<double>(n));
  const int k = static_cast<int>(m < 0 ? m + n : m);
  return k >= n ? 0 : k;
}

}  // namespace

UvTexture::UvTexture(int width, int height, int channels, double fill)
    : width_(width),
      height_(height),
      channels_(channels),
      values_(static_cast<size_t>(width) * height * channels, fill) {
  CHECK(width >= 0 && height >= 0 && channels >= 1) << width << "x" << height << "x" << channels;
}

UvTexture UvTexture::FromImage(const Image& image, int channels) {
  CHECK_GE(image.channels, channels);
  UvTexture texture(image.width, image.height, channels);
  for (int k = 0; k < texture.num_texels(); ++k) {
    for (int c = 0; c < channels; ++c) {
      texture.texel(k)[c] = image.data[static_cast<size_t>(k) * image.channels + c];
    }
  }
  return texture;
}

BilinearFootprint UvTexture::Footprint(const Eigen::Vector2d& uv) const {
  const double px = uv.x() * width_ - 0.5, py = (1.0 - uv.y()) * height_ - 0.5;
  const double fx = std::floor(px), fy = std::floor(py);
  const double s = std::isfinite(px) ? px - fx : 0.0, t = std::isfinite(py) ? py - fy : 0.0;
  const int x0 = Wrap(fx, width_), y0 = Wrap(fy, height_);
  const int x1 = x0 + 1 == width_ ? 0 : x0 + 1;
  const int y1 = y0 + 1 == height_ ? 0 : y0 + 1;
  BilinearFootprint f;
  f.texel[0] = y0 * width_ + x0;
  f.texel[1] = y0 * width_ + x1;
  f.texel[2] = y1 * width_ + x0;
  f.texel[3] = y1 * width_ + x1;
  f.weight[0] = (1 - s) * (1 - t);
  f.weight[1] = s * (1 - t);
  f.weight[2] = (1 - s) * t;
  f.weight[3] = s * t;
  f.s = s;
  f.t = t;
  return f;
}

void UvTexture::Gradient(const BilinearFootprint& f, double* d_du, double* d_dv) const {
  const double* t0 = texel(f.texel[0]);
  const double* t1 = texel(f.texel[1]);
  const double* t2 = texel(f.texel[2]);
  const double* t3 = texel(f.texel[3]);
  for (int c = 0; c < channels_; ++c) {
    const double d_ds = (1 - f.t) * (t1[c] - t0[c]) + f.t * (t3[c] - t2[c]);
    const double d_dt = (1 - f.s) * (t2[c] - t0[c]) + f.s * (t3[c] - t1[c]);
    d_du[c] = width_ * d_ds;    // s = u·W − ½ − x0.
    d_dv[c] = -height_ * d_dt;  // t = (1 − v)·H − ½ − y0.
  }
}

void UvTexture::Sample(const Eigen::Vector2d& uv, double* out) const {
  const BilinearFootprint f = Footprint(uv);
  for (int c = 0; c < channels_; ++c) out[c] = 0.0;
  for (int k = 0; k < 4; ++k) {
    const double* texel_values = texel(f.texel[k]);
    for (int c = 0; c < channels_; ++c) out[c] += f.weight[k] * texel_values[c];
  }
}

}  // namespace sft
