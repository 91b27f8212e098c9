// Triangulation of the polygons that mesh files contain (OBJ/OFF/PLY faces with more than three
// corners): planar simple polygons, convex or not, by ear clipping in the polygon's best-fit plane.
#ifndef SFT_GEOMETRY_POLYGON_H_
#define SFT_GEOMETRY_POLYGON_H_

#include <Eigen/Core>
#include <array>
#include <vector>

#include "src/core/status.h"

namespace sft {

// A polygon is planar when every corner lies within this fraction of the polygon's size (the
// diagonal of its corners' bounding box) of its best-fit (least-squares) plane. Beyond it the
// polygon does not define one surface: its triangulations differ by more than 1% of its size.
constexpr double kPolygonPlanarTolerance = 1e-2;

// Polygons with more corners are refused: the checks and ear clipping take O(n²) time (a concave
// 10000-corner star takes 0.4 s), so a hostile face of a million corners would take hours.
constexpr int kMaxPolygonCorners = 16384;

// Triangulates the polygon whose corners are `corners` (in order; at least 3). Each triangle
// (indices into `corners`) has the polygon's winding and starts at its lowest corner index.
//   - Strictly convex polygons give the fan (0, k, k+1), unchanged from a plain fan.
//   - Other simple polygons are ear-clipped in the best-fit plane: the triangles cover exactly
//     the polygon (a concave notch stays uncovered).
//   - Polygons whose corners all lie on a line (zero area) give the fan's zero-area triangles, as
//     a degenerate triangle would be kept.
// Errors (one line, without the file or face, which the caller adds): a polygon that is not
// planar (tolerance above), is self-intersecting (two edges cross or touch, projected into the
// plane), or has more than kMaxPolygonCorners corners.
Status TriangulatePolygon(const std::vector<Eigen::Vector3d>& corners,
                          std::vector<std::array<int, 3>>* triangles);

}  // namespace sft

#endif  // SFT_GEOMETRY_POLYGON_H_
