// Laplacian regulariser on vertex positions (the Gauss–Newton analogue of "Large Steps"
// preconditioning).
//
// Residual (3 residuals, one per coordinate), for vertex i with one-ring neighbours j = 1..n:
//
//   r_i = w · (p_i − Σ_j w_ij · p_j − c_i)
//
// with c_i = 0 (the Laplacian of the shape: it smooths and shrinks it) or, with
// `relative_to_rest`, c_i = the same Laplacian of the rest mesh (the Laplacian of the
// displacement from the rest mesh: it smooths the update and leaves the rest shape's detail).
//
// where w is the term's weight and the w_ij are fixed numbers chosen when the block is built:
//   uniform:    w_ij = 1/n (umbrella operator);
//   cotangent:  w_ij = c_ij / Σ_k c_ik, c_ij = (cot α_ij + cot β_ij)/2, α_ij and β_ij the angles
//               opposite the edge ij in its two faces (one face at a boundary edge), measured on
//               the *rest* mesh handed to the builder. Single c_ij are negative across obtuse
//               angles, but each face adds sin α/(sin β·sin γ)/2 > 0 to Σ_k c_ik (α its angle at
//               i), so the sum is positive unless every face of the ring is degenerate (a
//               degenerate corner contributes no cotangent); then (Σ_k c_ik ≤ 1e-9 · Σ_k |c_ik|)
//               the vertex falls back to uniform weights.
// Both kinds have Σ_j w_ij = 1, so r_i is invariant under translation and zero for a vertex at the
// weighted average of its ring: any interior vertex of a planar uniform grid (uniform) or of any
// planar mesh (cotangent). On a curved surface the cotangent residual points along the normal
// (at the rest mesh it is the discrete mean-curvature normal divided by Σ_k c_ik), while the
// uniform one also has tangential parts that even out the vertex distribution.
//
// Why fixed weights: the residual is then linear in the positions, the term is an ordinary linear
// least-squares term whose Jacobian is constant, and Gauss–Newton/Levenberg–Marquardt sees a fixed
// (I − W) operator, which is what makes it act as a preconditioner-like smoother of the rendering
// gradient ("Large Steps", Nicolet et al. 2021, use the fixed matrix I + λL). Recomputing the
// cotangents from the current positions would make the term nonlinear, and its exact Jacobian
// would need ∂w_ij/∂p, negligible only while the mesh stays near the rest mesh.
// Rebuild the blocks (from the current mesh as the new rest mesh) after remeshing or large motion.
//
// Parameter blocks: [p_i, p_j1, ..., p_jn], each 3 doubles (x, y, z), in that order.
// Jacobians: ∂r/∂p_i = w·I₃, ∂r/∂p_j = −w·w_ij·I₃ (exact: the residual is linear).
// Evaluate never returns false.
// Derivative terms it does not have: the dependence of the cotangent weights on the positions
// (they are constants by construction; see above).
#ifndef SFT_COST_FUNCTIONS_VERTEX_LAPLACIAN_H_
#define SFT_COST_FUNCTIONS_VERTEX_LAPLACIAN_H_

#include <ceres/cost_function.h>
#include <ceres/problem.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/geometry/mesh.h"

namespace sft {

enum class LaplacianKind { kUniform, kCotangent };

// One vertex's Laplacian stencil: r = w·(p_vertex − Σ_k weights[k]·p_neighbours[k]).
struct LaplacianStencil {
  int vertex = -1;
  std::vector<int> neighbours;  // one-ring vertex indices, in OpenMesh's circulator order.
  std::vector<double> weights;  // w_ij, summing to 1.
};

// The cost function of one stencil (see the top comment). `neighbour_weights` are the w_ij.
class VertexLaplacianCost : public ceres::CostFunction {
 public:
  VertexLaplacianCost(double weight, std::vector<double> neighbour_weights);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // c_i of the top comment (zero unless set).
  void set_rest_laplacian(const Eigen::Vector3d& c) { rest_laplacian_ = c; }

 private:
  double weight_;
  std::vector<double> neighbour_weights_;
  Eigen::Vector3d rest_laplacian_ = Eigen::Vector3d::Zero();
};

struct VertexLaplacianOptions {
  LaplacianKind kind = LaplacianKind::kCotangent;  // weights w_ij (see the top comment).
  // w, multiplying every residual; finite, ≥ 0. The residual has units of length, so the right
  // weight depends on the scene's scale and on the data term's magnitude.
  double weight = 1.0;
  // Whether boundary vertices get a residual. Their ring is one-sided, so the residual pulls them
  // inwards even on a flat mesh (an open boundary would shrink): off by default.
  bool include_boundary = false;
  // Whether residuals measure the Laplacian of the displacement from `rest` (c_i above) rather
  // than of the shape.
  bool relative_to_rest = false;

  bool Check(std::string* why) const;
};

// The stencils of every vertex that gets a residual: vertices with at least one neighbour, and not
// on a boundary unless options.include_boundary. Weights are computed from `rest`'s positions.
std::vector<LaplacianStencil> LaplacianStencils(const TriMesh& rest,
                                                const VertexLaplacianOptions& options);

// Adds one VertexLaplacianCost residual block per stencil of `rest` to `problem` (which takes
// ownership of the cost functions). `vertex_blocks[v]` is vertex v's parameter block (3 doubles);
// there must be one per vertex of `rest` (CHECK). Returns the number of blocks added. Options must
// pass Check (CHECK).
int AddVertexLaplacian(const TriMesh& rest, const VertexLaplacianOptions& options,
                       const std::vector<double*>& vertex_blocks, ceres::Problem* problem);

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_VERTEX_LAPLACIAN_H_
