// Polygon triangulation: exact cover of concave polygons (area and a point-sampled IoU), the fan
// for convex ones, winding, and refusal of non-planar and self-intersecting polygons.
#include "src/geometry/polygon.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace sft {
namespace {

using ::testing::HasSubstr;
using Triangles = std::vector<std::array<int, 3>>;

std::vector<Eigen::Vector3d> InPlaneZ0(const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector2d& p : points) out.emplace_back(p.x(), p.y(), 0.0);
  return out;
}

// The concave pentagon of issue 9: a square with a notch cut to (2, 1) from the top edge.
std::vector<Eigen::Vector2d> NotchedPentagon() { return {{0, 0}, {4, 0}, {4, 4}, {2, 1}, {0, 4}}; }

double Cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Even-odd point-in-polygon test (points sampled off every edge).
bool InsidePolygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

bool InsideTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                    const Eigen::Vector2d& p) {
  const double d1 = Cross2(b - a, p - a), d2 = Cross2(c - b, p - b), d3 = Cross2(a - c, p - c);
  return (d1 >= 0 && d2 >= 0 && d3 >= 0) || (d1 <= 0 && d2 <= 0 && d3 <= 0);
}

// Intersection over union of the polygon and the triangles' union, on a 400×400 point grid over
// the polygon's bounding box (grid points chosen off the polygon's edges and diagonals).
double GridIoU(const std::vector<Eigen::Vector2d>& poly, const Triangles& triangles) {
  Eigen::Vector2d lo = poly[0], hi = poly[0];
  for (const Eigen::Vector2d& p : poly) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  int both = 0, either = 0;
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2d p(lo.x() + (hi.x() - lo.x()) * (i + 0.5123) / n,
                              lo.y() + (hi.y() - lo.y()) * (j + 0.4871) / n);
      const bool in_poly = InsidePolygon(poly, p);
      bool in_tri = false;
      for (const auto& t : triangles) {
        in_tri = in_tri || InsideTriangle(poly[t[0]], poly[t[1]], poly[t[2]], p);
      }
      both += in_poly && in_tri;
      either += in_poly || in_tri;
    }
  }
  return static_cast<double>(both) / either;
}

double SignedArea(const std::vector<Eigen::Vector2d>& poly, const std::array<int, 3>& t) {
  return 0.5 * Cross2(poly[t[1]] - poly[t[0]], poly[t[2]] - poly[t[0]]);
}

TEST(PolygonTest, ConcavePentagonCoveredExactly) {
  const std::vector<Eigen::Vector2d> poly = NotchedPentagon();
  Triangles triangles;
  ASSERT_TRUE(TriangulatePolygon(InPlaneZ0(poly), &triangles).ok());
  ASSERT_EQ(triangles.size(), 3u);
  double area = 0.0;
  for (const auto& t : triangles) {
    const double a = SignedArea(poly, t);
    EXPECT_GT(a, 0.0) << "every triangle keeps the polygon's (counter-clockwise) winding";
    area += a;
    EXPECT_LT(t[0], t[1]) << "starts at its lowest corner";
    EXPECT_LT(t[0], t[2]);
  }
  EXPECT_EQ(area, 10.0);  // Shoelace area of the pentagon (a fan gives |areas| = 14).
  EXPECT_EQ(GridIoU(poly, triangles), 1.0);
  // The fan that the reader used before covers the notch.
  const Triangles fan = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}};
  EXPECT_LT(GridIoU(poly, fan), 0.9);  // 0.89: it covers part of the notch.
}

TEST(PolygonTest, ClockwiseAndTiltedPolygonsKeepTheirWinding) {
  std::vector<Eigen::Vector2d> poly = NotchedPentagon();
  std::reverse(poly.begin(), poly.end());  // Clockwise seen from +z.
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d offset(10, -3, 5);
  std::vector<Eigen::Vector3d> corners;
  for (const Eigen::Vector3d& p : InPlaneZ0(poly)) corners.push_back(rotation * p + offset);
  Triangles triangles;
  ASSERT_TRUE(TriangulatePolygon(corners, &triangles).ok());
  ASSERT_EQ(triangles.size(), 3u);
  const Eigen::Vector3d polygon_normal = rotation * Eigen::Vector3d(0, 0, -1);
  double area = 0.0;
  for (const auto& t : triangles) {
    const Eigen::Vector3d n = (corners[t[1]] - corners[t[0]]).cross(corners[t[2]] - corners[t[0]]);
    EXPECT_GT(n.dot(polygon_normal), 0.0);
    area += 0.5 * n.norm();
  }
  EXPECT_NEAR(area, 10.0, 1e-12);
  EXPECT_EQ(GridIoU(poly, triangles), 1.0);
}

TEST(PolygonTest, ConvexPolygonIsTheFan) {
  std::vector<Eigen::Vector2d> hexagon;
  for (int k = 0; k < 6; ++k) hexagon.emplace_back(std::cos(k * M_PI / 3), std::sin(k * M_PI / 3));
  Triangles triangles;
  ASSERT_TRUE(TriangulatePolygon(InPlaneZ0(hexagon), &triangles).ok());
  EXPECT_EQ(triangles, (Triangles{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}}));
  ASSERT_TRUE(TriangulatePolygon(InPlaneZ0({{0, 0}, {1, 0}, {1, 1}, {0, 1}}), &triangles).ok());
  EXPECT_EQ(triangles, (Triangles{{0, 1, 2}, {0, 2, 3}}));
  ASSERT_TRUE(TriangulatePolygon(InPlaneZ0({{0, 0}, {1, 0}, {0, 1}}), &triangles).ok());
  EXPECT_EQ(triangles, (Triangles{{0, 1, 2}}));
}

TEST(PolygonTest, StraightCornerMakesNoZeroAreaTriangle) {
  // Corner 1 lies on the edge from 0 to 2 (a T-junction in a quad mesh).
  const std::vector<Eigen::Vector2d> poly = {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {0, 1}};
  Triangles triangles;
  ASSERT_TRUE(TriangulatePolygon(InPlaneZ0(poly), &triangles).ok());
  ASSERT_EQ(triangles.size(), 3u);
  double area = 0.0;
  for (const auto& t : triangles) {
    EXPECT_GT(SignedArea(poly, t), 0.1);
    area += SignedArea(poly, t);
  }
  EXPECT_EQ(area, 2.0);
}

TEST(PolygonTest, CollinearCornersGiveTheDegenerateFan) {
  Triangles triangles;
  ASSERT_TRUE(TriangulatePolygon(InPlaneZ0({{0, 0}, {1, 0}, {3, 0}, {2, 0}}), &triangles).ok());
  EXPECT_EQ(triangles, (Triangles{{0, 1, 2}, {0, 2, 3}}));
}

// A quad with a collapsed edge (corners 1 and 2 at one position, common in quad meshes) is not
// "self-touching": it gives the triangle of its distinct corners plus a zero-area triangle that
// keeps the repeated corner connected, as the fan did.
TEST(PolygonTest, RepeatedCornerPositionsGiveADegenerateTriangle) {
  Triangles triangles;
  ASSERT_TRUE(TriangulatePolygon(InPlaneZ0({{0, 0}, {1, 0}, {1, 0}, {0, 1}}), &triangles).ok());
  EXPECT_EQ(triangles, (Triangles{{0, 1, 3}, {1, 2, 3}}));
  // The concave pentagon with its notch corner doubled, and with the first corner doubled at
  // the end (the wrap-around).
  ASSERT_TRUE(
      TriangulatePolygon(InPlaneZ0({{0, 0}, {4, 0}, {4, 4}, {2, 1}, {2, 1}, {0, 4}}), &triangles)
          .ok());
  ASSERT_EQ(triangles.size(), 4u);
  const std::vector<Eigen::Vector2d> notched = {{0, 0}, {4, 0}, {4, 4}, {2, 1}, {2, 1}, {0, 4}};
  double area = 0.0;
  for (const auto& t : triangles) area += SignedArea(notched, t);
  EXPECT_EQ(area, 10.0);
  ASSERT_TRUE(
      TriangulatePolygon(InPlaneZ0({{0, 0}, {4, 0}, {4, 4}, {2, 1}, {0, 4}, {0, 0}}), &triangles)
          .ok());
  EXPECT_EQ(triangles.size(), 4u);
  // Corners that meet without being neighbours still make the polygon touch itself.
  EXPECT_THAT(
      TriangulatePolygon(InPlaneZ0({{0, 0}, {1, 0}, {1, 1}, {0, 0}, {-1, 1}, {-1, 0}}), &triangles)
          .message(),
      HasSubstr("self-intersecting"));
}

TEST(PolygonTest, NonPlanarRefusedWithTolerance) {
  Triangles triangles;
  // A unit quad with one corner lifted by 0.2 (the diagonal is 1.43): refused.
  Status s = TriangulatePolygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0.2}, {0, 1, 0}}, &triangles);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("not planar"));
  EXPECT_THAT(s.message(), HasSubstr("1% of the polygon's size"));
  // A non-planar concave pentagon too.
  std::vector<Eigen::Vector3d> pentagon = InPlaneZ0(NotchedPentagon());
  pentagon[3].z() = 0.5;
  EXPECT_THAT(TriangulatePolygon(pentagon, &triangles).message(), HasSubstr("not planar"));
  // Lifted by 0.002 (well under 1% of the size): accepted.
  EXPECT_TRUE(
      TriangulatePolygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0.002}, {0, 1, 0}}, &triangles).ok());
}

TEST(PolygonTest, SelfIntersectingRefused) {
  Triangles triangles;
  // Bow tie: edges 0-1 and 2-3 cross.
  Status s = TriangulatePolygon(InPlaneZ0({{0, 0}, {1, 1}, {1, 0}, {0, 1}}), &triangles);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("self-intersecting"));
  EXPECT_THAT(s.message(), HasSubstr("edges 0-1 and 2-3"));
  // Pentagram: every corner joined to the next-but-one point of a regular pentagon.
  std::vector<Eigen::Vector2d> star;
  for (int k = 0; k < 5; ++k)
    star.emplace_back(std::cos(k * 4 * M_PI / 5), std::sin(k * 4 * M_PI / 5));
  EXPECT_THAT(TriangulatePolygon(InPlaneZ0(star), &triangles).message(),
              HasSubstr("self-intersecting"));
  // A pentagon folding back along its first edge (a spike) and one touching itself.
  EXPECT_THAT(
      TriangulatePolygon(InPlaneZ0({{0, 0}, {2, 0}, {1, 0}, {1, 1}, {0, 1}}), &triangles).message(),
      HasSubstr("self-intersecting"));
  EXPECT_THAT(
      TriangulatePolygon(InPlaneZ0({{0, 0}, {4, 0}, {4, 4}, {2, 0}, {0, 4}}), &triangles).message(),
      HasSubstr("self-intersecting"));
}

// A concave star with the maximum number of corners is triangulated exactly (and quickly: the
// work is O(n²)); one more corner is refused.
TEST(PolygonTest, LargeConcavePolygonAndCornerLimit) {
  std::vector<Eigen::Vector2d> star;
  const int n = kMaxPolygonCorners;
  for (int k = 0; k < n; ++k) {
    const double r = k % 2 == 0 ? 1.0 : 0.6, a = 2 * M_PI * k / n;
    star.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  Triangles triangles;
  ASSERT_TRUE(TriangulatePolygon(InPlaneZ0(star), &triangles).ok());
  ASSERT_EQ(triangles.size(), static_cast<size_t>(n - 2));
  double area = 0.0, shoelace = 0.0;
  for (const auto& t : triangles) {
    EXPECT_GT(SignedArea(star, t), 0.0);
    area += SignedArea(star, t);
  }
  for (int k = 0; k < n; ++k) shoelace += 0.5 * Cross2(star[k], star[(k + 1) % n]);
  EXPECT_NEAR(area, shoelace, 1e-12);
  star.emplace_back(1.0, -1e-9);
  const Status s = TriangulatePolygon(InPlaneZ0(star), &triangles);
  EXPECT_THAT(s.message(), HasSubstr("polygon has 16385 corners, more than the 16384 supported"));
}

}  // namespace
}  // namespace sft
