#include "src/optim/large_steps.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <string>

namespace sft {

struct LargeSteps::Factor {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
};

LargeSteps::~LargeSteps() = default;

Status LargeSteps::Create(const std::vector<std::vector<int>>& neighbours, double lambda,
                          std::unique_ptr<LargeSteps>* out) {
  if (!(std::isfinite(lambda) && lambda >= 0.0)) {
    return Status::Error("large steps: lambda must be finite and >= 0");
  }
  const int n = static_cast<int>(neighbours.size());
  std::vector<Eigen::Triplet<double>> triplets;
  for (int i = 0; i < n; ++i) {
    const std::vector<int>& ring = neighbours[i];
    triplets.emplace_back(i, i, 1.0 + lambda * static_cast<double>(ring.size()));
    for (int j : ring) {
      if (j < 0 || j >= n || j == i ||
          !std::binary_search(neighbours[j].begin(), neighbours[j].end(), i)) {
        return Status::Error("large steps: vertex " + std::to_string(i) +
                             " has an invalid or one-sided neighbour " + std::to_string(j));
      }
      triplets.emplace_back(i, j, -lambda);
    }
  }
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(triplets.begin(), triplets.end());
  std::unique_ptr<LargeSteps> steps(new LargeSteps());
  steps->factor_ = std::make_unique<Factor>();
  steps->factor_->ldlt.compute(m);
  if (steps->factor_->ldlt.info() != Eigen::Success) {
    return Status::Error("large steps: the factorization of I + lambda L failed");
  }
  steps->num_vertices_ = n;
  steps->lambda_ = lambda;
  steps->neighbours_ = neighbours;
  *out = std::move(steps);
  return Status::Ok();
}

void LargeSteps::ToU(const double* x, double* u) const {
  for (int i = 0; i < num_vertices_; ++i) {
    const std::vector<int>& ring = neighbours_[i];
    for (int k = 0; k < 3; ++k) {
      double sum = 0.0;
      for (int j : ring) sum += x[3 * j + k];
      u[3 * i + k] =
          x[3 * i + k] + lambda_ * (static_cast<double>(ring.size()) * x[3 * i + k] - sum);
    }
  }
}

void LargeSteps::ToX(const double* u, double* x) const {
  // The interleaved coordinates as an n × 3 row-major block: one solve with three right sides.
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  const Eigen::Map<const RowMajor> rhs(u, num_vertices_, 3);
  const Eigen::MatrixXd solution = factor_->ldlt.solve(Eigen::MatrixXd(rhs));
  Eigen::Map<RowMajor>(x, num_vertices_, 3) = solution;
}

}  // namespace sft
