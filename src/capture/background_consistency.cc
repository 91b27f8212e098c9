#include "src/capture/background_consistency.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "src/core/progress.h"

namespace sft {

// A view at the working resolution: its camera, pose and display image (8-bit RGB, row-major).
struct BackgroundWorkView {
  Camera camera;
  Rigid3d cam_from_world;
  double max_radius2 = std::numeric_limits<double>::infinity();  // of normalized coordinates.
  std::vector<uint8_t> rgb;
  // 1 where an earlier mask says the view sees the object (row-major); empty = no mask.
  std::vector<uint8_t> object;
};

namespace {

using WorkView = BackgroundWorkView;

bool Fail(std::string* why, const std::string& text) {
  *why = text;
  return false;
}

// The linear image of view `index` box-filtered to `camera`'s size (cv::INTER_AREA).
Status LoadWorkImage(const Dataset& dataset, int index, const Camera& camera, Image* out) {
  Image rgb;
  SFT_RETURN_IF_ERROR(LoadViewImage(dataset, index, &rgb));
  rgb = ToRgb(rgb);
  cv::Mat full(rgb.height, rgb.width, CV_32FC3, rgb.data.data());
  cv::Mat small;
  cv::resize(full, small, cv::Size(camera.width, camera.height), 0, 0, cv::INTER_AREA);
  *out = Image(camera.width, camera.height, 3);
  std::copy(small.ptr<float>(), small.ptr<float>() + out->data.size(), out->data.begin());
  return Status::Ok();
}

float Luminance(const Image& rgb, size_t pixel) {
  return 0.2126f * rgb.data[3 * pixel] + 0.7152f * rgb.data[3 * pixel + 1] +
         0.0722f * rgb.data[3 * pixel + 2];
}

float Percentile99(const Image& rgb) {
  std::vector<float> lum(static_cast<size_t>(rgb.width) * rgb.height);
  for (size_t i = 0; i < lum.size(); ++i) lum[i] = Luminance(rgb, i);
  auto nth = lum.begin() + static_cast<std::ptrdiff_t>(lum.size() * 99 / 100);
  std::nth_element(lum.begin(), nth, lum.end());
  return *nth;
}

uint8_t Display(float linear, float white) {
  const float v = std::clamp(linear / white, 0.0f, 1.0f);
  const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(255.0f * s));
}

// Bilinear display colour of `view` at image point `px` (pixel (x, y) covers [x, x+1]); false
// outside the pixel centres' rectangle.
bool Sample(const WorkView& view, const Eigen::Vector2d& px, std::array<float, 3>* rgb) {
  const double u = px.x() - 0.5, v = px.y() - 0.5;
  const int w = view.camera.width, h = view.camera.height;
  if (!(u >= 0 && v >= 0 && u <= w - 1 && v <= h - 1)) return false;
  if (!view.object.empty() &&
      view.object[static_cast<int>(px.y()) * w + static_cast<int>(px.x())] != 0) {
    return false;  // the object hides the background point from this view.
  }
  const int x0 = std::min(static_cast<int>(u), std::max(w - 2, 0));
  const int y0 = std::min(static_cast<int>(v), std::max(h - 2, 0));
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const float fx = static_cast<float>(u - x0), fy = static_cast<float>(v - y0);
  for (int c = 0; c < 3; ++c) {
    auto at = [&](int x, int y) { return static_cast<float>(view.rgb[(y * w + x) * 3 + c]); };
    (*rgb)[c] = ((1 - fx) * (1 - fy) * at(x0, y0) + fx * (1 - fy) * at(x1, y0) +
                 (1 - fx) * fy * at(x0, y1) + fx * fy * at(x1, y1)) /
                255.0f;
  }
  return true;
}

// Projects a point of `view`'s camera frame (a direction when the hypothesis is distant) into its
// image; false behind the camera or beyond a distortion's fold.
bool Project(const WorkView& view, const Eigen::Vector3d& p_in_cam, Eigen::Vector2d* px) {
  if (!(p_in_cam.z() > 1e-9)) return false;
  const double r2 =
      (p_in_cam.x() * p_in_cam.x() + p_in_cam.y() * p_in_cam.y()) / (p_in_cam.z() * p_in_cam.z());
  if (!(r2 <= view.max_radius2)) return false;
  *px = view.camera.ImageFromCam(p_in_cam);
  return true;
}

// The largest channel's distance of `pixel` from the channel-wise median of `samples`.
float MedianDistance(const std::array<float, 3>& pixel,
                     std::array<std::vector<float>, 3>* samples) {
  float distance = 0;
  for (int c = 0; c < 3; ++c) {
    std::vector<float>& s = (*samples)[c];
    auto mid = s.begin() + static_cast<std::ptrdiff_t>(s.size() / 2);
    std::nth_element(s.begin(), mid, s.end());
    distance = std::max(distance, std::abs(pixel[c] - *mid));
  }
  return distance;
}

struct Hypothesis {
  std::array<std::vector<float>, 3> samples;
  void Clear() {
    for (auto& s : samples) s.clear();
  }
  void Add(const std::array<float, 3>& rgb) {
    for (int c = 0; c < 3; ++c) samples[c].push_back(rgb[c]);
  }
  int size() const { return static_cast<int>(samples[0].size()); }
};

// One row of view i's distance map.
void DistanceRow(const std::vector<WorkView>& views, int i, const std::vector<int>& others,
                 const SupportPlane* plane, int min_views, int y, Image* distance) {
  const WorkView& view = views[i];
  const Eigen::Quaterniond world_from_cam = view.cam_from_world.rotation.conjugate();
  const Eigen::Vector3d centre = -(world_from_cam * view.cam_from_world.translation);
  Hypothesis on_plane, distant;
  for (int x = 0; x < view.camera.width; ++x) {
    float& out = distance->at(x, y);
    out = std::numeric_limits<float>::quiet_NaN();
    const Eigen::Vector3d ray = view.camera.CamFromImage({x + 0.5, y + 0.5});
    if (ray.isZero()) continue;
    const Eigen::Vector3d dir = world_from_cam * ray;
    bool hits_plane = false;
    Eigen::Vector3d hit;
    if (plane != nullptr && plane->found) {
      const double along = plane->normal.dot(dir);
      const double t = along < -1e-12 ? -plane->SignedDistance(centre) / along : -1.0;
      hits_plane = t > 0;
      hit = centre + t * dir;
    }
    on_plane.Clear();
    distant.Clear();
    std::array<float, 3> rgb;
    Eigen::Vector2d px;
    for (int j : others) {
      const WorkView& other = views[j];
      if (hits_plane && Project(other, other.cam_from_world * hit, &px) && Sample(other, px, &rgb))
        on_plane.Add(rgb);
      if (Project(other, other.cam_from_world.rotation * dir, &px) && Sample(other, px, &rgb))
        distant.Add(rgb);
    }
    std::array<float, 3> own;
    for (int c = 0; c < 3; ++c) own[c] = view.rgb[(y * view.camera.width + x) * 3 + c] / 255.0f;
    if (on_plane.size() >= min_views) out = MedianDistance(own, &on_plane.samples);
    if (distant.size() >= min_views) {
      const float d = MedianDistance(own, &distant.samples);
      out = std::isnan(out) ? d : std::min(out, d);
    }
  }
}

// The views compared with view i: every other view, or max_views of them spread evenly.
std::vector<int> OtherViews(int i, int count, int max_views) {
  std::vector<int> others;
  const int n = count - 1;
  const int take = std::min(n, max_views);
  for (int k = 0; k < take; ++k) {
    const int j = static_cast<int>((static_cast<int64_t>(k) * n) / take);
    others.push_back(j < i ? j : j + 1);
  }
  return others;
}

Status LoadWorkViews(const Dataset& dataset, const BackgroundConsistencyOptions& options,
                     std::vector<WorkView>* views) {
  const int n = static_cast<int>(dataset.views.size());
  views->assign(n, WorkView());
  std::vector<float> whites(n);
  for (int i = 0; i < n; ++i) {
    const Camera& full = dataset.cameras[dataset.views[i].camera];
    WorkView& view = (*views)[i];
    view.camera =
        DownscaledCamera(full, BackgroundLog2Factor(full.width, full.height, options.max_side));
    view.cam_from_world = dataset.views[i].cam_from_world;
    const double r = view.camera.MaxUndistortedRadius();
    if (std::isfinite(r)) view.max_radius2 = r * r;
    Image rgb;
    SFT_RETURN_IF_ERROR(LoadWorkImage(dataset, i, view.camera, &rgb));
    whites[i] = Percentile99(rgb);
  }
  std::vector<float> sorted = whites;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const float white = std::max(sorted[n / 2], 1e-8f);
  for (int i = 0; i < n; ++i) {
    WorkView& view = (*views)[i];
    Image rgb;
    SFT_RETURN_IF_ERROR(LoadWorkImage(dataset, i, view.camera, &rgb));
    view.rgb.resize(rgb.data.size());
    for (size_t k = 0; k < rgb.data.size(); ++k) view.rgb[k] = Display(rgb.data[k], white);
  }
  return Status::Ok();
}

// A 3×3 median of the distance map (the pixel noise of renders and sensors, which a single
// pixel's colour carries in full); pixels without a distance stay without one, and the median
// takes the neighbours that have one.
void MedianFilter3(Image* distance) {
  const Image in = *distance;
  float window[9];
  for (int y = 0; y < in.height; ++y) {
    for (int x = 0; x < in.width; ++x) {
      if (std::isnan(in.at(x, y))) continue;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = x + dx, v = y + dy;
          if (u < 0 || v < 0 || u >= in.width || v >= in.height) continue;
          const float d = in.at(u, v);
          if (!std::isnan(d)) window[n++] = d;
        }
      }
      std::nth_element(window, window + n / 2, window + n);
      distance->at(x, y) = window[n / 2];
    }
  }
}

}  // namespace

bool BackgroundConsistencyOptions::Check(std::string* why) const {
  if (max_side < 16 || max_side > 16384) return Fail(why, "max_side: must be in [16, 16384]");
  if (min_views < 1 || min_views > 1000) return Fail(why, "min_views: must be in [1, 1000]");
  if (max_views < 1 || max_views > 1000) return Fail(why, "max_views: must be in [1, 1000]");
  return true;
}

int BackgroundLog2Factor(int width, int height, int max_side) {
  int k = 0;
  while ((std::max(width, height) >> k) > max_side) ++k;
  return k;
}

namespace {

// `mask` (1 channel, > 0.5 = object, any resolution) at `view`'s working resolution: a working
// pixel is object when any mask pixel it covers is (nearest lookups at its corners and centre).
std::vector<uint8_t> WorkMask(const Image& mask, const Camera& camera) {
  std::vector<uint8_t> object(static_cast<size_t>(camera.width) * camera.height, 0);
  const double sx = static_cast<double>(mask.width) / camera.width;
  const double sy = static_cast<double>(mask.height) / camera.height;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      bool any = false;
      for (double fy : {0.0, 0.5, 0.999}) {
        for (double fx : {0.0, 0.5, 0.999}) {
          const int mx = std::min(mask.width - 1, static_cast<int>((x + fx) * sx));
          const int my = std::min(mask.height - 1, static_cast<int>((y + fy) * sy));
          any = any || mask.at(mx, my) > 0.5f;
        }
      }
      object[static_cast<size_t>(y) * camera.width + x] = any;
    }
  }
  return object;
}

}  // namespace

BackgroundViews::BackgroundViews() = default;
BackgroundViews::~BackgroundViews() = default;

Status BackgroundViews::Load(const Dataset& dataset, const BackgroundConsistencyOptions& options,
                             std::unique_ptr<BackgroundViews>* out) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("background consistency: " + why);
  if (dataset.views.size() < 2) {
    return Status::Error("background consistency: needs at least 2 views");
  }
  std::unique_ptr<BackgroundViews> loaded(new BackgroundViews());
  loaded->options_ = options;
  try {
    SFT_RETURN_IF_ERROR(LoadWorkViews(dataset, options, &loaded->views_));
  } catch (const std::exception& e) {
    return Status::Error("background consistency: OpenCV: " + std::string(e.what()));
  }
  *out = std::move(loaded);
  return Status::Ok();
}

Status BackgroundViews::Distances(const SupportPlane* plane, const std::vector<Image>* masks,
                                  std::vector<Image>* distances) {
  const int n = static_cast<int>(views_.size());
  if (masks != nullptr && static_cast<int>(masks->size()) != n) {
    return Status::Error("background consistency: one mask per view needed");
  }
  for (int i = 0; i < n; ++i) {
    const bool has_mask = masks != nullptr && !(*masks)[i].empty();
    views_[i].object = has_mask ? WorkMask((*masks)[i], views_[i].camera) : std::vector<uint8_t>();
  }
  distances->assign(n, Image());
  Progress progress("background", n, !options_.quiet);
  for (int i = 0; i < n; ++i) {
    Image& distance = (*distances)[i];
    distance = Image(views_[i].camera.width, views_[i].camera.height, 1);
    const std::vector<int> others = OtherViews(i, n, options_.max_views);
    tbb::parallel_for(0, distance.height, [&](int y) {
      DistanceRow(views_, i, others, plane, options_.min_views, y, &distance);
    });
    MedianFilter3(&distance);
    progress.Advance();
  }
  progress.Finish();
  return Status::Ok();
}

Status BackgroundDistances(const Dataset& dataset, const SupportPlane* plane,
                           const BackgroundConsistencyOptions& options,
                           std::vector<Image>* distances) {
  return BackgroundDistances(dataset, plane, nullptr, options, distances);
}

Status BackgroundDistances(const Dataset& dataset, const SupportPlane* plane,
                           const std::vector<Image>* masks,
                           const BackgroundConsistencyOptions& options,
                           std::vector<Image>* distances) {
  std::unique_ptr<BackgroundViews> views;
  SFT_RETURN_IF_ERROR(BackgroundViews::Load(dataset, options, &views));
  return views->Distances(plane, masks, distances);
}

}  // namespace sft
