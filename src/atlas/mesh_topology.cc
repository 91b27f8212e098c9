#include "src/atlas/mesh_topology.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace sft {
namespace {

// One directed edge of a face, keyed by its unordered vertex pair.
struct HalfEdge {
  int lo, hi;    // the edge's vertices, lo < hi.
  int face, e;   // face and edge slot (corner e → corner e + 1).
  bool forward;  // the face runs lo → hi.
};

}  // namespace

MeshTopology::MeshTopology(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<Eigen::Vector3i>& faces)
    : positions_(positions), faces_(faces) {
  const int num_faces = static_cast<int>(faces.size());
  neighbours_.assign(num_faces, {-1, -1, -1});
  vertex_faces_.assign(positions.size(), {});
  degenerate_.assign(num_faces, false);
  normals_.assign(num_faces, Eigen::Vector3d::Zero());
  areas_.assign(num_faces, 0.0);
  centroids_.assign(num_faces, Eigen::Vector3d::Zero());
  angles_.assign(num_faces, {0.0, 0.0, 0.0});
  // Zero area relative to the bounding box: the scale of 1e-14·diagonal² is far below any face
  // a reconstruction keeps, and far above rounding noise of a collinear triple.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const Eigen::Vector3i& f : faces) {
    for (int c = 0; c < 3; ++c) {
      lo = lo.cwiseMin(positions[f[c]]);
      hi = hi.cwiseMax(positions[f[c]]);
    }
  }
  const double min_area = num_faces > 0 ? 1e-14 * (hi - lo).squaredNorm() : 0.0;
  std::vector<HalfEdge> halfedges;
  halfedges.reserve(3 * faces.size());
  for (int f = 0; f < num_faces; ++f) {
    const Eigen::Vector3i& t = faces[f];
    const Eigen::Vector3d& p0 = positions[t[0]];
    const Eigen::Vector3d cross = (positions[t[1]] - p0).cross(positions[t[2]] - p0);
    areas_[f] = 0.5 * cross.norm();
    centroids_[f] = (p0 + positions[t[1]] + positions[t[2]]) / 3.0;
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || !(areas_[f] > min_area)) {
      degenerate_[f] = true;
      ++num_degenerate_;
      continue;
    }
    normals_[f] = cross.normalized();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d a = positions[t[(k + 1) % 3]] - positions[t[k]];
      const Eigen::Vector3d b = positions[t[(k + 2) % 3]] - positions[t[k]];
      angles_[f][k] = std::atan2(a.cross(b).norm(), a.dot(b));
    }
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      halfedges.push_back({std::min(a, b), std::max(a, b), f, e, a < b});
      vertex_faces_[t[e]].push_back(f);
    }
  }
  std::sort(halfedges.begin(), halfedges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.lo != y.lo ? x.lo < y.lo : (x.hi != y.hi ? x.hi < y.hi : x.face < y.face);
  });
  for (size_t i = 0; i < halfedges.size();) {
    size_t j = i;
    while (j < halfedges.size() && halfedges[j].lo == halfedges[i].lo &&
           halfedges[j].hi == halfedges[i].hi) {
      ++j;
    }
    if (j - i == 2) {
      const HalfEdge& x = halfedges[i];
      const HalfEdge& y = halfedges[i + 1];
      if (x.forward != y.forward) {
        neighbours_[x.face][x.e] = y.face;
        neighbours_[y.face][y.e] = x.face;
      } else {
        ++num_inconsistent_edges_;
      }
    } else if (j - i > 2) {
      ++num_nonmanifold_edges_;
    }
    i = j;
  }
}

}  // namespace sft
