// Image quality of re-renders against reference images over a mask (`sft eval`: PSNR, SSIM and
// relative RMSE of full, albedo and roughness re-renders, docs/cli.md).
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
//
// Linear and display values. Renders and photographs are linear radiance, and on HDR data (an
// environment-lit object) pixels exceed 1, so a peak-1 PSNR on linear values says little about
// what a viewer sees. The display image (DisplayImage) clips the colour channels to [0, 1] and
// sRGB-encodes them (IEC 61966-2-1), as an 8-bit PNG or a screen shows them; PSNR and SSIM of
// display images (peak 1) are the numbers comparable with published image metrics. The relative
// RMSE is scale-free and keeps the HDR values.
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

// The image as a viewer sees it: the colour channels (the first min(channels, 3)) clipped to
// [0, 1] and sRGB-encoded; further channels (alpha) are copied unchanged.
Image DisplayImage(const Image& image);

// sqrt(Σ (ours − reference)² / Σ reference²) over the masked pixels and compared channels, on the
// values as given (linear, HDR kept): the error as a fraction of the reference's RMS. NaN when
// the reference is 0 on every masked pixel. Errors as ComputePsnr.
Status ComputeRelativeRmse(const Image& ours, const Image& reference, const Image& mask,
                           double* relative_rmse);

// Every measure of one comparison (`sft eval`'s keys in brackets).
struct ImageScores {
  double psnr_srgb = 0.0;      // [psnr_srgb] PSNR of the display images, peak 1, dB.
  double ssim_srgb = 0.0;      // [ssim_srgb] SSIM of the display images, L = 1.
  double psnr_linear = 0.0;    // [psnr_linear] PSNR of the linear values, peak `options.peak`.
  double ssim_linear = 0.0;    // [ssim_linear] SSIM of the linear values, L = `options.peak`.
  double relative_rmse = 0.0;  // [rel_rmse] ComputeRelativeRmse of the linear values; may be NaN.
};
// `options` applies to the linear measures; the display measures use peak 1 and its max_psnr.
Status ComputeImageScores(const Image& ours, const Image& reference, const Image& mask,
                          const ImageMetricsOptions& options, ImageScores* scores);

}  // namespace sft

#endif  // SFT_EVAL_IMAGE_METRICS_H_
