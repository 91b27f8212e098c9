#include "src/capture/pixel_masks.h"

#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace sft {
namespace {

// Values of `image` scaled so that full scale is 1 (32F as stored), as CV_32F with the same
// channels.
cv::Mat UnitScale(const cv::Mat& image) {
  const double full = image.depth() == CV_8U ? 255.0 : image.depth() == CV_16U ? 65535.0 : 1.0;
  cv::Mat values;
  image.convertTo(values, CV_32F, 1.0 / full);
  return values;
}

cv::Mat Disc(int radius) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
}

}  // namespace

bool ThresholdMaskOptions::Check(std::string* why) const {
  char buffer[96];
  if (!(threshold >= 0 && threshold < 1)) {
    std::snprintf(buffer, sizeof(buffer), "--threshold: must be in [0, 1), got %g", threshold);
    *why = buffer;
    return false;
  }
  if (dilate < 0 || dilate > 1000) {
    *why = "--dilate: must be in [0, 1000] pixels, got " + std::to_string(dilate);
    return false;
  }
  if (erode < 0 || erode > 1000) {
    *why = "--erode: must be in [0, 1000] pixels, got " + std::to_string(erode);
    return false;
  }
  return true;
}

cv::Mat ThresholdMask(const cv::Mat& image, const ThresholdMaskOptions& options) {
  const cv::Mat values = UnitScale(image);
  std::vector<cv::Mat> channels;
  cv::split(values, channels);
  const int colours = channels.size() >= 3 ? 3 : 1;  // BGR(A): alpha is not a colour.
  cv::Mat brightest = channels[0].clone();
  for (int c = 1; c < colours; ++c) cv::max(brightest, channels[c], brightest);
  cv::Mat mask = brightest > options.threshold;  // 8-bit 0/255.
  // Outside the image the morphology sees neutral values (OpenCV's default border), so a mask
  // touching the frame is neither grown nor cut there.
  if (options.dilate > 0) cv::dilate(mask, mask, Disc(options.dilate));
  if (options.erode > 0) cv::erode(mask, mask, Disc(options.erode));
  if (options.fill_holes) {
    cv::Mat background = mask == 0, labels;
    const int count = cv::connectedComponents(background, labels, 4, CV_32S);
    std::vector<bool> reaches_border(count, false);
    for (int y = 0; y < labels.rows; ++y) {
      for (int x = 0; x < labels.cols; ++x) {
        if (y == 0 || x == 0 || y == labels.rows - 1 || x == labels.cols - 1) {
          reaches_border[labels.at<int>(y, x)] = true;
        }
      }
    }
    for (int y = 0; y < labels.rows; ++y) {
      for (int x = 0; x < labels.cols; ++x) {
        const int label = labels.at<int>(y, x);
        if (label > 0 && !reaches_border[label]) mask.at<uint8_t>(y, x) = 255;
      }
    }
  }
  return mask;
}

Status AlphaMask(const cv::Mat& image, const std::string& name, cv::Mat* mask) {
  if (image.channels() != 4) {
    return Status::Error(name + ": --masks alpha: the image has no alpha channel (" +
                         std::to_string(image.channels()) + " channels)");
  }
  cv::Mat alpha;
  cv::extractChannel(UnitScale(image), alpha, 3);
  *mask = alpha > 0.5f;
  return Status::Ok();
}

}  // namespace sft
