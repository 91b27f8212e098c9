#include "src/init/stereo_points.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace sft {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Disparities searched beyond the object box's depth range on each side (pixels).
constexpr int kDisparityMargin = 4;
// StereoSGBM's largest search range here: bounds its cost volume (width × height × range shorts).
constexpr int kMaxDisparities = 1024;

// A view ready for matching: 8-bit grey, its mask, and OpenCV's calibration.
struct MatchView {
  Camera camera;  // at the matching scale.
  Rigid3d cam_from_world;
  cv::Mat grey;                                      // CV_8UC1.
  cv::Mat mask;                                      // CV_8UC1, 255 = object; empty = everything.
  cv::Mat K;                                         // 3×3, OpenCV pixel centres.
  cv::Mat dist;                                      // k1, k2, p1, p2.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // camera centre, world frame.
};

uint8_t EncodeSrgb(float linear) {
  const double v = std::clamp(static_cast<double>(linear), 0.0, 1.0);
  const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<uint8_t>(std::lround(255.0 * s));
}

Status PrepareView(const StereoView& view, int scale_log2, MatchView* out) {
  std::string why;
  if (!view.camera.Check(&why)) return Status::Error(view.name + ": camera: " + why);
  const Image& image = view.image;
  if (image.width != view.camera.width || image.height != view.camera.height ||
      image.channels < 1) {
    return Status::Error(view.name + ": the image is " + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + ", the camera " +
                         std::to_string(view.camera.width) + "x" +
                         std::to_string(view.camera.height));
  }
  if (!view.mask.empty() && (view.mask.width != image.width || view.mask.height != image.height)) {
    return Status::Error(view.name + ": the mask does not have the image's size");
  }
  cv::Mat grey(image.height, image.width, CV_8UC1);
  cv::Mat mask;
  if (!view.mask.empty()) mask.create(image.height, image.width, CV_8UC1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      float value = image.at(x, y, 0);
      if (image.channels >= 3) {
        value =
            0.2126f * image.at(x, y, 0) + 0.7152f * image.at(x, y, 1) + 0.0722f * image.at(x, y, 2);
      }
      grey.at<uint8_t>(y, x) = EncodeSrgb(value);
      if (!mask.empty()) mask.at<uint8_t>(y, x) = view.mask.at(x, y) > 0.5f ? 255 : 0;
    }
  }
  out->camera = DownscaledCamera(view.camera, scale_log2);
  if (scale_log2 > 0) {
    const cv::Size size(out->camera.width, out->camera.height);
    cv::resize(grey, grey, size, 0, 0, cv::INTER_AREA);
    if (!mask.empty()) cv::resize(mask, mask, size, 0, 0, cv::INTER_NEAREST);
  }
  out->grey = grey;
  out->mask = mask;
  out->cam_from_world = view.cam_from_world;
  out->centre = view.cam_from_world.Inverse().translation;
  const Eigen::Vector2d f = out->camera.Focal(), c = out->camera.Principal();
  out->K = (cv::Mat_<double>(3, 3) << f.x(), 0, c.x() - 0.5, 0, f.y(), c.y() - 0.5, 0, 0, 1);
  const std::vector<double>& p = out->camera.params;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;
  switch (out->camera.model) {
    case CameraModel::kSimplePinhole:
    case CameraModel::kPinhole:
      break;
    case CameraModel::kSimpleRadial:
      k1 = p[3];
      break;
    case CameraModel::kRadial:
      k1 = p[3];
      k2 = p[4];
      break;
    case CameraModel::kOpenCV:
      k1 = p[4];
      k2 = p[5];
      p1 = p[6];
      p2 = p[7];
      break;
  }
  out->dist = (cv::Mat_<double>(1, 4) << k1, k2, p1, p2);
  return Status::Ok();
}

cv::Mat ToCv(const Eigen::Matrix3d& m) {
  cv::Mat out(3, 3, CV_64F);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out.at<double>(i, j) = m(i, j);
  }
  return out;
}

// A rectified pair, turned and flipped so that StereoSGBM can match it: rows are epipolar lines
// and b's match of a pixel of a lies to its left (disparity d = u_a − u_b in the matched images).
struct RectifiedPair {
  cv::Mat grey_a, grey_b;  // CV_8UC1, the matched images (before padding).
  cv::Mat r1, p1;          // a's rectifying rotation and projection (OpenCV's).
  Eigen::Matrix3d r1e;     // r1 as Eigen.
  int axis = 0;            // the baseline's axis in the rectified images (0: rows, 1: columns).
  double s = 0;            // f · (the baseline along the axis), P2's translation entry.
  double ca = 0, cb = 0;   // the principal points along the axis (P1, P2).
  bool mirror = false;     // flipped horizontally (s > 0).

  // Disparity of depth z (rectified a frame) and back.
  double Disparity(double z) const { return mirror ? s / z - (ca - cb) : -s / z + (ca - cb); }
  double Depth(double d) const { return mirror ? s / (d + ca - cb) : -s / (d - (ca - cb)); }
};

RectifiedPair Rectify(const MatchView& a, const MatchView& b) {
  const Eigen::Matrix3d ra = a.cam_from_world.rotation.toRotationMatrix();
  const Eigen::Matrix3d rb = b.cam_from_world.rotation.toRotationMatrix();
  const Eigen::Matrix3d r_ba = rb * ra.transpose();
  const Eigen::Vector3d t_ba = b.cam_from_world.translation - r_ba * a.cam_from_world.translation;
  const cv::Size size(a.camera.width, a.camera.height);
  RectifiedPair pair;
  cv::Mat r2, p2, q;
  cv::Mat t_cv = (cv::Mat_<double>(3, 1) << t_ba.x(), t_ba.y(), t_ba.z());
  // alpha 1: every source pixel stays in the rectified canvas, so the object is not cut off.
  cv::stereoRectify(a.K, a.dist, b.K, b.dist, size, ToCv(r_ba), t_cv, pair.r1, r2, pair.p1, p2, q,
                    0, 1.0, size);
  cv::Mat ma_x, ma_y, mb_x, mb_y;
  cv::initUndistortRectifyMap(a.K, a.dist, pair.r1, pair.p1, size, CV_32FC1, ma_x, ma_y);
  cv::initUndistortRectifyMap(b.K, b.dist, r2, p2, size, CV_32FC1, mb_x, mb_y);
  cv::remap(a.grey, pair.grey_a, ma_x, ma_y, cv::INTER_LINEAR);
  cv::remap(b.grey, pair.grey_b, mb_x, mb_y, cv::INTER_LINEAR);
  pair.axis = std::abs(p2.at<double>(0, 3)) >= std::abs(p2.at<double>(1, 3)) ? 0 : 1;
  pair.s = p2.at<double>(pair.axis, 3);
  pair.ca = pair.p1.at<double>(pair.axis, 2);
  pair.cb = p2.at<double>(pair.axis, 2);
  pair.mirror = pair.s > 0;
  if (pair.axis == 1) {
    pair.grey_a = pair.grey_a.t();
    pair.grey_b = pair.grey_b.t();
  }
  if (pair.mirror) {
    cv::flip(pair.grey_a, pair.grey_a, 1);
    cv::flip(pair.grey_b, pair.grey_b, 1);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) pair.r1e(i, j) = pair.r1.at<double>(i, j);
  }
  return pair;
}

// Semi-global matching's disparities of the pair (CV_16S, 1/16 pixel), searched over the depths of
// `box` seen from a. The images are padded: column c of pair.grey_a is column c + *pad_left of
// the result; values below *min_disparity · 16 are StereoSGBM's "invalid".
cv::Mat MatchDisparities(const MatchView& a, const RectifiedPair& pair,
                         const Eigen::AlignedBox3d& box, const StereoOptions& options,
                         int* min_disparity, int* pad_left) {
  double d_lo = 1e300, d_hi = -1e300;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d x = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    const double z = (pair.r1e * (a.cam_from_world * x)).z();
    const double d = pair.Disparity(std::max(z, 1e-6 * box.diagonal().norm()));
    d_lo = std::min(d_lo, d);
    d_hi = std::max(d_hi, d);
  }
  *min_disparity = static_cast<int>(std::floor(d_lo)) - kDisparityMargin;
  int disparities = static_cast<int>(std::ceil(d_hi - *min_disparity)) + kDisparityMargin;
  disparities = std::clamp((disparities + 15) / 16 * 16, 16, kMaxDisparities);
  // Pads so that no column of the object lies in the unsearched left border or matches past the
  // right edge.
  *pad_left = std::max(0, *min_disparity + disparities);
  const int pad_right = std::max(0, -*min_disparity);
  cv::Mat grey_a, grey_b;
  cv::copyMakeBorder(pair.grey_a, grey_a, 0, 0, *pad_left, pad_right, cv::BORDER_CONSTANT, 0);
  cv::copyMakeBorder(pair.grey_b, grey_b, 0, 0, *pad_left, pad_right, cv::BORDER_CONSTANT, 0);
  const int block = options.block_size;
  auto sgbm = cv::StereoSGBM::create(
      *min_disparity, disparities, block, 8 * block * block, 32 * block * block,
      /*disp12MaxDiff=*/1, /*preFilterCap=*/0, /*uniquenessRatio=*/10,
      /*speckleWindowSize=*/100, /*speckleRange=*/2, cv::StereoSGBM::MODE_SGBM_3WAY);
  cv::Mat disp;
  sgbm->compute(grey_a, grey_b, disp);
  return disp;
}

// Matches (a, b) and writes the depths (a's z) of a's mask pixels: depth[y·w + x], 0 = none.
// Every pixel looks its disparity up in the rectified grid (an inverse map, so that no pixel is
// left between the forward images of rectified pixels). Returns the pixels that got a depth.
int64_t MatchPair(const MatchView& a, const MatchView& b, const Eigen::AlignedBox3d& box,
                  const StereoOptions& options, std::vector<float>* depth) {
  const RectifiedPair pair = Rectify(a, b);
  int min_disparity = 0, pad_left = 0;
  const cv::Mat disp = MatchDisparities(a, pair, box, options, &min_disparity, &pad_left);
  const int rows = pair.grey_a.rows, cols = pair.grey_a.cols;
  const int w = a.camera.width, h = a.camera.height;
  std::vector<cv::Point2f> pixels, rectified;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (a.mask.empty() || a.mask.at<uint8_t>(y, x) != 0) pixels.emplace_back(x, y);
    }
  }
  if (pixels.empty()) return 0;
  cv::undistortPoints(pixels, rectified, a.K, a.dist, pair.r1, pair.p1);
  const auto disparity_at = [&](int r, int c, double* d) {
    if (r < 0 || c < 0 || r >= rows || c >= cols) return false;
    const int16_t raw = disp.at<int16_t>(r, c + pad_left);
    if (raw < min_disparity * 16) return false;  // StereoSGBM marks invalid below the range.
    *d = raw / 16.0;
    return true;
  };
  const double f = pair.p1.at<double>(0, 0);
  int64_t matched = 0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const double u = rectified[i].x, v = rectified[i].y;
    const double along = pair.axis == 0 ? u : v, across = pair.axis == 0 ? v : u;
    const double c = pair.mirror ? cols - 1 - along : along;
    // Bilinear between the four neighbours when all are valid and within a pixel of one another
    // (a smooth surface), else the nearest one.
    const int c0 = static_cast<int>(std::floor(c)), r0 = static_cast<int>(std::floor(across));
    double d00, d01, d10, d11, d;
    if (disparity_at(r0, c0, &d00) && disparity_at(r0, c0 + 1, &d01) &&
        disparity_at(r0 + 1, c0, &d10) && disparity_at(r0 + 1, c0 + 1, &d11) &&
        std::max({d00, d01, d10, d11}) - std::min({d00, d01, d10, d11}) <= 1.0) {
      const double fc = c - c0, fr = across - r0;
      d = (1 - fr) * ((1 - fc) * d00 + fc * d01) + fr * ((1 - fc) * d10 + fc * d11);
    } else if (!disparity_at(static_cast<int>(std::lround(across)),
                             static_cast<int>(std::lround(c)), &d)) {
      continue;
    }
    const double z = pair.Depth(d);
    if (!(z > 0) || !std::isfinite(z)) continue;
    const Eigen::Vector3d in_rect((u - pair.p1.at<double>(0, 2)) * z / f,
                                  (v - pair.p1.at<double>(1, 2)) * z / f, z);
    const double depth_a = (pair.r1e.transpose() * in_rect).z();
    if (!(depth_a > 0)) continue;
    ++matched;
    (*depth)[static_cast<size_t>(pixels[i].y) * w + static_cast<int>(pixels[i].x)] =
        static_cast<float>(depth_a);
  }
  return matched;
}

// The depths of a's pixels that at least min_agreeing pairs confirm (0 elsewhere).
// `shortest_baseline`: the distance between a's centre and its nearest partner's (scene units).
std::vector<float> AgreedDepths(const MatchView& a, const std::vector<std::vector<float>>& pairs,
                                double shortest_baseline, const StereoOptions& options) {
  // Depth per pixel of disparity at depth z: z² / (f · baseline).
  const double per_z2 = options.consistency_pixels / (a.camera.Focal().mean() * shortest_baseline);
  const int w = a.camera.width, h = a.camera.height;
  std::vector<float> out(static_cast<size_t>(w) * h, 0.0f);
  std::vector<float> values;
  for (size_t i = 0; i < out.size(); ++i) {
    if (!a.mask.empty() && a.mask.data[i] == 0) continue;
    values.clear();
    for (const std::vector<float>& depth : pairs) {
      if (depth[i] > 0) values.push_back(depth[i]);
    }
    if (static_cast<int>(values.size()) < options.min_agreeing_pairs) continue;
    std::sort(values.begin(), values.end());
    const float median = values[values.size() / 2];
    double sum = 0;
    int agreeing = 0;
    for (float z : values) {
      if (std::abs(z - median) <= per_z2 * median * median) {
        sum += z;
        ++agreeing;
      }
    }
    if (agreeing >= options.min_agreeing_pairs) out[i] = static_cast<float>(sum / agreeing);
  }
  return out;
}

// Oriented world points from a's depth map; normals from central differences, towards the camera.
void DepthToPoints(const MatchView& a, const std::vector<float>& depth,
                   std::vector<OrientedPoint>* points) {
  const int w = a.camera.width, h = a.camera.height;
  std::vector<Eigen::Vector3d> in_cam(depth.size(), Eigen::Vector3d::Zero());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      if (depth[i] <= 0) continue;
      const Eigen::Vector3d ray = a.camera.CamFromImage(Eigen::Vector2d(x + 0.5, y + 0.5));
      if (ray.z() > 0) in_cam[i] = ray / ray.z() * depth[i];
    }
  }
  const Rigid3d world_from_cam = a.cam_from_world.Inverse();
  const auto valid = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h && in_cam[static_cast<size_t>(y) * w + x].z() > 0;
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!valid(x, y) || !valid(x - 1, y) || !valid(x + 1, y) || !valid(x, y - 1) ||
          !valid(x, y + 1)) {
        continue;
      }
      const auto at = [&](int px, int py) { return in_cam[static_cast<size_t>(py) * w + px]; };
      const Eigen::Vector3d p = at(x, y);
      Eigen::Vector3d n = (at(x + 1, y) - at(x - 1, y)).cross(at(x, y + 1) - at(x, y - 1));
      if (!(n.norm() > 0)) continue;
      n.normalize();
      if (n.dot(p) > 0) n = -n;  // the camera sits at the origin: the normal faces it.
      OrientedPoint point;
      point.position = world_from_cam * p;
      point.normal = world_from_cam.rotation * n;
      points->push_back(point);
    }
  }
}

// The partners of view a: views within the angle range seen from `centre`, closest first.
std::vector<int> Partners(const std::vector<MatchView>& views, int a, const Eigen::Vector3d& centre,
                          const StereoOptions& options) {
  const Eigen::Vector3d da = (views[a].centre - centre).normalized();
  std::vector<std::pair<double, int>> candidates;
  for (int b = 0; b < static_cast<int>(views.size()); ++b) {
    if (b == a) continue;
    const Eigen::Vector3d db = (views[b].centre - centre).normalized();
    const double angle = std::acos(std::clamp(da.dot(db), -1.0, 1.0)) * 180.0 / kPi;
    if (angle >= options.min_angle_deg && angle <= options.max_angle_deg) {
      candidates.emplace_back(angle, b);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<int> out;
  for (const auto& [angle, b] : candidates) {
    if (static_cast<int>(out.size()) == options.pairs_per_view) break;
    out.push_back(b);
  }
  return out;
}

Status Compute(const std::vector<StereoView>& views, const Eigen::AlignedBox3d& box,
               const StereoOptions& options, std::vector<OrientedPoint>* points,
               StereoReport* report) {
  const auto start = std::chrono::steady_clock::now();
  if (views.size() < 3) {
    return Status::Error("stereo needs at least 3 views, got " + std::to_string(views.size()));
  }
  if (box.isEmpty() || !(box.diagonal().norm() > 0))
    return Status::Error("the object box is empty");
  std::vector<MatchView> prepared(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    SFT_RETURN_IF_ERROR(PrepareView(views[v], options.image_scale_log2, &prepared[v]));
  }
  report->views = static_cast<int>(views.size());
  std::vector<std::vector<OrientedPoint>> per_view(views.size());
  std::atomic<int> pairs{0}, lonely{0};
  std::atomic<int64_t> matched{0};
  tbb::parallel_for(0, static_cast<int>(views.size()), [&](int a) {
    const std::vector<int> partners = Partners(prepared, a, box.center(), options);
    if (static_cast<int>(partners.size()) < options.min_agreeing_pairs) {
      ++lonely;
      return;
    }
    const MatchView& view = prepared[a];
    std::vector<std::vector<float>> depths;
    double shortest_baseline = std::numeric_limits<double>::infinity();
    for (int b : partners) {
      shortest_baseline = std::min(shortest_baseline, (prepared[b].centre - view.centre).norm());
      depths.emplace_back(static_cast<size_t>(view.camera.width) * view.camera.height, 0.0f);
      matched += MatchPair(view, prepared[b], box, options, &depths.back());
      ++pairs;
    }
    std::vector<float> agreed = AgreedDepths(view, depths, shortest_baseline, options);
    DepthToPoints(view, agreed, &per_view[a]);
  });
  for (const std::vector<OrientedPoint>& v : per_view) {
    points->insert(points->end(), v.begin(), v.end());
  }
  report->pairs = pairs;
  report->views_without_pair = lonely;
  report->matched_pixels = matched;
  report->points = static_cast<int64_t>(points->size());
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace

bool StereoOptions::Check(std::string* why) const {
  if (pairs_per_view < 2 || pairs_per_view > 8) {
    *why = "pairs_per_view: must be in [2, 8], got " + std::to_string(pairs_per_view);
    return false;
  }
  if (!(min_angle_deg > 0 && min_angle_deg <= 90 && max_angle_deg >= min_angle_deg &&
        max_angle_deg <= 90)) {
    *why = "min_angle_deg, max_angle_deg: must satisfy 0 < min <= max <= 90, got " +
           std::to_string(min_angle_deg) + ", " + std::to_string(max_angle_deg);
    return false;
  }
  if (block_size < 3 || block_size > 11 || block_size % 2 == 0) {
    *why = "block_size: must be odd and in [3, 11], got " + std::to_string(block_size);
    return false;
  }
  if (!(consistency_pixels > 0 && consistency_pixels <= 16)) {
    *why = "consistency_pixels: must be in (0, 16], got " + std::to_string(consistency_pixels);
    return false;
  }
  if (min_agreeing_pairs < 2 || min_agreeing_pairs > pairs_per_view) {
    *why = "min_agreeing_pairs: must be in [2, pairs_per_view = " + std::to_string(pairs_per_view) +
           "], got " + std::to_string(min_agreeing_pairs);
    return false;
  }
  if (image_scale_log2 < 0 || image_scale_log2 > 4) {
    *why = "image_scale_log2: must be in [0, 4], got " + std::to_string(image_scale_log2);
    return false;
  }
  return true;
}

Status ComputeStereoPoints(const std::vector<StereoView>& views,
                           const Eigen::AlignedBox3d& object_box, const StereoOptions& options,
                           std::vector<OrientedPoint>* points, StereoReport* report) {
  *report = StereoReport();
  points->clear();
  std::string why;
  if (!options.Check(&why)) return Status::Error("stereo options: " + why);
  try {
    return Compute(views, object_box, options, points, report).Prefixed("stereo");
  } catch (const std::exception& e) {
    return Status::Error(std::string("stereo failed: ") + e.what());
  }
}

}  // namespace sft
