#include "cost_functions/proximal_smoothing.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace sft {

ProximalSmoothingCost::ProximalSmoothingCost(double weight, double lambda,
                                             std::vector<Eigen::Vector3d> anchors)
    : weight_(weight), lambda_(lambda), anchors_(std::move(anchors)) {
  CHECK(!anchors_.empty()) << "ProximalSmoothingCost: no anchor for the vertex itself";
  set_num_residuals(3);
  mutable_parameter_block_sizes()->assign(anchors_.size(), 3);
}

bool ProximalSmoothingCost::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const int degree = static_cast<int>(anchors_.size()) - 1;
  const double diagonal = 1.0 + lambda_ * degree;
  Eigen::Vector3d neighbour_sum = Eigen::Vector3d::Zero();
  for (int k = 1; k <= degree; ++k) {
    neighbour_sum += Eigen::Map<const Eigen::Vector3d>(parameters[k]) - anchors_[k];
  }
  const Eigen::Vector3d own = Eigen::Map<const Eigen::Vector3d>(parameters[0]) - anchors_[0];
  const Eigen::Vector3d r = weight_ * (diagonal * own - lambda_ * neighbour_sum);
  for (int c = 0; c < 3; ++c) residuals[c] = r[c];
  if (jacobians == nullptr) return true;
  // Row-major 3×3 blocks: ∂r_c/∂x_d = scale·δ_cd.
  const auto fill = [](double* jacobian, double scale) {
    for (int e = 0; e < 9; ++e) jacobian[e] = (e % 4 == 0) ? scale : 0.0;
  };
  if (jacobians[0] != nullptr) fill(jacobians[0], weight_ * diagonal);
  for (int k = 1; k <= degree; ++k) {
    if (jacobians[k] != nullptr) fill(jacobians[k], -weight_ * lambda_);
  }
  return true;
}

bool ProximalSmoothingOptions::Check(std::string* why) const {
  if (!(weight >= 0.0 && std::isfinite(weight))) {
    *why = "weight: must be finite and >= 0, got " + std::to_string(weight);
    return false;
  }
  if (!(lambda >= 0.0 && std::isfinite(lambda))) {
    *why = "lambda: must be finite and >= 0, got " + std::to_string(lambda);
    return false;
  }
  return true;
}

std::vector<std::vector<int>> VertexNeighbours(const TriMesh& mesh) {
  std::vector<std::vector<int>> neighbours(mesh.n_vertices());
  for (TriMesh::VertexHandle v : mesh.vertices()) {
    std::vector<int>& ring = neighbours[v.idx()];
    for (TriMesh::HalfedgeHandle h : mesh.voh_range(v)) {
      const int j = mesh.to_vertex_handle(h).idx();
      if (j != v.idx()) ring.push_back(j);
    }
    // Ceres refuses a block twice in one residual; L = D − A counts each neighbour once.
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  }
  return neighbours;
}

int AddProximalSmoothing(const TriMesh& anchor, const ProximalSmoothingOptions& options,
                         const std::vector<double*>& vertex_blocks, ceres::Problem* problem) {
  std::string why;
  CHECK(options.Check(&why)) << "AddProximalSmoothing: " << why;
  CHECK_EQ(vertex_blocks.size(), anchor.n_vertices())
      << "AddProximalSmoothing: one block per vertex";
  const auto at = [&](int v) {
    const TriMesh::Point& p = anchor.point(anchor.vertex_handle(v));
    return Eigen::Vector3d(p[0], p[1], p[2]);
  };
  const std::vector<std::vector<int>> neighbours = VertexNeighbours(anchor);
  std::vector<double*> blocks;
  for (int i = 0; i < static_cast<int>(neighbours.size()); ++i) {
    std::vector<Eigen::Vector3d> anchors = {at(i)};
    blocks.assign(1, vertex_blocks[i]);
    for (int j : neighbours[i]) {
      anchors.push_back(at(j));
      blocks.push_back(vertex_blocks[j]);
    }
    problem->AddResidualBlock(
        new ProximalSmoothingCost(options.weight, options.lambda, std::move(anchors)), nullptr,
        blocks);
  }
  return static_cast<int>(neighbours.size());
}

}  // namespace sft
