// Polygon triangulation: best-fit plane (least squares through the centroid), planarity and
// simplicity checks in that plane, then a fan for strictly convex polygons and ear clipping for
// the others. O(n²) per polygon (n = corners), which is what mesh files' polygons need.
#include "src/geometry/polygon.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace sft {
namespace {

// Corners within this fraction of the polygon's size of one line make a zero-area polygon (the
// same order as the degenerate-triangle threshold of mesh reading, 1e-12 of the area scale).
constexpr double kCollinearRelativeWidth = 1e-9;
// Orientations (twice a triangle's area) within this fraction of size² count as collinear.
constexpr double kOrientRelativeTolerance = 1e-12;

std::string Format(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", value);
  return buffer;
}

// Twice the signed area of triangle (a, b, c): > 0 when counter-clockwise.
double Orient(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// The sign of Orient, 0 within `eps` (projected coordinates carry rounding error, so corners
// that are collinear in the file are only nearly collinear after the projection).
int OrientSign(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
               double eps) {
  const double o = Orient(a, b, c);
  return o > eps ? 1 : (o < -eps ? -1 : 0);
}

// p lies on the closed segment [a, b], given that it is (nearly) collinear with it.
bool OnSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p,
               double eps) {
  const Eigen::Vector2d ab = b - a;
  const double t = ab.dot(p - a);
  return t >= -eps && t <= ab.squaredNorm() + eps;
}

// The closed segments [a, b] and [c, d] share a point (up to eps).
bool SegmentsTouch(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d, double eps) {
  const int o1 = OrientSign(a, b, c, eps), o2 = OrientSign(a, b, d, eps);
  const int o3 = OrientSign(c, d, a, eps), o4 = OrientSign(c, d, b, eps);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && OnSegment(a, b, c, eps)) || (o2 == 0 && OnSegment(a, b, d, eps)) ||
         (o3 == 0 && OnSegment(c, d, a, eps)) || (o4 == 0 && OnSegment(c, d, b, eps));
}

// Finds two edges of the closed polygon q that cross or touch (other than adjacent edges meeting
// at their shared corner), or an adjacent pair that folds back onto itself. Edge k is q[k]→q[k+1].
bool FindSelfIntersection(const std::vector<Eigen::Vector2d>& q, double eps, int* edge_a,
                          int* edge_b) {
  const int n = static_cast<int>(q.size());
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = q[i];
    const Eigen::Vector2d& b = q[(i + 1) % n];
    for (int j = i + 1; j < n; ++j) {
      const Eigen::Vector2d& c = q[j];
      const Eigen::Vector2d& d = q[(j + 1) % n];
      bool hit = false;
      if (j == i + 1) {  // Shares b = c: a spike when d goes back along b→a.
        hit = OrientSign(a, b, d, eps) == 0 && (a - b).dot(d - b) > 0;
      } else if (i == 0 && j == n - 1) {  // Shares a = d: a spike when c lies along a→b.
        hit = OrientSign(a, b, c, eps) == 0 && (b - a).dot(c - a) > 0;
      } else {
        hit = SegmentsTouch(a, b, c, d, eps);
      }
      if (hit) {
        *edge_a = i;
        *edge_b = j;
        return true;
      }
    }
  }
  return false;
}

// Closed test (up to eps) for a counter-clockwise triangle.
bool PointInTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                     const Eigen::Vector2d& p, double eps) {
  return Orient(a, b, p) >= -eps && Orient(b, c, p) >= -eps && Orient(c, a, p) >= -eps;
}

// The triangle (a, b, c) rotated to start at its lowest index (same cyclic order).
std::array<int, 3> Rotated(int a, int b, int c) {
  if (b < a && b < c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

// Ear clipping of the counter-clockwise simple polygon q. An ear is a strictly convex corner
// whose triangle with its neighbours contains no other remaining corner (closed test, so a
// corner on the cutting diagonal blocks it).
void EarClip(const std::vector<Eigen::Vector2d>& q, double eps,
             std::vector<std::array<int, 3>>* triangles) {
  std::vector<int> ring(q.size());
  for (size_t i = 0; i < q.size(); ++i) ring[i] = static_cast<int>(i);
  size_t cursor = 0;
  while (ring.size() > 3) {
    const size_t m = ring.size();
    bool clipped = false;
    for (size_t step = 0; step < m && !clipped; ++step) {
      const size_t k = (cursor + step) % m;
      const int ia = ring[(k + m - 1) % m], ib = ring[k], ic = ring[(k + 1) % m];
      if (OrientSign(q[ia], q[ib], q[ic], eps) <= 0) continue;
      bool empty = true;
      for (int j : ring) {
        if (j != ia && j != ib && j != ic && PointInTriangle(q[ia], q[ib], q[ic], q[j], eps)) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      triangles->push_back(Rotated(ia, ib, ic));
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(k));
      cursor = (k + ring.size() - 1) % ring.size();
      clipped = true;
    }
    if (!clipped) break;  // Only rounding can get here: fan the rest (it is nearly collinear).
  }
  for (size_t k = 1; k + 1 < ring.size(); ++k) {
    triangles->push_back(Rotated(ring[0], ring[k], ring[k + 1]));
  }
}

}  // namespace

Status TriangulatePolygon(const std::vector<Eigen::Vector3d>& corners,
                          std::vector<std::array<int, 3>>* triangles) {
  const int n = static_cast<int>(corners.size());
  triangles->clear();
  if (n < 3) return Status::Error("polygon with " + std::to_string(n) + " corners");
  if (n > kMaxPolygonCorners) {
    return Status::Error("polygon has " + std::to_string(n) + " corners, more than the " +
                         std::to_string(kMaxPolygonCorners) + " supported");
  }
  auto fan = [&]() {
    for (int k = 1; k + 1 < n; ++k) triangles->push_back({0, k, k + 1});
    return Status::Ok();
  };
  if (n == 3) return fan();

  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), lo = corners[0], hi = corners[0];
  for (const Eigen::Vector3d& p : corners) {
    centroid += p;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  centroid /= n;
  const double size = (hi - lo).norm();
  if (!(size > 0)) return fan();  // All corners at one point: zero-area triangles.
  // Corners that repeat the previous corner's position (a collapsed edge, common in quad meshes)
  // would make the polygon touch itself: triangulate without them, then give each a zero-area
  // triangle with its neighbours so that it stays connected (as the fan's degenerate triangle
  // did).
  std::vector<int> kept;
  for (int i = 0; i < n; ++i) {
    const int previous = kept.empty() ? n - 1 : kept.back();
    const bool repeats = (corners[i] - corners[previous]).norm() <= kCollinearRelativeWidth * size;
    if (!repeats || (kept.empty() && i == n - 1)) kept.push_back(i);
  }
  if (static_cast<int>(kept.size()) < n) {
    if (kept.size() < 3) return fan();
    std::vector<Eigen::Vector3d> reduced;
    for (int i : kept) reduced.push_back(corners[i]);
    std::vector<std::array<int, 3>> reduced_triangles;
    SFT_RETURN_IF_ERROR(TriangulatePolygon(reduced, &reduced_triangles));
    for (const std::array<int, 3>& t : reduced_triangles) {
      triangles->push_back(Rotated(kept[t[0]], kept[t[1]], kept[t[2]]));
    }
    for (int i = 0, k = 0; i < n; ++i) {  // k: position in `kept` of the next kept corner.
      if (k < static_cast<int>(kept.size()) && kept[k] == i) {
        ++k;
        continue;
      }
      const int before = (i + n - 1) % n;
      const int after = kept[k % kept.size()];
      triangles->push_back(Rotated(before, i, after));
    }
    return Status::Ok();
  }
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d newell = Eigen::Vector3d::Zero();  // Twice the vector area: winding's normal.
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = corners[i] - centroid;
    covariance += d * d.transpose();
    newell += d.cross(corners[(i + 1) % n] - centroid);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  Eigen::Vector3d normal = eigen.eigenvectors().col(0);      // Smallest eigenvalue.
  const Eigen::Vector3d axis = eigen.eigenvectors().col(2);  // Largest: the main direction.

  int worst = 0;
  double worst_distance = 0.0, width = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = corners[i] - centroid;
    const double distance = std::abs(normal.dot(d));
    if (distance > worst_distance) {
      worst_distance = distance;
      worst = i;
    }
    width = std::max(width, (d - axis.dot(d) * axis).norm());
  }
  if (width <= kCollinearRelativeWidth * size) return fan();  // Collinear corners.
  if (worst_distance > kPolygonPlanarTolerance * size) {
    return Status::Error("polygon is not planar: corner " + std::to_string(worst) + " is " +
                         Format(worst_distance) + " from the best-fit plane (tolerance " +
                         Format(kPolygonPlanarTolerance * 100) + "% of the polygon's size " +
                         Format(size) + ")");
  }

  // Project into the plane with axes (u, v, normal) right-handed and normal on the side from
  // which the polygon turns counter-clockwise.
  if (normal.dot(newell) < 0) normal = -normal;
  const Eigen::Vector3d u = axis;
  const Eigen::Vector3d v = normal.cross(u);
  std::vector<Eigen::Vector2d> q(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = corners[i] - centroid;
    q[i] = Eigen::Vector2d(u.dot(d), v.dot(d));
  }
  // Orientation tolerance: rounding of the projection, far below any real polygon's geometry.
  const double eps = kOrientRelativeTolerance * size * size;
  int edge_a = 0, edge_b = 0;
  if (FindSelfIntersection(q, eps, &edge_a, &edge_b)) {
    return Status::Error("polygon is self-intersecting: its edges " + std::to_string(edge_a) + "-" +
                         std::to_string((edge_a + 1) % n) + " and " + std::to_string(edge_b) + "-" +
                         std::to_string((edge_b + 1) % n) + " (corners) cross or touch");
  }
  bool convex = true;
  for (int i = 0; i < n && convex; ++i) {
    convex = OrientSign(q[(i + n - 1) % n], q[i], q[(i + 1) % n], eps) > 0;
  }
  if (convex) return fan();
  EarClip(q, eps, triangles);
  return Status::Ok();
}

}  // namespace sft
