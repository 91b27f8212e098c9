#include "src/render/internal/mesh_edge_table.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "src/render/internal/edge_sampling.h"
#include "src/render/internal/sampling.h"
#include "src/render/internal/scene_state_cache.h"

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
  if (records_.empty()) {
    near_offsets_.assign(scene.faces().size() + 1, 0);
    return;
  }
  std::vector<Eigen::Vector3f> a(records_.size()), b(records_.size());
  std::vector<float> float_lengths(records_.size());
  for (size_t i = 0; i < records_.size(); ++i) {
    a[i] = records_[i].a;
    b[i] = records_[i].b;
    // Clamped into float's range: the tree divides by sums of these.
    float_lengths[i] = static_cast<float>(std::clamp<double>(
        lengths[i], std::numeric_limits<float>::min(), std::numeric_limits<float>::max()));
    records_[i].length = float_lengths[i];
  }
  tree_ = EdgeTree(a, b, float_lengths);
  // Records in the tree's order: record i is tree position i.
  std::vector<Record> records(records_.size());
  std::vector<int> edges(edges_.size());
  for (size_t j = 0; j < records.size(); ++j) {
    records[j] = records_[tree_.order()[j]];
    edges[j] = edges_[tree_.order()[j]];
  }
  records_.swap(records);
  edges_.swap(edges);
  BuildNearLists(scene);
}

void MeshEdgeTable::BuildNearLists(const RenderScene& scene) {
  // Records per welded vertex (CSR), then per face the union over its corners.
  const int num_vertices = static_cast<int>(scene.positions().size());
  std::vector<int> vertex_offsets(num_vertices + 1, 0);
  for (int edge : edges_) {
    ++vertex_offsets[scene.edges()[edge].v0 + 1];
    ++vertex_offsets[scene.edges()[edge].v1 + 1];
  }
  for (int v = 0; v < num_vertices; ++v) vertex_offsets[v + 1] += vertex_offsets[v];
  std::vector<int> vertex_records(vertex_offsets.back());
  std::vector<int> fill(vertex_offsets.begin(), vertex_offsets.end() - 1);
  for (size_t i = 0; i < edges_.size(); ++i) {
    const MeshEdge& edge = scene.edges()[edges_[i]];
    vertex_records[fill[edge.v0]++] = static_cast<int>(i);
    vertex_records[fill[edge.v1]++] = static_cast<int>(i);
  }
  const int num_faces = static_cast<int>(scene.faces().size());
  near_offsets_.assign(num_faces + 1, 0);
  std::vector<int> list;
  for (int f = 0; f < num_faces; ++f) {
    list.clear();
    for (int k = 0; k < 3; ++k) {
      const int v = scene.WeldedVertex(scene.faces()[f][k]);
      for (int j = vertex_offsets[v]; j < vertex_offsets[v + 1]; ++j) {
        const int r = vertex_records[j];
        if (records_[r].f0 != f && records_[r].f1 != f) list.push_back(r);
      }
    }
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    near_records_.insert(near_records_.end(), list.begin(), list.end());
    near_offsets_[f + 1] = static_cast<int>(near_records_.size());
  }
}

std::shared_ptr<const MeshEdgeTable> MeshEdgeTable::Of(const RenderScene& scene) {
  return LastBuildFor<MeshEdgeTable>(scene);
}

}  // namespace render_internal
}  // namespace sft
