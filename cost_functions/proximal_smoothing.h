// A smoothing proximal term on vertex positions: the Levenberg–Marquardt form of the "large steps"
// preconditioner of Nicolet, Jacobson and Jakob 2021, "Large Steps in Inverse Rendering of
// Geometry" (ACM TOG 40(6), SIGGRAPH Asia), which descends in u = (I + λL)x instead of x.
//
// Residual (3 residuals, one per coordinate), for vertex i with its distinct one-ring neighbours
// j ∈ N(i), deg_i = |N(i)|:
//
//   r_i = w · ((I + λL)(x − a))_i = w · ((1 + λ·deg_i)(x_i − a_i) − λ Σ_{j∈N(i)} (x_j − a_j))
//
// with w = √μ the term's weight, λ ≥ 0 the smoothing strength, a the anchor (the vertex
// positions the blocks were built from) and L = D − A the combinatorial (uniform, unnormalised)
// graph Laplacian of the mesh: (Lx)_i = deg_i·x_i − Σ_{j∈N(i)} x_j. This is the L of the paper's
// method as its authors' code builds it (rgl-epfl/large-steps-pytorch, largesteps/geometry.py,
// laplacian_uniform: −1 per edge, the vertex degree on the diagonal); note it is not the
// row-normalised I − W of cost_functions/vertex_laplacian.h. Every vertex gets a residual,
// boundary and isolated ones included (deg_i = 0 gives w·(x_i − a_i)): the stack of all residuals
// is w·M(x − a) with M = I + λL symmetric positive definite.
//
// Why it is the large-steps update: a Gauss–Newton/LM step δ minimises ½‖Jδ + f‖² + ½μ‖Mδ‖²
// (at the anchor). For large μ the data term is nearly linear over the step and
// δ ≈ −μ⁻¹ M⁻² Jᵀf = −μ⁻¹ (I + λL)⁻² ∇, which is the x-space step of gradient descent in
// u = Mx (∂/∂u = M⁻¹∂/∂x and δx = M⁻¹δu, M symmetric): high frequencies of the gradient are damped
// by (1 + λσ)⁻² (σ an eigenvalue of L), the smooth ones pass. λ = 0 gives plain Tikhonov damping
// μ‖δ‖².
//
// The anchor is fixed when the blocks are built. The reconstruction builds them at the start of
// every Ceres Solve (each outer iteration and phase), so the term is re-anchored per outer
// iteration; it is not re-anchored at each accepted step inside a Solve, because Ceres keeps the
// cost of the current point across iterations and compares it with the trial's: changing the
// objective inside a Solve would corrupt the gain ratio (actual vs. predicted decrease).
//
// Parameter blocks: [x_i, x_j1, ..., x_jn], each 3 doubles (x, y, z); the neighbours distinct,
// in increasing vertex index.
// Jacobians (hand-written: the residual is linear, the Jacobian constant and exact; autodiff over
// a variable number of blocks would only add cost): ∂r/∂x_i = w(1 + λ·deg_i)·I₃,
// ∂r/∂x_j = −wλ·I₃.
// Evaluate never returns false.
// Derivative terms it does not have: none (M and a are constants by construction).
#ifndef SFT_COST_FUNCTIONS_PROXIMAL_SMOOTHING_H_
#define SFT_COST_FUNCTIONS_PROXIMAL_SMOOTHING_H_

#include <ceres/cost_function.h>
#include <ceres/problem.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/geometry/mesh.h"

namespace sft {

// The cost function of vertex i (see the top comment).
class ProximalSmoothingCost : public ceres::CostFunction {
 public:
  // `anchors` = [a_i, a_j1, ..., a_jn], in the order of the parameter blocks; deg_i = n.
  ProximalSmoothingCost(double weight, double lambda, std::vector<Eigen::Vector3d> anchors);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double weight_;
  double lambda_;
  // Differences x − a are formed before M is applied: no cancellation, and exactly zero at a.
  std::vector<Eigen::Vector3d> anchors_;
};

struct ProximalSmoothingOptions {
  // w = √μ, multiplying every residual; finite, ≥ 0. The residual has units of length.
  double weight = 1.0;
  // λ, the smoothing strength of M = I + λL (dimensionless: L counts neighbours); finite, ≥ 0.
  // Nicolet et al. use values between 19 and 49; Mitsuba 3's shape-optimisation tutorial uses 25.
  double lambda = 25.0;

  bool Check(std::string* why) const;
};

// The distinct one-ring neighbours of every vertex of `mesh`, each list increasing.
std::vector<std::vector<int>> VertexNeighbours(const TriMesh& mesh);

// Adds one ProximalSmoothingCost block per vertex of `anchor` to `problem` (which takes ownership
// of the cost functions); the anchor a is `anchor`'s positions. `vertex_blocks[v]` is vertex v's
// parameter block (3 doubles); there must be one per vertex (CHECK). Options must pass Check
// (CHECK). Returns the number of blocks added.
int AddProximalSmoothing(const TriMesh& anchor, const ProximalSmoothingOptions& options,
                         const std::vector<double*>& vertex_blocks, ceres::Problem* problem);

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_PROXIMAL_SMOOTHING_H_
