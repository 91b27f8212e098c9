#include "src/optim/large_steps.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <string>

namespace sft {

struct LargeSteps::Matrix {
  Eigen::SparseMatrix<double> m;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
};

namespace {
// The interleaved coordinates as an n × 3 row-major block.
using Coordinates = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
}  // namespace

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
  std::unique_ptr<LargeSteps> steps(new LargeSteps());
  steps->m_ = std::make_unique<Matrix>();
  steps->m_->m.resize(n, n);
  steps->m_->m.setFromTriplets(triplets.begin(), triplets.end());
  steps->m_->ldlt.compute(steps->m_->m);
  if (steps->m_->ldlt.info() != Eigen::Success) {
    return Status::Error("large steps: the factorization of I + lambda L failed");
  }
  *out = std::move(steps);
  return Status::Ok();
}

void LargeSteps::ToU(const double* x, double* u) const {
  const Eigen::MatrixXd result = m_->m * Eigen::Map<const Coordinates>(x, m_->m.rows(), 3);
  Eigen::Map<Coordinates>(u, m_->m.rows(), 3) = result;
}

void LargeSteps::ToX(const double* u, double* x) const {
  // The solution is formed before x is written, so u and x may alias.
  const Eigen::MatrixXd result =
      m_->ldlt.solve(Eigen::MatrixXd(Eigen::Map<const Coordinates>(u, m_->m.rows(), 3)));
  Eigen::Map<Coordinates>(x, m_->m.rows(), 3) = result;
}

}  // namespace sft
