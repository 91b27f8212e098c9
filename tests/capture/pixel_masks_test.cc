// Threshold masks (threshold, dilate, erode, holes) and alpha masks.
#include "src/capture/pixel_masks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace sft {
namespace {

TEST(PixelMasksTest, ThresholdClosesGapsAndFillsHoles) {
  // A bright 40x40 square on black (BGR 8-bit) with a dark 4-pixel slit across it and a dark hole
  // in its middle; a dim pixel below the threshold outside it.
  cv::Mat image(100, 100, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::rectangle(image, cv::Rect(30, 30, 40, 40), cv::Scalar(0, 200, 60), cv::FILLED);
  cv::rectangle(image, cv::Rect(30, 48, 20, 4), cv::Scalar(10, 10, 10), cv::FILLED);
  cv::circle(image, cv::Point(58, 58), 5, cv::Scalar(0, 0, 0), cv::FILLED);
  image.at<cv::Vec3b>(5, 5) = cv::Vec3b(40, 40, 40);  // 0.157 < 0.19.
  ThresholdMaskOptions options;
  options.dilate = 3;
  options.erode = 2;
  const cv::Mat mask = ThresholdMask(image, options);
  EXPECT_EQ(mask.type(), CV_8U);
  EXPECT_EQ(mask.at<uint8_t>(50, 40), 255);  // the slit is closed.
  EXPECT_EQ(mask.at<uint8_t>(58, 58), 255);  // the hole is filled.
  EXPECT_EQ(mask.at<uint8_t>(5, 5), 0);
  EXPECT_EQ(mask.at<uint8_t>(60, 29), 255);  // one pixel of net growth (dilate 3 − erode 2).
  EXPECT_EQ(mask.at<uint8_t>(60, 27), 0);
  options.fill_holes = false;
  options.dilate = options.erode = 0;
  const cv::Mat raw = ThresholdMask(image, options);
  EXPECT_EQ(raw.at<uint8_t>(58, 58), 0);
  EXPECT_EQ(raw.at<uint8_t>(50, 40), 0);
  // 16-bit values are scaled to [0, 1] the same way.
  cv::Mat wide;
  image.convertTo(wide, CV_16U, 257.0);
  EXPECT_EQ(cv::countNonZero(ThresholdMask(wide, options) != raw), 0);
}

TEST(PixelMasksTest, ThresholdMaskTouchingTheFrameIsNotCutThere) {
  cv::Mat image(50, 50, CV_8UC1, cv::Scalar(0));
  cv::rectangle(image, cv::Rect(0, 10, 20, 20), cv::Scalar(255), cv::FILLED);
  const cv::Mat mask = ThresholdMask(image, ThresholdMaskOptions());
  EXPECT_EQ(mask.at<uint8_t>(20, 0), 255);
  EXPECT_EQ(mask.at<uint8_t>(10, 0), 255);
}

TEST(PixelMasksTest, AlphaMaskNeedsAnAlphaChannel) {
  cv::Mat rgba(4, 4, CV_8UC4, cv::Scalar(9, 9, 9, 0));
  rgba.at<cv::Vec4b>(1, 2)[3] = 200;
  cv::Mat mask;
  ASSERT_TRUE(AlphaMask(rgba, "a.png", &mask).ok());
  EXPECT_EQ(cv::countNonZero(mask), 1);
  EXPECT_EQ(mask.at<uint8_t>(1, 2), 255);
  const Status status = AlphaMask(cv::Mat(4, 4, CV_8UC3), "a.png", &mask);
  EXPECT_THAT(status.message(),
              ::testing::HasSubstr("a.png: --masks alpha: the image has no alpha"));
}

}  // namespace
}  // namespace sft
