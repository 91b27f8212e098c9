#include "cost_functions/vertex_laplacian.h"

#include <glog/logging.h>

#include <cmath>
#include <utility>

namespace sft {
namespace {

// Below this Σ c_ik / Σ |c_ik| a vertex's cotangent weights are not usable (see the header).
constexpr double kMinCotangentSum = 1e-9;
// A face whose corner has |u × v| ≤ this · |u|·|v| is treated as degenerate: no cotangent.
constexpr double kDegenerateSine = 1e-12;

Eigen::Vector3d Position(const TriMesh& mesh, TriMesh::VertexHandle v) {
  const TriMesh::Point& p = mesh.point(v);
  return Eigen::Vector3d(p[0], p[1], p[2]);
}

// cot of the angle at `apex` between the directions to a and b; 0 for a degenerate corner.
double Cotangent(const Eigen::Vector3d& apex, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d u = a - apex, v = b - apex;
  const double sine = u.cross(v).norm();
  if (!(sine > kDegenerateSine * u.norm() * v.norm())) return 0.0;
  return u.dot(v) / sine;
}

// (cot α + cot β)/2 for the edge of the outgoing halfedge h (i → j), over its one or two faces.
double EdgeCotangentWeight(const TriMesh& mesh, TriMesh::HalfedgeHandle h) {
  const Eigen::Vector3d pi = Position(mesh, mesh.from_vertex_handle(h));
  const Eigen::Vector3d pj = Position(mesh, mesh.to_vertex_handle(h));
  double sum = 0.0;
  for (TriMesh::HalfedgeHandle side : {h, mesh.opposite_halfedge_handle(h)}) {
    if (mesh.is_boundary(side)) continue;  // no face on this side.
    const Eigen::Vector3d apex =
        Position(mesh, mesh.to_vertex_handle(mesh.next_halfedge_handle(side)));
    sum += Cotangent(apex, pi, pj);
  }
  return 0.5 * sum;
}

}  // namespace

VertexLaplacianCost::VertexLaplacianCost(double weight, std::vector<double> neighbour_weights)
    : weight_(weight), neighbour_weights_(std::move(neighbour_weights)) {
  CHECK(!neighbour_weights_.empty()) << "VertexLaplacianCost: no neighbours";
  set_num_residuals(3);
  mutable_parameter_block_sizes()->assign(neighbour_weights_.size() + 1, 3);
}

bool VertexLaplacianCost::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  for (int c = 0; c < 3; ++c) residuals[c] = parameters[0][c];
  for (size_t k = 0; k < neighbour_weights_.size(); ++k) {
    for (int c = 0; c < 3; ++c) residuals[c] -= neighbour_weights_[k] * parameters[k + 1][c];
  }
  for (int c = 0; c < 3; ++c) residuals[c] = weight_ * (residuals[c] - rest_laplacian_[c]);
  if (jacobians == nullptr) return true;
  // Row-major 3×3 blocks: ∂r_c/∂p_d = scale·δ_cd.
  const auto fill = [](double* jacobian, double scale) {
    for (int e = 0; e < 9; ++e) jacobian[e] = (e % 4 == 0) ? scale : 0.0;
  };
  if (jacobians[0] != nullptr) fill(jacobians[0], weight_);
  for (size_t k = 0; k < neighbour_weights_.size(); ++k) {
    if (jacobians[k + 1] != nullptr) fill(jacobians[k + 1], -weight_ * neighbour_weights_[k]);
  }
  return true;
}

bool VertexLaplacianOptions::Check(std::string* why) const {
  if (!(weight >= 0.0 && std::isfinite(weight))) {
    *why = "weight: must be finite and >= 0, got " + std::to_string(weight);
    return false;
  }
  return true;
}

std::vector<LaplacianStencil> LaplacianStencils(const TriMesh& rest,
                                                const VertexLaplacianOptions& options) {
  std::vector<LaplacianStencil> stencils;
  for (TriMesh::VertexHandle v : rest.vertices()) {
    if (!options.include_boundary && rest.is_boundary(v)) continue;
    LaplacianStencil s;
    s.vertex = v.idx();
    double sum = 0.0, abs_sum = 0.0;
    for (TriMesh::HalfedgeHandle h : rest.voh_range(v)) {
      s.neighbours.push_back(rest.to_vertex_handle(h).idx());
      const double c =
          options.kind == LaplacianKind::kCotangent ? EdgeCotangentWeight(rest, h) : 1.0;
      s.weights.push_back(c);
      sum += c;
      abs_sum += std::abs(c);
    }
    if (s.neighbours.empty()) continue;  // isolated vertex: nothing to average.
    const bool usable = sum > kMinCotangentSum * abs_sum && std::isfinite(sum);
    for (double& w : s.weights) w = usable ? w / sum : 1.0 / s.neighbours.size();
    stencils.push_back(std::move(s));
  }
  return stencils;
}

int AddVertexLaplacian(const TriMesh& rest, const VertexLaplacianOptions& options,
                       const std::vector<double*>& vertex_blocks, ceres::Problem* problem) {
  std::string why;
  CHECK(options.Check(&why)) << "AddVertexLaplacian: " << why;
  CHECK_EQ(vertex_blocks.size(), rest.n_vertices()) << "AddVertexLaplacian: one block per vertex";
  const std::vector<LaplacianStencil> stencils = LaplacianStencils(rest, options);
  std::vector<double*> blocks;
  for (const LaplacianStencil& s : stencils) {
    blocks.clear();
    blocks.push_back(vertex_blocks[s.vertex]);
    for (int n : s.neighbours) blocks.push_back(vertex_blocks[n]);
    auto* cost = new VertexLaplacianCost(options.weight, s.weights);
    if (options.relative_to_rest) {
      // L(p_rest)_i: the residual then measures the Laplacian of the displacement.
      Eigen::Vector3d rest_laplacian = Eigen::Vector3d::Zero();
      const auto at = [&](int v) {
        const auto p = rest.point(rest.vertex_handle(v));
        return Eigen::Vector3d(p[0], p[1], p[2]);
      };
      rest_laplacian = at(s.vertex);
      for (size_t k = 0; k < s.neighbours.size(); ++k) {
        rest_laplacian -= s.weights[k] * at(s.neighbours[k]);
      }
      cost->set_rest_laplacian(rest_laplacian);
    }
    problem->AddResidualBlock(cost, nullptr, blocks);
  }
  return static_cast<int>(stencils.size());
}

}  // namespace sft
