// PSNR, SSIM and relative RMSE over a mask, on linear and display (sRGB) values
// (src/eval/image_metrics.h), on cases with known answers.
#include "src/eval/image_metrics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "src/core/rng.h"
#include "tests/testing/test_images.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

TEST(ImageMetricsTest, IdenticalImagesGiveCappedPsnrAndUnitSsim) {
  const Image a = testing::SmoothPattern(40, 30);
  ImageMetricsOptions options;
  double psnr = 0.0, ssim = 0.0;
  ASSERT_TRUE(ComputePsnr(a, a, Image(), options, &psnr).ok());
  EXPECT_EQ(psnr, options.max_psnr);
  ASSERT_TRUE(ComputeSsim(a, a, Image(), options, &ssim).ok());
  EXPECT_NEAR(ssim, 1.0, 1e-9);
  ASSERT_TRUE(SsimGaussian(a, a, Image(), options, &ssim).ok());
  EXPECT_NEAR(ssim, 1.0, 1e-9);
  options.max_psnr = 60.0;
  ASSERT_TRUE(ComputePsnr(a, a, Image(), options, &psnr).ok());
  EXPECT_EQ(psnr, 60.0);
}

// Differences of ±σ everywhere give MSE = σ² exactly: PSNR = 20·log10(peak/σ).
TEST(ImageMetricsTest, KnownNoiseLevelGivesKnownPsnr) {
  const Image a = testing::SmoothPattern(32, 32);
  Image b = a;
  const double sigma = 0.01;
  for (size_t i = 0; i < b.data.size(); ++i) {
    b.data[i] += static_cast<float>((Mix64(i) & 1) ? sigma : -sigma);
  }
  ImageMetricsOptions options;
  double psnr = 0.0;
  ASSERT_TRUE(ComputePsnr(b, a, Image(), options, &psnr).ok());
  EXPECT_NEAR(psnr, 40.0, 1e-3);  // float storage of the pixels: ~1e-6 relative in σ.
  options.peak = 10.0;
  ASSERT_TRUE(ComputePsnr(b, a, Image(), options, &psnr).ok());
  EXPECT_NEAR(psnr, 60.0, 1e-3);
}

// Only masked pixels count: noise outside the mask leaves PSNR at the cap and SSIM at 1 away
// from the mask's border; noise inside lowers both.
TEST(ImageMetricsTest, MaskSelectsPixels) {
  const int w = 48, h = 48;
  const Image a = testing::SmoothPattern(w, h);
  Image mask(w, h, 1, 0.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w / 2; ++x) mask.at(x, y) = 1.0f;
  }
  Image noisy_outside = a;
  for (int y = 0; y < h; ++y) {
    for (int x = w / 2; x < w; ++x) {
      for (int c = 0; c < 3; ++c) noisy_outside.at(x, y, c) += (x + y) % 2 ? 0.2f : -0.2f;
    }
  }
  ImageMetricsOptions options;
  double psnr = 0.0, ssim = 0.0;
  ASSERT_TRUE(ComputePsnr(noisy_outside, a, mask, options, &psnr).ok());
  EXPECT_EQ(psnr, options.max_psnr);
  ASSERT_TRUE(ComputePsnr(noisy_outside, a, Image(), options, &psnr).ok());
  EXPECT_NEAR(psnr, 20.0 * std::log10(1.0 / 0.2) + 10.0 * std::log10(2.0), 1e-3);  // half noisy.
  // SSIM windows reach 5 pixels across the border; in a mask 6+ pixels away from it, SSIM is 1.
  Image inner(w, h, 1, 0.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w / 2 - 6; ++x) inner.at(x, y) = 1.0f;
  }
  ASSERT_TRUE(ComputeSsim(noisy_outside, a, inner, options, &ssim).ok());
  EXPECT_NEAR(ssim, 1.0, 1e-9);
  ASSERT_TRUE(ComputeSsim(noisy_outside, a, mask, options, &ssim).ok());
  EXPECT_LT(ssim, 1.0);
}

// Constant images have zero variance in every window, so SSIM = (2μaμb + C1)/(μa² + μb² + C1).
TEST(ImageMetricsTest, SsimOfConstantImagesIsTheLuminanceTerm) {
  const Image a(20, 20, 3, 0.5f), b(20, 20, 3, 0.4f);
  ImageMetricsOptions options;
  const double c1 = 1e-4;
  const double expected = (2 * 0.5 * 0.4 + c1) / (0.25 + 0.16 + c1);
  double ssim = 0.0;
  ASSERT_TRUE(ComputeSsim(b, a, Image(), options, &ssim).ok());
  EXPECT_NEAR(ssim, expected, 1e-6);
  ASSERT_TRUE(SsimGaussian(b, a, Image(), options, &ssim).ok());
  EXPECT_NEAR(ssim, expected, 1e-6);
  // Same images in other units (peak 100): same SSIM.
  Image a100 = a, b100 = b;
  for (float& v : a100.data) v *= 100.0f;
  for (float& v : b100.data) v *= 100.0f;
  options.peak = 100.0;
  ASSERT_TRUE(ComputeSsim(b100, a100, Image(), options, &ssim).ok());
  EXPECT_NEAR(ssim, expected, 1e-6);
}

TEST(ImageMetricsTest, ShiftedImageHasLowerSsim) {
  const Image a = testing::SmoothPattern(64, 48), shifted = testing::SmoothPattern(64, 48, 3);
  ImageMetricsOptions options;
  double ssim = 0.0, fallback = 0.0;
  ASSERT_TRUE(ComputeSsim(shifted, a, Image(), options, &ssim).ok());
  EXPECT_LT(ssim, 0.9);
  EXPECT_GT(ssim, -1.0);
  // The quality module (when built with it) and the GaussianBlur fallback compute the same map.
  ASSERT_TRUE(SsimGaussian(shifted, a, Image(), options, &fallback).ok());
  EXPECT_NEAR(ssim, fallback, 1e-6);
  // A 1-pixel shift is more similar than a 3-pixel shift.
  double closer = 0.0;
  ASSERT_TRUE(ComputeSsim(testing::SmoothPattern(64, 48, 1), a, Image(), options, &closer).ok());
  EXPECT_GT(closer, ssim);
  EXPECT_LT(closer, 1.0);
}

// HDR pixels: a reference of 4 and a re-render of 3 differ by 1 in linear values (peak-1 PSNR
// 0 dB, relative RMSE 1/4) but both show as white: the display PSNR is the cap, SSIM 1.
TEST(ImageMetricsTest, HdrValuesClipOnTheDisplay) {
  const Image reference(16, 12, 3, 4.0f), ours(16, 12, 3, 3.0f);
  ImageScores s;
  ASSERT_TRUE(ComputeImageScores(ours, reference, Image(), ImageMetricsOptions(), &s).ok());
  EXPECT_NEAR(s.psnr_linear, 0.0, 1e-12);
  EXPECT_NEAR(s.relative_rmse, 0.25, 1e-12);
  EXPECT_EQ(s.psnr_srgb, ImageMetricsOptions().max_psnr);
  EXPECT_NEAR(s.ssim_srgb, 1.0, 1e-9);
}

// Constant images with a known sRGB code value: linear 0.5 shows as 1.055·0.5^(1/2.4) − 0.055 =
// 0.7353570, 0.25 as 0.5370987; PSNR = −20·log10(0.1982582) = 14.05537 dB. The linear PSNR is
// −20·log10(0.25) = 12.04120 dB, the relative RMSE 0.25 / 0.5 = 0.5 (0.5 is the reference here).
// Below 0.0031308 the encoding is linear: 0.002 shows as 0.02584 (31.75415 dB against black).
TEST(ImageMetricsTest, DisplayPsnrOfConstantImagesIsKnown) {
  const Image reference(10, 10, 3, 0.5f), ours(10, 10, 3, 0.25f);
  ImageScores s;
  ASSERT_TRUE(ComputeImageScores(ours, reference, Image(), ImageMetricsOptions(), &s).ok());
  EXPECT_NEAR(s.psnr_srgb, 14.055374519, 1e-4);
  EXPECT_NEAR(s.psnr_linear, 12.041199827, 1e-6);
  EXPECT_NEAR(s.relative_rmse, 0.5, 1e-7);
  const Image display = DisplayImage(reference);
  EXPECT_NEAR(display.at(3, 4, 1), 0.735356983, 1e-6);
  const Image dark(10, 10, 3, 0.002f), black(10, 10, 3, 0.0f);
  ASSERT_TRUE(ComputeImageScores(dark, black, Image(), ImageMetricsOptions(), &s).ok());
  EXPECT_NEAR(s.psnr_srgb, 31.754149814, 1e-4);
  EXPECT_TRUE(std::isnan(s.relative_rmse));  // a black reference: undefined.
  // Alpha is not encoded; negative values show as black.
  Image rgba(2, 1, 4, -1.0f);
  rgba.at(0, 0, 3) = 0.5f;
  const Image shown = DisplayImage(rgba);
  EXPECT_EQ(shown.at(0, 0, 0), 0.0f);
  EXPECT_EQ(shown.at(0, 0, 3), 0.5f);
}

TEST(ImageMetricsTest, BadInputsAreErrors) {
  const Image a = testing::SmoothPattern(16, 16);
  ImageMetricsOptions options;
  double value = 0.0;
  EXPECT_THAT(ComputePsnr(a, testing::SmoothPattern(16, 15), Image(), options, &value).message(),
              HasSubstr("sizes differ"));
  EXPECT_THAT(ComputeSsim(a, Image(16, 16, 4), Image(), options, &value).message(),
              HasSubstr("sizes differ"));
  EXPECT_THAT(ComputePsnr(a, a, Image(16, 16, 1, 0.0f), options, &value).message(),
              HasSubstr("no pixel"));
  EXPECT_THAT(ComputeSsim(a, a, Image(8, 8, 1, 1.0f), options, &value).message(),
              HasSubstr("mask"));
  EXPECT_FALSE(ComputePsnr(Image(), Image(), Image(), options, &value).ok());
  Image nan_image = a;
  nan_image.at(3, 4, 1) = std::nanf("");
  EXPECT_THAT(ComputePsnr(nan_image, a, Image(), options, &value).message(),
              HasSubstr("non-finite"));
  EXPECT_THAT(ComputeRelativeRmse(a, testing::SmoothPattern(16, 15), Image(), &value).message(),
              HasSubstr("sizes differ"));
  ImageScores scores;
  EXPECT_THAT(ComputeImageScores(nan_image, a, Image(), options, &scores).message(),
              HasSubstr("non-finite"));
  options.peak = 0.0;
  EXPECT_THAT(ComputePsnr(a, a, Image(), options, &value).message(), HasSubstr("peak"));
}

}  // namespace
}  // namespace sft
