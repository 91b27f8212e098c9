#include "src/capture/probe_alignment.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <exception>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "src/core/progress.h"
#include "src/render/environment.h"

namespace sft {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool Fail(std::string* why, const std::string& text) {
  *why = text;
  return false;
}

// SIFT features of one image with each keypoint's unit direction (env or world frame).
struct Features {
  std::vector<Eigen::Vector3d> directions;
  cv::Mat descriptors;  // CV_32F, one row per direction.
};

// Log luminance mapped to 8 bits between its 1st and 99th percentiles (over `valid` pixels when
// given). A global intensity scale becomes an offset, which the mapping removes.
cv::Mat LogLuminance8(const Image& rgb, const cv::Mat& valid) {
  cv::Mat lum(rgb.height, rgb.width, CV_32F);
  std::vector<float> samples;
  for (int y = 0; y < rgb.height; ++y) {
    for (int x = 0; x < rgb.width; ++x) {
      const float l =
          0.2126f * rgb.at(x, y, 0) + 0.7152f * rgb.at(x, y, 1) + 0.0722f * rgb.at(x, y, 2);
      lum.at<float>(y, x) = std::max(l, 0.0f);
      if (valid.empty() || valid.at<uint8_t>(y, x)) samples.push_back(std::max(l, 0.0f));
    }
  }
  if (samples.empty()) return cv::Mat::zeros(rgb.height, rgb.width, CV_8U);
  std::sort(samples.begin(), samples.end());
  const float median = samples[samples.size() / 2];
  const float eps = std::max(1e-2f * median, 1e-8f);
  const float lo = std::log(samples[samples.size() / 100] + eps);
  const float hi = std::log(samples[samples.size() * 99 / 100] + eps);
  const float gain = hi > lo ? 255.0f / (hi - lo) : 1.0f;
  cv::Mat out(rgb.height, rgb.width, CV_8U);
  for (int y = 0; y < rgb.height; ++y) {
    for (int x = 0; x < rgb.width; ++x) {
      const float v = (std::log(lum.at<float>(y, x) + eps) - lo) * gain;
      out.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(v);
    }
  }
  return out;
}

// Unit directions on a Fibonacci sphere.
std::vector<Eigen::Vector3d> FibonacciDirections(int n) {
  std::vector<Eigen::Vector3d> dirs;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    dirs.emplace_back(r * std::cos(golden * k), r * std::sin(golden * k), z);
  }
  return dirs;
}

// env_from_crop for a crop looking along `axis` (+z of the crop camera).
Eigen::Matrix3d CropRotation(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d helper =
      std::abs(axis.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = helper.cross(axis).normalized();
  const Eigen::Vector3d y = axis.cross(x);
  Eigen::Matrix3d r;
  r << x, y, axis;
  return r;
}

struct CropGeometry {
  int count = 0;
  int size = 0;      // pixels per side.
  double focal = 0;  // pixels.
};

CropGeometry ChooseCrops(const Dataset& dataset, int probe_width,
                         const ProbeAlignmentOptions& opts) {
  double fov = 0, pixel_angle = 0;
  for (const Camera& camera : dataset.cameras) {
    const double f = camera.Focal().x();
    const double cam_fov = 2.0 * std::atan(0.5 * camera.width / f);
    fov += cam_fov / dataset.cameras.size();
    pixel_angle += cam_fov / camera.width / dataset.cameras.size();
  }
  if (opts.crop_fov_deg > 0) fov = opts.crop_fov_deg * kDeg;
  fov = std::clamp(fov, 20.0 * kDeg, 120.0 * kDeg);
  pixel_angle = std::max(pixel_angle, 2.0 * M_PI / probe_width);
  CropGeometry g;
  g.size = std::clamp(static_cast<int>(std::lround(fov / pixel_angle)), 64, 1024);
  g.focal = 0.5 * g.size / std::tan(0.5 * fov);
  // Caps of 0.8 × the half field of view, doubled for overlap, cover the sphere.
  const double cap = 2.0 * M_PI * (1.0 - std::cos(0.4 * fov));
  g.count = opts.crops > 0 ? opts.crops : static_cast<int>(std::ceil(2.0 * 4.0 * M_PI / cap));
  return g;
}

// Renders the crops, detects SIFT in each, and keeps a keypoint only in the crop whose centre is
// nearest to its direction, so that overlapping crops do not duplicate features (which would fail
// the ratio test).
Features ProbeFeatures(const Image& probe, const CropGeometry& g, cv::Ptr<cv::SIFT> sift) {
  const EnvironmentMap env(probe, Eigen::Matrix3d::Identity(), 1.0);
  const std::vector<Eigen::Vector3d> axes = FibonacciDirections(g.count);
  Features out;
  for (const Eigen::Vector3d& axis : axes) {
    const Eigen::Matrix3d env_from_crop = CropRotation(axis);
    Image crop(g.size, g.size, 3);
    auto ray = [&](double px, double py) {
      const Eigen::Vector3d r((px - 0.5 * g.size) / g.focal, (py - 0.5 * g.size) / g.focal, 1.0);
      return (env_from_crop * r).normalized().eval();
    };
    for (int y = 0; y < g.size; ++y) {
      for (int x = 0; x < g.size; ++x) {
        const Eigen::Vector3d l = env.Radiance(ray(x + 0.5, y + 0.5));
        for (int c = 0; c < 3; ++c) crop.at(x, y, c) = static_cast<float>(l[c]);
      }
    }
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    sift->detectAndCompute(LogLuminance8(crop, cv::Mat()), cv::noArray(), keypoints, descriptors);
    for (size_t k = 0; k < keypoints.size(); ++k) {
      // OpenCV's pixel centres are integers; sft's are at +0.5.
      const Eigen::Vector3d dir = ray(keypoints[k].pt.x + 0.5, keypoints[k].pt.y + 0.5);
      double best = -2;
      const Eigen::Vector3d* owner = nullptr;
      for (const Eigen::Vector3d& a : axes) {
        if (a.dot(dir) > best) best = a.dot(dir), owner = &a;
      }
      if (owner != &axis) continue;
      out.directions.push_back(dir);
      out.descriptors.push_back(descriptors.row(static_cast<int>(k)));
    }
  }
  return out;
}

// Background features of view `index` with their world directions.
Status FrameFeatures(const Dataset& dataset, int index, const ProbeAlignmentOptions& opts,
                     cv::Ptr<cv::SIFT> sift, Features* out) {
  Image rgb;
  SFT_RETURN_IF_ERROR(LoadViewImage(dataset, index, &rgb));
  const ViewSpec& view = dataset.views[index];
  const Camera& camera = dataset.cameras[view.camera];
  cv::Mat background(rgb.height, rgb.width, CV_8U, cv::Scalar(255));
  if (!view.mask.empty()) {
    Image mask;
    SFT_RETURN_IF_ERROR(LoadViewMask(dataset, index, &mask));
    cv::Mat object(mask.height, mask.width, CV_8U);
    for (int y = 0; y < mask.height; ++y) {
      for (int x = 0; x < mask.width; ++x) object.at<uint8_t>(y, x) = mask.at(x, y) > 0.5f;
    }
    if (opts.mask_dilation_px > 0) {
      const int k = 2 * opts.mask_dilation_px + 1;
      cv::dilate(object, object, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
    }
    background.setTo(0, object);
  }
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  sift->detectAndCompute(LogLuminance8(rgb, background), background, keypoints, descriptors);
  const Eigen::Matrix3d world_from_cam =
      view.cam_from_world.rotation.conjugate().toRotationMatrix();
  for (size_t k = 0; k < keypoints.size(); ++k) {
    Eigen::Vector3d ray;
    const Eigen::Vector2d pixel(keypoints[k].pt.x + 0.5, keypoints[k].pt.y + 0.5);
    if (!camera.RayFromImage(pixel, &ray)) continue;
    out->directions.push_back((world_from_cam * ray).normalized());
    out->descriptors.push_back(descriptors.row(static_cast<int>(k)));
  }
  return Status::Ok();
}

// Rotation R minimising Σ |b_i − R a_i|² (Kabsch; Wahba's problem with unit weights).
Eigen::Matrix3d Kabsch(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                       const std::vector<int>& which) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (int i : which) h += a[i] * b[i].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixV() * d * svd.matrixU().transpose();
}

std::vector<int> Inliers(const Eigen::Matrix3d& r, const std::vector<Eigen::Vector3d>& env,
                         const std::vector<Eigen::Vector3d>& world, double cos_threshold) {
  std::vector<int> inliers;
  for (size_t i = 0; i < env.size(); ++i) {
    if ((r * env[i]).dot(world[i]) >= cos_threshold) inliers.push_back(static_cast<int>(i));
  }
  return inliers;
}

// RANSAC over 2-pair minimal sets, then Kabsch refinement on the inliers (three rounds).
Eigen::Matrix3d SolveRotation(const std::vector<Eigen::Vector3d>& env,
                              const std::vector<Eigen::Vector3d>& world,
                              const ProbeAlignmentOptions& opts, std::vector<int>* inliers) {
  const double cos_threshold = std::cos(opts.inlier_angle_deg * kDeg);
  const double cos_separation = std::cos(5.0 * kDeg);
  std::mt19937_64 rng(opts.seed);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(env.size()) - 1);
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  inliers->clear();
  for (int it = 0; it < opts.ransac_iterations; ++it) {
    const int i = pick(rng), j = pick(rng);
    if (i == j || std::abs(env[i].dot(env[j])) > cos_separation ||
        std::abs(world[i].dot(world[j])) > cos_separation) {
      continue;
    }
    const Eigen::Matrix3d r = Kabsch(env, world, {i, j});
    std::vector<int> in = Inliers(r, env, world, cos_threshold);
    if (in.size() > inliers->size()) best = r, *inliers = std::move(in);
  }
  for (int round = 0; round < 3 && inliers->size() >= 3; ++round) {
    const Eigen::Matrix3d r = Kabsch(env, world, *inliers);
    std::vector<int> in = Inliers(r, env, world, cos_threshold);
    if (in.size() < inliers->size()) break;
    best = r, *inliers = std::move(in);
  }
  return best;
}

Status Align(const Dataset& dataset, int light_index, const ProbeAlignmentOptions& opts,
             ProbeAlignmentResult* result) {
  Image probe;
  SFT_RETURN_IF_ERROR(LoadProbe(dataset, light_index, &probe));
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  const CropGeometry geometry = ChooseCrops(dataset, probe.width, opts);
  const int views = static_cast<int>(dataset.views.size());
  const int used = std::min(views, opts.max_views);
  Progress progress("align-probe", geometry.count / 8 + used, !opts.quiet);
  const Features probe_features = ProbeFeatures(probe, geometry, sift);
  progress.Advance(geometry.count / 8);
  result->crops = geometry.count;
  if (probe_features.directions.size() < 2) {
    return Status::Error(dataset.lights[light_index].image + ": no SIFT features in the probe");
  }
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<Eigen::Vector3d> env, world;
  for (int k = 0; k < used; ++k) {
    const int index = static_cast<int>(static_cast<int64_t>(k) * views / used);
    Features frame;
    SFT_RETURN_IF_ERROR(FrameFeatures(dataset, index, opts, sift, &frame));
    progress.Advance();
    if (frame.directions.empty()) continue;
    ++result->views_used;
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(frame.descriptors, probe_features.descriptors, knn, 2);
    for (const std::vector<cv::DMatch>& m : knn) {
      if (m.size() < 2 || m[0].distance > opts.ratio * m[1].distance) continue;
      env.push_back(probe_features.directions[m[0].trainIdx]);
      world.push_back(frame.directions[m[0].queryIdx]);
    }
  }
  progress.Finish();
  result->matches = static_cast<int>(env.size());
  std::vector<int> inliers;
  if (env.size() >= 2) result->world_from_env = SolveRotation(env, world, opts, &inliers);
  result->inliers = static_cast<int>(inliers.size());
  if (result->inliers < opts.min_inliers) {
    return Status::Error(dataset.lights[light_index].image + ": the probe does not match the " +
                         "frames' background: " + std::to_string(result->inliers) +
                         " consistent matches of " + std::to_string(result->matches) + " (need " +
                         std::to_string(opts.min_inliers) + ")");
  }
  std::vector<double> residuals;
  for (int i : inliers) {
    const double c = std::clamp((result->world_from_env * env[i]).dot(world[i]), -1.0, 1.0);
    residuals.push_back(std::acos(c) / kDeg);
  }
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  result->median_residual_deg = residuals[residuals.size() / 2];
  result->rotation_angle_deg =
      Eigen::AngleAxisd(Eigen::Matrix3d(result->world_from_env)).angle() / kDeg;
  return Status::Ok();
}

}  // namespace

bool ProbeAlignmentOptions::Check(std::string* why) const {
  if (max_views < 1 || max_views > 10000) return Fail(why, "max_views: must be in [1, 10000]");
  if (crops != 0 && (crops < 6 || crops > 500)) return Fail(why, "crops: must be 0 or in [6, 500]");
  if (crop_fov_deg != 0 && !(crop_fov_deg >= 20 && crop_fov_deg <= 120)) {
    return Fail(why, "crop_fov_deg: must be 0 or in [20, 120]");
  }
  if (!(ratio > 0 && ratio <= 1)) return Fail(why, "ratio: must be in (0, 1]");
  if (!(inlier_angle_deg > 0 && inlier_angle_deg <= 20)) {
    return Fail(why, "inlier_angle_deg: must be in (0, 20]");
  }
  if (ransac_iterations < 1 || ransac_iterations > 1000000) {
    return Fail(why, "ransac_iterations: must be in [1, 1e6]");
  }
  if (min_inliers < 3) return Fail(why, "min_inliers: must be >= 3");
  if (mask_dilation_px < 0 || mask_dilation_px > 100) {
    return Fail(why, "mask_dilation_px: must be in [0, 100]");
  }
  return true;
}

Status AlignProbe(const Dataset& dataset, int light_index, const ProbeAlignmentOptions& options,
                  ProbeAlignmentResult* result) {
  *result = ProbeAlignmentResult();
  std::string why;
  if (!options.Check(&why)) return Status::Error("probe alignment: " + why);
  if (light_index < 0 || light_index >= static_cast<int>(dataset.lights.size()) ||
      dataset.lights[light_index].type != LightType::kEnvironment) {
    return Status::Error("probe alignment: light " + std::to_string(light_index) +
                         " is not an environment light");
  }
  if (dataset.views.empty()) return Status::Error("probe alignment: the dataset has no views");
  try {
    return Align(dataset, light_index, options, result);
  } catch (const std::exception& e) {
    return Status::Error(std::string("probe alignment: OpenCV: ") + e.what());
  }
}

std::string AlignedProbeLighting(const ProbeAlignmentResult& r) {
  char text[200];
  std::snprintf(text, sizeof(text),
                "probe aligned by sft align-probe (%d inliers of %d matches, median residual "
                "%.2f deg); intensity scale unknown",
                r.inliers, r.matches, r.median_residual_deg);
  return text;
}

}  // namespace sft
