#include "src/capture/auto_masks.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/image/image_io.h"

namespace sft {
namespace {

namespace fs = std::filesystem;

bool Fail(std::string* why, const std::string& text) {
  *why = text;
  return false;
}

// Linear RGB to 8-bit BGR: scaled so the 99th luminance percentile is white, then the sRGB curve.
cv::Mat ToneMap8(const Image& rgb) {
  std::vector<float> lum;
  lum.reserve(static_cast<size_t>(rgb.width) * rgb.height);
  for (int y = 0; y < rgb.height; ++y) {
    for (int x = 0; x < rgb.width; ++x) {
      lum.push_back(0.2126f * rgb.at(x, y, 0) + 0.7152f * rgb.at(x, y, 1) +
                    0.0722f * rgb.at(x, y, 2));
    }
  }
  std::nth_element(lum.begin(), lum.begin() + lum.size() * 99 / 100, lum.end());
  const float white = std::max(lum[lum.size() * 99 / 100], 1e-8f);
  cv::Mat out(rgb.height, rgb.width, CV_8UC3);
  for (int y = 0; y < rgb.height; ++y) {
    for (int x = 0; x < rgb.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = std::clamp(rgb.at(x, y, c) / white, 0.0f, 1.0f);
        const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
        out.at<cv::Vec3b>(y, x)[2 - c] = cv::saturate_cast<uint8_t>(255.0f * s);
      }
    }
  }
  return out;
}

// Background consistency on the labels (see the header): `distance` at its working resolution,
// looked up at each pixel's nearest working pixel; NaN (no comparison) changes nothing.
void ApplyBackgroundDistance(const Image& distance, const AutoMaskOptions& opts, cv::Mat* labels) {
  const int w = labels->cols, h = labels->rows;
  const double object = std::max(opts.object_distance, opts.background_distance);
  for (int y = 0; y < h; ++y) {
    const int dy = std::min(distance.height - 1, y * distance.height / h);
    for (int x = 0; x < w; ++x) {
      const float d = distance.at(std::min(distance.width - 1, x * distance.width / w), dy);
      uint8_t& label = labels->at<uint8_t>(y, x);
      if (d < opts.background_distance) {
        label = cv::GC_BGD;
      } else if (d > object && label == cv::GC_PR_BGD) {
        label = cv::GC_PR_FGD;
      }
    }
  }
}

// GrabCut labels from the seeds and, when given, the background distances (see the header).
cv::Mat SeedLabels(const std::vector<cv::Point>& seeds, cv::Size size, const AutoMaskOptions& opts,
                   const Image* background_distance) {
  cv::Mat labels(size, CV_8U, cv::Scalar(cv::GC_BGD));
  std::vector<cv::Point> hull;
  cv::convexHull(seeds, hull);
  const cv::Rect box = cv::boundingRect(hull);
  const int ring =
      static_cast<int>(std::lround(opts.ring_fraction * std::max(box.width, box.height)));
  cv::Mat hull_mask = cv::Mat::zeros(size, CV_8U);
  cv::fillConvexPoly(hull_mask, hull, cv::Scalar(255));
  cv::Mat grown;
  const int k = 2 * ring + 1;
  cv::dilate(hull_mask, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
  labels.setTo(cv::GC_PR_BGD, grown);
  labels.setTo(cv::GC_PR_FGD, hull_mask);
  const int b = opts.border_px;
  if (b > 0) {
    labels.rowRange(0, std::min(b, size.height)).setTo(cv::GC_BGD);
    labels.rowRange(std::max(0, size.height - b), size.height).setTo(cv::GC_BGD);
    labels.colRange(0, std::min(b, size.width)).setTo(cv::GC_BGD);
    labels.colRange(std::max(0, size.width - b), size.width).setTo(cv::GC_BGD);
  }
  if (background_distance != nullptr && !background_distance->empty()) {
    ApplyBackgroundDistance(*background_distance, opts, &labels);
  }
  for (const cv::Point& p : seeds) {
    cv::circle(labels, p, opts.seed_disc_px, cv::Scalar(cv::GC_FGD), cv::FILLED);
  }
  return labels;
}

// Foreground of the GrabCut labels: the component holding most seeds, holes filled.
cv::Mat KeepSeededComponent(const cv::Mat& labels, const std::vector<cv::Point>& seeds) {
  cv::Mat fg = (labels == cv::GC_FGD) | (labels == cv::GC_PR_FGD);
  cv::Mat components;
  const int n = cv::connectedComponents(fg, components, 8, CV_32S);
  std::vector<int> votes(n, 0);
  for (const cv::Point& p : seeds) ++votes[components.at<int>(p)];
  votes[0] = 0;
  const int keep = static_cast<int>(std::max_element(votes.begin(), votes.end()) - votes.begin());
  cv::Mat object = (components == keep) & fg;
  // Holes: background regions not connected to the image border.
  cv::Mat outside = object.clone();
  cv::copyMakeBorder(outside, outside, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::floodFill(outside, cv::Point(0, 0), cv::Scalar(255));
  cv::Mat filled = ~outside(cv::Rect(1, 1, object.cols, object.rows)) | object;
  return filled;
}

Status Segment(const Dataset& dataset, int index, const std::vector<Eigen::Vector3d>& sparse,
               const AutoMaskOptions& opts, const Image* background_distance, Image* mask) {
  const ViewSpec& view = dataset.views[index];
  const Camera& camera = dataset.cameras[view.camera];
  std::vector<cv::Point> seeds;
  for (const Eigen::Vector3d& p : sparse) {
    if (p.norm() > opts.seed_radius) continue;
    const Eigen::Vector3d p_in_cam = view.cam_from_world * p;
    if (p_in_cam.z() <= 1e-9) continue;
    const Eigen::Vector2d px = camera.ImageFromCam(p_in_cam);
    const int x = static_cast<int>(std::floor(px.x())), y = static_cast<int>(std::floor(px.y()));
    if (x >= 0 && y >= 0 && x < camera.width && y < camera.height) seeds.emplace_back(x, y);
  }
  if (static_cast<int>(seeds.size()) < opts.min_seeds) {
    return Status::Error(view.image + ": automatic mask: only " + std::to_string(seeds.size()) +
                         " sparse points of the object project into the view (need " +
                         std::to_string(opts.min_seeds) + ")");
  }
  Image rgb;
  SFT_RETURN_IF_ERROR(LoadViewImage(dataset, index, &rgb));
  const cv::Mat bgr = ToneMap8(rgb);
  cv::Mat labels = SeedLabels(seeds, bgr.size(), opts, background_distance);
  cv::Mat bgd_model, fgd_model;
  cv::grabCut(bgr, labels, cv::Rect(), bgd_model, fgd_model, opts.iterations,
              cv::GC_INIT_WITH_MASK);
  const cv::Mat object = KeepSeededComponent(labels, seeds);
  *mask = Image(rgb.width, rgb.height, 1);
  for (int y = 0; y < rgb.height; ++y) {
    for (int x = 0; x < rgb.width; ++x) mask->at(x, y) = object.at<uint8_t>(y, x) ? 1.0f : 0.0f;
  }
  return Status::Ok();
}

// "images/cam1/000.png" -> "masks/cam1/000.png".
std::string MaskPath(const std::string& image) {
  std::string rest = image;
  if (rest.rfind("images/", 0) == 0) rest = rest.substr(7);
  return (fs::path("masks") / fs::path(rest).replace_extension(".png")).generic_string();
}

}  // namespace

bool AutoMaskOptions::Check(std::string* why) const {
  if (!(seed_radius > 0 && seed_radius <= 10)) return Fail(why, "seed_radius: must be in (0, 10]");
  if (seed_disc_px < 0 || seed_disc_px > 50) return Fail(why, "seed_disc_px: must be in [0, 50]");
  if (!(ring_fraction >= 0 && ring_fraction <= 2)) {
    return Fail(why, "ring_fraction: must be in [0, 2]");
  }
  if (border_px < 0 || border_px > 1000) return Fail(why, "border_px: must be in [0, 1000]");
  if (iterations < 1 || iterations > 50) return Fail(why, "iterations: must be in [1, 50]");
  if (min_seeds < 3) return Fail(why, "min_seeds: must be >= 3");
  if (!(background_distance >= 0 && background_distance <= 1)) {
    return Fail(why, "background_distance: must be in [0, 1]");
  }
  if (!(object_distance >= 0 && object_distance <= 1)) {
    return Fail(why, "object_distance: must be in [0, 1]");
  }
  if (passes < 1 || passes > 4) return Fail(why, "passes: must be in [1, 4]");
  return consistency.Check(why);
}

Status AutoMask(const Dataset& dataset, int index, const std::vector<Eigen::Vector3d>& sparse,
                const AutoMaskOptions& options, const Image* background_distance, Image* mask) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("automatic masks: " + why);
  if (index < 0 || index >= static_cast<int>(dataset.views.size())) {
    return Status::Error("automatic masks: no view " + std::to_string(index));
  }
  try {
    return Segment(dataset, index, sparse, options, background_distance, mask);
  } catch (const std::exception& e) {
    return Status::Error(dataset.views[index].image + ": automatic mask: OpenCV: " + e.what());
  }
}

Status WriteAutoMasks(Dataset* dataset, const std::vector<Eigen::Vector3d>& sparse,
                      const SupportPlane* plane, const AutoMaskOptions& options) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("automatic masks: " + why);
  const size_t n = dataset->views.size();
  const bool consistent = options.background_distance > 0 && n >= 2;
  BackgroundConsistencyOptions consistency = options.consistency;
  consistency.quiet = consistency.quiet || options.quiet;
  std::vector<Image> masks(n), distances;
  std::unique_ptr<BackgroundViews> views;
  if (consistent) SFT_RETURN_IF_ERROR(BackgroundViews::Load(*dataset, consistency, &views));
  for (int pass = 0; pass < (consistent ? options.passes : 1); ++pass) {
    if (consistent) {
      SFT_RETURN_IF_ERROR(views->Distances(plane, pass == 0 ? nullptr : &masks, &distances));
    }
    Progress progress("auto masks", static_cast<int64_t>(n), !options.quiet);
    std::vector<Image> next(n);
    for (size_t i = 0; i < n; ++i) {
      SFT_RETURN_IF_ERROR(AutoMask(*dataset, static_cast<int>(i), sparse, options,
                                   distances.empty() ? nullptr : &distances[i], &next[i]));
      progress.Advance();
    }
    progress.Finish();
    masks.swap(next);
  }
  for (size_t i = 0; i < n; ++i) {
    const std::string path = MaskPath(dataset->views[i].image);
    SFT_RETURN_IF_ERROR(
        MakeDirectories(fs::path(JoinPath(dataset->root, path)).parent_path().string()));
    SFT_RETURN_IF_ERROR(WritePng(JoinPath(dataset->root, path), masks[i], false));
    dataset->views[i].mask = path;
  }
  return Status::Ok();
}

double MaskIoU(const Image& a, const Image& b) {
  int64_t inter = 0, uni = 0;
  const size_t n = std::min(a.data.size(), b.data.size());
  for (size_t i = 0; i < n; ++i) {
    const bool x = a.data[i] > 0.5f, y = b.data[i] > 0.5f;
    inter += x && y;
    uni += x || y;
  }
  return uni == 0 ? 1.0 : static_cast<double>(inter) / uni;
}

}  // namespace sft
