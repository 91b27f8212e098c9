#include "src/atlas/atlas_packing.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace sft {
namespace {

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Convex hull, Andrew's monotone chain, counter-clockwise without collinear points.
std::vector<Eigen::Vector2d> ConvexHull(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() != b.x() ? a.x() < b.x() : a.y() < b.y();
  });
  if (points.size() < 3) return points;
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && Cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// Rotates and translates `corners` to their minimum-area bounding box [0, w] × [0, h] with
// w ≥ h; returns (w, h).
Eigen::Vector2d NormalizeChart(ChartCorners* corners) {
  const std::vector<Eigen::Vector2d> hull = ConvexHull(*corners);
  Eigen::Matrix2d best_rotation = Eigen::Matrix2d::Identity();
  double best_area = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d edge = hull[(i + 1) % hull.size()] - hull[i];
    if (edge.norm() <= 0.0) continue;
    const Eigen::Vector2d d = edge.normalized();
    Eigen::Matrix2d rotation;
    rotation << d.x(), d.y(), -d.y(), d.x();  // takes d to the x axis.
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
    for (const Eigen::Vector2d& p : hull) {
      const Eigen::Vector2d q = rotation * p;
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
    const double area = (hi - lo).prod();
    if (area < best_area) {
      best_area = area;
      best_rotation = rotation;
    }
  }
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (Eigen::Vector2d& p : *corners) {
    p = best_rotation * p;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Eigen::Vector2d size = hi - lo;
  for (Eigen::Vector2d& p : *corners) p -= lo;
  if (size.y() > size.x()) {
    // A quarter turn (x, y) → (h − y, x) keeps the orientation and makes the chart lie flat.
    for (Eigen::Vector2d& p : *corners) p = Eigen::Vector2d(size.y() - p.y(), p.x());
    size = Eigen::Vector2d(size.y(), size.x());
  }
  return size;
}

// First-fit decreasing-height shelves at scale s; false when the charts do not fit. `origin`
// gets each chart's top-left texel.
bool PlaceOnShelves(const std::vector<Eigen::Vector2d>& sizes, double s, int texture_size,
                    int gutter, std::vector<Eigen::Vector2i>* origin) {
  const int n = static_cast<int>(sizes.size());
  std::vector<Eigen::Vector2i> box(n);
  for (int i = 0; i < n; ++i) {
    box[i] = Eigen::Vector2i(static_cast<int>(std::ceil(sizes[i].x() * s)) + gutter,
                             static_cast<int>(std::ceil(sizes[i].y() * s)) + gutter);
    if (box[i].x() + gutter > texture_size || box[i].y() + gutter > texture_size) return false;
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return box[a].y() > box[b].y(); });
  struct Shelf {
    int y, height, x;
  };
  std::vector<Shelf> shelves;
  int top = gutter;
  origin->assign(n, Eigen::Vector2i::Zero());
  for (int i : order) {
    bool placed = false;
    for (Shelf& shelf : shelves) {
      if (shelf.x + box[i].x() <= texture_size && box[i].y() <= shelf.height) {
        (*origin)[i] = Eigen::Vector2i(shelf.x, shelf.y);
        shelf.x += box[i].x();
        placed = true;
        break;
      }
    }
    if (placed) continue;
    if (top + box[i].y() > texture_size) return false;
    shelves.push_back({top, box[i].y(), gutter + box[i].x()});
    (*origin)[i] = Eigen::Vector2i(gutter, top);
    top += box[i].y();
  }
  return true;
}

}  // namespace

Status PackCharts(int texture_size, int gutter, std::vector<ChartCorners>* charts,
                  double* texels_per_unit) {
  std::vector<Eigen::Vector2d> sizes;
  double total_area = 0.0;
  for (ChartCorners& corners : *charts) {
    sizes.push_back(NormalizeChart(&corners));
    for (size_t i = 0; i + 2 < corners.size(); i += 3) {
      total_area += 0.5 * std::abs(Cross(corners[i], corners[i + 1], corners[i + 2]));
    }
  }
  // Full utilisation bounds the scale from above.
  double hi = texture_size / std::sqrt(std::max(total_area, 1e-300));
  double lo = 0.0;
  std::vector<Eigen::Vector2i> origin;
  if (!PlaceOnShelves(sizes, hi * 1e-6, texture_size, gutter, &origin)) {
    return Status::Error(std::to_string(charts->size()) + " charts do not fit a " +
                         std::to_string(texture_size) + "² atlas with " + std::to_string(gutter) +
                         "-texel gutters (raise --texture-size)");
  }
  lo = hi * 1e-6;
  for (int iteration = 0; iteration < 40; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    if (PlaceOnShelves(sizes, mid, texture_size, gutter, &origin)) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  PlaceOnShelves(sizes, lo, texture_size, gutter, &origin);
  const double t = texture_size;
  for (size_t c = 0; c < charts->size(); ++c) {
    for (Eigen::Vector2d& p : (*charts)[c]) {
      // Texel x to the right, texel y down from the top row; v = 1 − y/T.
      const double x = origin[c].x() + p.x() * lo;
      const double y = origin[c].y() + (sizes[c].y() - p.y()) * lo;
      p = Eigen::Vector2d(x / t, 1.0 - y / t);
    }
  }
  *texels_per_unit = lo;
  return Status::Ok();
}

}  // namespace sft
