// The large-steps reparameterisation of vertex positions for first-order solvers (Nicolet,
// Jacobson and Jakob 2021, "Large Steps in Inverse Rendering of Geometry", ACM TOG 40(6)).
//
// The solver moves u = M x instead of the positions x, with M = I + λL and L = D − A the
// combinatorial graph Laplacian of the mesh ((Lx)_i = deg_i·x_i − Σ_{j∈N(i)} x_j), applied to
// each coordinate separately. M is symmetric positive definite, so the gradient with respect to u
// is M⁻¹ times the gradient with respect to x: a step in u moves x by M⁻¹·(step), which damps the
// high-frequency (rough) modes of the step by up to (1 + λ·2·deg) and keeps the smooth ones. This
// is what lets gradient descent take large steps without tangling the surface. The paper uses
// λ between 19 and 49; Mitsuba 3's shape tutorial uses 25.
//
// Positions are interleaved as the parameter layout stores them (vertex v, coordinate k at
// 3v + k). The factorization is a sparse LDLᵀ (Eigen), built by Create (Adam builds one per
// phase, for the mesh connectivity of that phase).
#ifndef SFT_OPTIM_LARGE_STEPS_H_
#define SFT_OPTIM_LARGE_STEPS_H_

#include <memory>
#include <vector>

#include "src/core/status.h"

namespace sft {

class LargeSteps {
 public:
  // `neighbours`: the distinct one-ring of every vertex (VertexNeighbours), symmetric (j in N(i)
  // iff i in N(j)); `lambda` finite, ≥ 0. Fails on an asymmetric or out-of-range neighbour list,
  // or when the factorization fails.
  static Status Create(const std::vector<std::vector<int>>& neighbours, double lambda,
                       std::unique_ptr<LargeSteps>* out);
  ~LargeSteps();

  // u = M x, for 3 × (vertex count) interleaved coordinates. x and u may be the same array.
  void ToU(const double* x, double* u) const;
  // x = M⁻¹ u. u and x may be the same array.
  void ToX(const double* u, double* x) const;
  // M⁻¹ g: the gradient with respect to u from the gradient g with respect to x.
  void GradientToU(const double* g, double* out) const { ToX(g, out); }

 private:
  struct Matrix;  // M and its factorization.
  LargeSteps() = default;
  std::unique_ptr<Matrix> m_;
};

}  // namespace sft

#endif  // SFT_OPTIM_LARGE_STEPS_H_
