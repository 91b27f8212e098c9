// Angle-weighted vertex normals for smooth shading (Shading::kSmooth in render.h): the normal of
// a welded vertex is the normalized sum over the faces around it of θ·n̂, θ the face's interior
// angle at the vertex and n̂ its unit normal (Thürmer and Wüthrich 1998, "Computing vertex
// normals from polygonal facets"; Blender's vertex normals). Unlike area weighting it does not
// change when a face is split, so a remeshed surface keeps its shading.
#ifndef SFT_RENDER_VERTEX_NORMALS_H_
#define SFT_RENDER_VERTEX_NORMALS_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

namespace sft {

// θ·n̂ of the corner at p with neighbours a, b (counter-clockwise: n̂ ∝ (a − p) × (b − p)),
// θ = atan2(|e1 × e2|, e1·e2) ∈ [0, π]. Zero for a degenerate corner (|e1 × e2| = 0), which has
// no normal. Templated so that ceres::Jet gives its derivatives (VertexNormalJacobian).
template <typename T>
Eigen::Matrix<T, 3, 1> CornerNormalTerm(const Eigen::Matrix<T, 3, 1>& p,
                                        const Eigen::Matrix<T, 3, 1>& a,
                                        const Eigen::Matrix<T, 3, 1>& b) {
  using std::atan2;
  using std::sqrt;
  const Eigen::Matrix<T, 3, 1> e1 = a - p, e2 = b - p;
  const Eigen::Matrix<T, 3, 1> c = e1.cross(e2);
  const T s2 = c.squaredNorm();
  if (!(s2 > T(0.0))) return Eigen::Matrix<T, 3, 1>::Zero();
  const T s = sqrt(s2);
  const T theta = atan2(s, e1.dot(e2));
  return c * (theta / s);
}

// The unnormalized sums S_w = Σ θ·n̂ per vertex index `welded[v]` (entries of vertices that are
// not a welded representative stay zero). `faces` index `positions`; welded[v] ≤ v.
void AngleWeightedNormalSums(const std::vector<Eigen::Vector3d>& positions,
                             const std::vector<Eigen::Vector3i>& faces,
                             const std::vector<int>& welded, std::vector<Eigen::Vector3d>* sums);

}  // namespace sft

#endif  // SFT_RENDER_VERTEX_NORMALS_H_
