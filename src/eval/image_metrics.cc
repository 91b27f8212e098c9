#include "src/eval/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "src/image/image_io.h"
#ifdef SFT_HAVE_OPENCV_QUALITY
#include <opencv2/quality/qualityssim.hpp>
#endif

namespace sft {
namespace {

// SSIM's window (Wang et al. 2004, as in OpenCV's quality module).
constexpr int kSsimWindow = 11;
constexpr double kSsimSigma = 1.5;

// Checks sizes, channels, mask and values; sets *channels to the compared channel count and
// *masked to the number of pixels in the mask.
Status CheckInputs(const Image& ours, const Image& reference, const Image& mask,
                   const ImageMetricsOptions& options, int* channels, size_t* masked) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (ours.empty() || reference.empty()) return Status::Error("image is empty");
  if (ours.width != reference.width || ours.height != reference.height ||
      ours.channels != reference.channels) {
    return Status::Error(
        "image sizes differ: " + std::to_string(ours.width) + "x" + std::to_string(ours.height) +
        "x" + std::to_string(ours.channels) + " vs reference " + std::to_string(reference.width) +
        "x" + std::to_string(reference.height) + "x" + std::to_string(reference.channels));
  }
  if (!mask.empty() &&
      (mask.width != ours.width || mask.height != ours.height || mask.channels != 1)) {
    return Status::Error("mask must be one channel of the image's size");
  }
  *channels = std::min(ours.channels, 3);
  *masked = 0;
  for (int y = 0; y < ours.height; ++y) {
    for (int x = 0; x < ours.width; ++x) {
      if (!mask.empty() && !(mask.at(x, y) > 0.5f)) continue;
      ++*masked;
      for (int c = 0; c < *channels; ++c) {
        if (!std::isfinite(ours.at(x, y, c)) || !std::isfinite(reference.at(x, y, c))) {
          return Status::Error("non-finite pixel value at (" + std::to_string(x) + ", " +
                               std::to_string(y) + ")");
        }
      }
    }
  }
  if (*masked == 0) return Status::Error("mask selects no pixel");
  return Status::Ok();
}

// The first `channels` channels as a CV_64F matrix scaled by `scale`.
cv::Mat ToMat(const Image& image, int channels, double scale) {
  cv::Mat mat(image.height, image.width, CV_64FC(channels));
  for (int y = 0; y < image.height; ++y) {
    double* row = mat.ptr<double>(y);
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < channels; ++c) row[x * channels + c] = scale * image.at(x, y, c);
    }
  }
  return mat;
}

// Mean of a CV_64F map over the masked pixels, per channel, then over channels.
double MaskedMapMean(const cv::Mat& map, const Image& mask) {
  const int channels = map.channels();
  double sum = 0.0;
  size_t count = 0;
  for (int y = 0; y < map.rows; ++y) {
    const double* row = map.ptr<double>(y);
    for (int x = 0; x < map.cols; ++x) {
      if (!mask.empty() && !(mask.at(x, y) > 0.5f)) continue;
      for (int c = 0; c < channels; ++c) sum += row[x * channels + c];
      ++count;
    }
  }
  // Equal pixel counts per channel: the mean of channel means is the mean of everything.
  return sum / (static_cast<double>(count) * channels);
}

cv::Mat Blur(const cv::Mat& m) {
  cv::Mat out;
  cv::GaussianBlur(m, out, cv::Size(kSsimWindow, kSsimWindow), kSsimSigma);
  return out;
}

// The SSIM map of a and b (same size and channels, CV_64F) for dynamic range `range`.
cv::Mat SsimMap(const cv::Mat& a, const cv::Mat& b, double range) {
  const double c1 = (0.01 * range) * (0.01 * range);
  const double c2 = (0.03 * range) * (0.03 * range);
  const cv::Mat mu_a = Blur(a), mu_b = Blur(b);
  const cv::Mat mu_aa = mu_a.mul(mu_a), mu_bb = mu_b.mul(mu_b), mu_ab = mu_a.mul(mu_b);
  const cv::Mat var_a = Blur(a.mul(a)) - mu_aa;
  const cv::Mat var_b = Blur(b.mul(b)) - mu_bb;
  const cv::Mat cov = Blur(a.mul(b)) - mu_ab;
  const cv::Mat numerator = (2.0 * mu_ab + c1).mul(2.0 * cov + c2);
  const cv::Mat denominator = (mu_aa + mu_bb + c1).mul(var_a + var_b + c2);
  cv::Mat map;
  cv::divide(numerator, denominator, map);
  return map;
}

}  // namespace

bool ImageMetricsOptions::Check(std::string* why) const {
  if (!(peak > 0.0 && std::isfinite(peak))) {
    *why = "peak: must be finite and > 0, got " + std::to_string(peak);
    return false;
  }
  if (!(max_psnr > 0.0 && std::isfinite(max_psnr))) {
    *why = "max_psnr: must be finite and > 0, got " + std::to_string(max_psnr);
    return false;
  }
  return true;
}

Status ComputePsnr(const Image& ours, const Image& reference, const Image& mask,
                   const ImageMetricsOptions& options, double* psnr) {
  int channels = 0;
  size_t masked = 0;
  SFT_RETURN_IF_ERROR(CheckInputs(ours, reference, mask, options, &channels, &masked));
  double sum = 0.0;
  for (int y = 0; y < ours.height; ++y) {
    for (int x = 0; x < ours.width; ++x) {
      if (!mask.empty() && !(mask.at(x, y) > 0.5f)) continue;
      for (int c = 0; c < channels; ++c) {
        const double d = static_cast<double>(ours.at(x, y, c)) - reference.at(x, y, c);
        sum += d * d;
      }
    }
  }
  const double mse = sum / (static_cast<double>(masked) * channels);
  const double value = mse > 0.0 ? 10.0 * std::log10(options.peak * options.peak / mse) : HUGE_VAL;
  *psnr = std::min(value, options.max_psnr);
  return Status::Ok();
}

Status SsimGaussian(const Image& ours, const Image& reference, const Image& mask,
                    const ImageMetricsOptions& options, double* ssim) {
  int channels = 0;
  size_t masked = 0;
  SFT_RETURN_IF_ERROR(CheckInputs(ours, reference, mask, options, &channels, &masked));
  const cv::Mat map =
      SsimMap(ToMat(reference, channels, 1.0), ToMat(ours, channels, 1.0), options.peak);
  *ssim = MaskedMapMean(map, mask);
  return Status::Ok();
}

bool HaveQualitySsim() {
#ifdef SFT_HAVE_OPENCV_QUALITY
  return true;
#else
  return false;
#endif
}

Status ComputeSsim(const Image& ours, const Image& reference, const Image& mask,
                   const ImageMetricsOptions& options, double* ssim) {
#ifdef SFT_HAVE_OPENCV_QUALITY
  int channels = 0;
  size_t masked = 0;
  SFT_RETURN_IF_ERROR(CheckInputs(ours, reference, mask, options, &channels, &masked));
  // QualitySSIM's constants are those of L = 255.
  const double scale = 255.0 / options.peak;
  cv::Mat quality_map, map;  // one multi-channel map (OpenCV 4.6's single-image interface).
  cv::quality::QualitySSIM::compute(ToMat(reference, channels, scale), ToMat(ours, channels, scale),
                                    quality_map);
  quality_map.convertTo(map, CV_64F);
  *ssim = MaskedMapMean(map, mask);
  return Status::Ok();
#else
  return SsimGaussian(ours, reference, mask, options, ssim);
#endif
}

Image DisplayImage(const Image& image) {
  Image out = image;
  const int colour = std::min(image.channels, 3);
  for (size_t i = 0; i < out.data.size(); ++i) {
    if (static_cast<int>(i % image.channels) < colour) out.data[i] = LinearToSrgb(out.data[i]);
  }
  return out;
}

Status ComputeRelativeRmse(const Image& ours, const Image& reference, const Image& mask,
                           double* relative_rmse) {
  int channels = 0;
  size_t masked = 0;
  SFT_RETURN_IF_ERROR(
      CheckInputs(ours, reference, mask, ImageMetricsOptions(), &channels, &masked));
  double error = 0.0, energy = 0.0;
  for (int y = 0; y < ours.height; ++y) {
    for (int x = 0; x < ours.width; ++x) {
      if (!mask.empty() && !(mask.at(x, y) > 0.5f)) continue;
      for (int c = 0; c < channels; ++c) {
        const double r = reference.at(x, y, c);
        const double d = static_cast<double>(ours.at(x, y, c)) - r;
        error += d * d;
        energy += r * r;
      }
    }
  }
  *relative_rmse =
      energy > 0.0 ? std::sqrt(error / energy) : std::numeric_limits<double>::quiet_NaN();
  return Status::Ok();
}

Status ComputeImageScores(const Image& ours, const Image& reference, const Image& mask,
                          const ImageMetricsOptions& options, ImageScores* scores) {
  SFT_RETURN_IF_ERROR(ComputePsnr(ours, reference, mask, options, &scores->psnr_linear));
  SFT_RETURN_IF_ERROR(ComputeSsim(ours, reference, mask, options, &scores->ssim_linear));
  SFT_RETURN_IF_ERROR(ComputeRelativeRmse(ours, reference, mask, &scores->relative_rmse));
  ImageMetricsOptions display = options;
  display.peak = 1.0;
  const Image ours_display = DisplayImage(ours), reference_display = DisplayImage(reference);
  SFT_RETURN_IF_ERROR(
      ComputePsnr(ours_display, reference_display, mask, display, &scores->psnr_srgb));
  return ComputeSsim(ours_display, reference_display, mask, display, &scores->ssim_srgb);
}

}  // namespace sft
