// A hinge that keeps triangles from folding over during geometry fits. For face f with vertices
// (p0, p1, p2), unit normal n̂ and area A of the phase's starting mesh, the signed area of the face
// projected on n̂ is a(p) = n̂ · ((p1 − p0) × (p2 − p0)) / 2, and
//
//   r_f = w · min(0, a(p)/A − τ)            (1 residual)
//
// is zero while the face keeps more than τ of its area facing the way it faced at the start, and
// grows linearly as it shrinks towards and past zero (a fold). τ = `min_fraction`, in (0, 1).
//
// Parameter blocks: p0, p1, p2 (3 doubles each), in the face's vertex order.
// Jacobians: exact (automatic differentiation); at a(p)/A = τ the one-sided derivative of the
// active side (zero) is used. Evaluate returns false when the rest face is degenerate (A ≤ 0),
// which AddFaceOrientation never builds. Derivative terms it does not have: none (n̂ and A are
// constants by construction).
#ifndef SFT_COST_FUNCTIONS_FACE_ORIENTATION_H_
#define SFT_COST_FUNCTIONS_FACE_ORIENTATION_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/problem.h>

#include <Eigen/Core>
#include <vector>

#include "src/geometry/mesh.h"

namespace sft {

struct FaceOrientationResidual {
  FaceOrientationResidual(const Eigen::Vector3d& rest_normal, double rest_area, double weight,
                          double min_fraction)
      : n(rest_normal), area(rest_area), w(weight), tau(min_fraction) {}

  template <typename T>
  bool operator()(const T* p0, const T* p1, const T* p2, T* residual) const {
    if (!(area > 0.0)) return false;
    const T u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const T v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const T cross[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                        u[0] * v[1] - u[1] * v[0]};
    const T fraction = (n[0] * cross[0] + n[1] * cross[1] + n[2] * cross[2]) / (2.0 * area);
    residual[0] = fraction < T(tau) ? T(w) * (fraction - T(tau)) : T(0.0);
    return true;
  }

  Eigen::Vector3d n;
  double area;
  double w;
  double tau;
};

struct FaceOrientationOptions {
  double weight = 10.0;        // w, finite, ≥ 0; 0 adds nothing.
  double min_fraction = 0.25;  // τ, in (0, 1).
};

// One residual per non-degenerate face of `rest` (area > 1e-12 × squared bounding-box diagonal).
// `vertex_blocks[v]` is vertex v's parameter block. Returns the number of blocks added.
int AddFaceOrientation(const TriMesh& rest, const FaceOrientationOptions& options,
                       const std::vector<double*>& vertex_blocks, ceres::Problem* problem);

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_FACE_ORIENTATION_H_
