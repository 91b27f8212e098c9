#include "src/render/internal/vertex_normal_jacobian.h"

#include <ceres/jet.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "src/render/internal/scene_state_cache.h"
#include "src/render/vertex_normals.h"

namespace sft {
namespace render_internal {
namespace {

using Jet9 = ceres::Jet<double, 9>;

struct Triplet {
  int welded;
  int vertex;
  Eigen::Matrix3d d;
};

// ∂(θ·n̂)/∂(p, a, b) of one corner: 3 × 9, columns 3·i + k for coordinate k of p, a, b.
Eigen::Matrix<double, 3, 9> CornerTermJacobian(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                               const Eigen::Vector3d& b) {
  Eigen::Matrix<Jet9, 3, 1> q[3];
  const Eigen::Vector3d* points[3] = {&p, &a, &b};
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) q[i][k] = Jet9((*points[i])[k], 3 * i + k);
  }
  const Eigen::Matrix<Jet9, 3, 1> term = CornerNormalTerm<Jet9>(q[0], q[1], q[2]);
  Eigen::Matrix<double, 3, 9> jacobian;
  for (int r = 0; r < 3; ++r) jacobian.row(r) = term[r].v.transpose();
  return jacobian;
}

}  // namespace

VertexNormalJacobian::VertexNormalJacobian(const RenderScene& scene) {
  const auto& positions = scene.positions();
  const auto& faces = scene.faces();
  const int num_vertices = static_cast<int>(positions.size());
  welded_.resize(num_vertices);
  for (int v = 0; v < num_vertices; ++v) welded_[v] = scene.WeldedVertex(v);
  std::vector<Eigen::Vector3d> sums;
  AngleWeightedNormalSums(positions, faces, welded_, &sums);
  std::vector<Triplet> triplets;
  triplets.reserve(9 * faces.size());
  for (const Eigen::Vector3i& f : faces) {
    for (int k = 0; k < 3; ++k) {
      const int corner[3] = {f[k], f[(k + 1) % 3], f[(k + 2) % 3]};
      const int w = welded_[corner[0]];
      const double len = sums[w].norm();
      if (!(len > 0.0) || !std::isfinite(len)) continue;
      const Eigen::Vector3d unit = sums[w] / len;
      const Eigen::Matrix3d projection =
          (Eigen::Matrix3d::Identity() - unit * unit.transpose()) / len;
      const Eigen::Matrix<double, 3, 9> jacobian =
          CornerTermJacobian(positions[corner[0]], positions[corner[1]], positions[corner[2]]);
      if (!jacobian.allFinite()) continue;
      for (int i = 0; i < 3; ++i) {
        triplets.push_back({w, corner[i], projection * jacobian.middleCols<3>(3 * i)});
      }
    }
  }
  std::sort(triplets.begin(), triplets.end(), [](const Triplet& x, const Triplet& y) {
    return std::tie(x.welded, x.vertex) < std::tie(y.welded, y.vertex);
  });
  offsets_.assign(num_vertices + 1, 0);
  for (size_t i = 0; i < triplets.size(); ++i) {
    const Triplet& t = triplets[i];
    if (i > 0 && t.welded == triplets[i - 1].welded && t.vertex == triplets[i - 1].vertex) {
      entries_.back().d += t.d;
      continue;
    }
    entries_.push_back({t.vertex, t.d});
    ++offsets_[t.welded + 1];
  }
  for (int v = 0; v < num_vertices; ++v) offsets_[v + 1] += offsets_[v];
}

std::shared_ptr<const VertexNormalJacobian> VertexNormalJacobian::Of(const RenderScene& scene) {
  return LastBuildFor<VertexNormalJacobian>(scene);
}

}  // namespace render_internal
}  // namespace sft
