// Image quality of re-renders against reference images over a mask (`sft eval`: PSNR and SSIM of
// full, albedo and roughness re-renders, docs/cli.md).
//
// Both measures compare the first min(channels, 3) channels (RGB, or grey); alpha is ignored. The
// mask (optional: an empty Image means every pixel) has one channel, and a pixel counts when its
// value is > 0.5.
//
// PSNR = 10·log10(peak² / MSE), MSE the mean over masked pixels and compared channels of the
// squared difference, in dB. Identical images (MSE = 0) and anything above `max_psnr` report
// `max_psnr` (100 dB by default), so the number stays finite in JSON and in averages.
//
// SSIM (Wang et al. 2004) with the usual constants: an 11×11 Gaussian window of σ = 1.5,
// C1 = (0.01·L)², C2 = (0.03·L)² with the dynamic range L = `peak`. The SSIM map is computed on
// the whole image (windows near the mask's border see background pixels), then averaged over the
// masked pixels per channel, and the channel means are averaged. When opencv_contrib's quality
// module is available the map comes from cv::quality::QualitySSIM (whose constants assume
// L = 255, so images are scaled by 255/peak first); otherwise from SsimGaussian below, which
// computes the same map with cv::GaussianBlur.
#ifndef SFT_EVAL_IMAGE_METRICS_H_
#define SFT_EVAL_IMAGE_METRICS_H_

#include <string>

#include "src/core/image.h"
#include "src/core/status.h"

namespace sft {

struct ImageMetricsOptions {
  // Value of a full-scale pixel: PSNR's MAX and SSIM's dynamic range L; finite, > 0.
  double peak = 1.0;
  // PSNR reported for identical images and the cap for all others; dB, finite, > 0.
  double max_psnr = 100.0;

  bool Check(std::string* why) const;
};

// Errors (one line): empty images, different sizes or channel counts, a mask of the wrong size or
// with more than one channel, no masked pixel, invalid options. Non-finite pixel values are
// errors too (they would make the measures NaN).
Status ComputePsnr(const Image& ours, const Image& reference, const Image& mask,
                   const ImageMetricsOptions& options, double* psnr);
Status ComputeSsim(const Image& ours, const Image& reference, const Image& mask,
                   const ImageMetricsOptions& options, double* ssim);

// SSIM as above with the map computed by cv::GaussianBlur (the fallback when the quality module is
// missing; also the cross-check of the quality module in tests).
Status SsimGaussian(const Image& ours, const Image& reference, const Image& mask,
                    const ImageMetricsOptions& options, double* ssim);

// True when ComputeSsim uses cv::quality::QualitySSIM.
bool HaveQualitySsim();

}  // namespace sft

#endif  // SFT_EVAL_IMAGE_METRICS_H_
