#include "src/render/internal/mesh_edge_table.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>

#include "src/render/internal/edge_sampling.h"
#include "src/render/internal/sampling.h"

namespace sft {
namespace render_internal {

MeshEdgeTable::MeshEdgeTable(const RenderScene& scene) {
  const auto& positions = scene.positions();
  std::vector<double> lengths;
  for (size_t e = 0; e < scene.edges().size(); ++e) {
    const MeshEdge& edge = scene.edges()[e];
    const double length = (positions[edge.v1] - positions[edge.v0]).norm();
    if (!(length > 0.0) || !std::isfinite(length)) continue;
    Record r;
    r.a = positions[edge.v0].cast<float>();
    r.b = positions[edge.v1].cast<float>();
    r.n0.setZero();
    r.n1.setZero();
    r.f0 = edge.f0;
    r.f1 = edge.f1;
    if (edge.num_faces == 2) {
      Eigen::Vector3d n0, n1;
      ConsistentEdgeNormals(scene, edge, &n0, &n1);
      // Coplanar neighbours (consistently oriented): never a silhouette nor a crease.
      if (!n0.isZero() && !n1.isZero() && n0.dot(n1) > 1.0 - 1e-12) continue;
      if (!n0.isZero() && !n1.isZero()) {
        r.n0 = n0.cast<float>();
        r.n1 = n1.cast<float>();
      }
      r.crease = std::abs(n0.dot(n1)) < 1.0 - 1e-12 ? 1.0f : 0.0f;
    }
    records_.push_back(r);
    edges_.push_back(static_cast<int>(e));
    lengths.push_back(length);
  }
  const DiscreteDistribution by_length(lengths);
  if (by_length.empty()) {
    records_.clear();
    edges_.clear();
    return;
  }
  cells_.resize(records_.size());
  for (size_t i = 0; i < records_.size(); ++i) {
    const int index = static_cast<int>(i);
    cells_[i] = {static_cast<float>(by_length.cell(index).probability),
                 by_length.cell(index).alias};
    records_[i].inverse_probability = static_cast<float>(by_length.InverseProbability(index));
  }
}

std::shared_ptr<const MeshEdgeTable> MeshEdgeTable::Of(const RenderScene& scene) {
  // The last build, shared by every view of a pass and both passes of an evaluation.
  static std::mutex mutex;
  static uint64_t cached_state = 0;
  static std::shared_ptr<const MeshEdgeTable> cached;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (cached != nullptr && cached_state == scene.state_id()) return cached;
  }
  auto built = std::make_shared<const MeshEdgeTable>(scene);
  std::lock_guard<std::mutex> lock(mutex);
  cached_state = scene.state_id();
  cached = built;
  return built;
}

}  // namespace render_internal
}  // namespace sft
