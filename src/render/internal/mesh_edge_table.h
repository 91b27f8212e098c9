// Internal to src/render: the mesh edges that secondary edge samples (A) draw from, per mesh
// state, packed for the candidate loop.
#ifndef SFT_RENDER_INTERNAL_MESH_EDGE_TABLE_H_
#define SFT_RENDER_INTERNAL_MESH_EDGE_TABLE_H_

#include <Eigen/Core>
#include <algorithm>
#include <memory>
#include <vector>

#include "src/render/internal/edge_tree.h"
#include "src/render/internal/sampling.h"
#include "src/render/scene.h"

namespace sft {
namespace render_internal {

// The mesh edges where radiance can jump seen from some point — every edge except those between
// coplanar, consistently oriented faces — in the order of an EdgeTree over them. A secondary
// edge sample draws its candidates from all of the mesh's edges (75k for a 50k-face mesh: far
// more than the caches hold), so a candidate reads one cache line instead of the edge, both
// ends and both face normals scattered over the scene's arrays, and the tree's order keeps
// nearby edges in nearby lines. The table depends on the mesh state only:
// MeshEdgeTable::Of returns the last build while scene.state_id() is unchanged.
class MeshEdgeTable {
 public:
  // One cache line per edge: what deciding whether a candidate can be a jump seen from x, and
  // weighing it, reads. Floats: they place the candidate point (the kept point is then evaluated
  // on the double-precision mesh) and decide the sign of a distance (silhouette test).
  struct alignas(64) Record {
    Eigen::Vector3f a, b;    // the edge's ends (welded vertices v0, v1), world frame.
    Eigen::Vector3f n0, n1;  // the faces' consistently oriented unit normals; both zero for an
                             // edge that is always a jump (boundary, non-manifold, degenerate).
    int f0 = -1, f1 = -1;    // the edge's faces (f1 = −1 for a boundary edge).
    float length = 0.0f;     // |b − a|.
    float crease = 0.0f;     // 1 when the neighbours are not coplanar (a crease), else 0.
  };

  // The table of `scene`'s current mesh state (built on first use, then shared).
  static std::shared_ptr<const MeshEdgeTable> Of(const RenderScene& scene);

  explicit MeshEdgeTable(const RenderScene& scene);

  bool empty() const { return records_.empty(); }
  int size() const { return static_cast<int>(records_.size()); }
  const Record& record(int i) const { return records_[i]; }
  int edge(int i) const { return edges_[i]; }  // index into scene.edges().
  // The hierarchy over the records (record i is tree position i).
  const EdgeTree& tree() const { return tree_; }
  void Prefetch(int i) const { __builtin_prefetch(&records_[i]); }

  // The records of the edges that share a vertex with `face` but are not its own, sorted.
  const int* near_begin(int face) const { return near_records_.data() + near_offsets_[face]; }
  const int* near_end(int face) const { return near_records_.data() + near_offsets_[face + 1]; }

  // Whether record i can be a jump seen from x: a silhouette from x, always, or a crease when
  // `creases`.
  bool IsDiscontinuity(int i, const Eigen::Vector3d& x, bool creases) const {
    const Record& r = records_[i];
    if (creases && r.crease > 0.0f) return true;
    if (r.n0.isZero()) return true;
    const Eigen::Vector3f to_x = x.cast<float>() - r.a;
    return (r.n0.dot(to_x) > 0.0f) != (r.n1.dot(to_x) > 0.0f);
  }

 private:
  void BuildNearLists(const RenderScene& scene);

  std::vector<Record> records_;
  EdgeTree tree_;
  std::vector<int> edges_;
  std::vector<int> near_offsets_;  // per face (+1), into near_records_.
  std::vector<int> near_records_;
};

// The candidate proposal of (A) at a path vertex x (normal n) on face `face`: with probability
// kNearFraction one of the edges around the face (MeshEdgeTable::near_begin/end) uniformly, else
// the EdgeTree's draw ∝ length·cosine/distance². Edges next to the vertex subtend the largest
// angles at it and the tree's clusters around x are coarse, so the ring bounds their weights Θ/p.
// The interface of DiscreteDistribution for DrawSegmentCandidates: SampleBatch writes each draw's
// inverse probability under the mixture (index −1: nothing to draw, every edge below x's plane).
class NearEdgeMixture {
 public:
  static constexpr double kNearFraction = 0.25;

  NearEdgeMixture(const MeshEdgeTable& table, int face, const Eigen::Vector3d& x,
                  const Eigen::Vector3d& n)
      : table_(table), near_begin_(table.near_begin(face)), near_end_(table.near_end(face)) {
    const int count = static_cast<int>(near_end_ - near_begin_);
    near_fraction_ = count > 0 ? kNearFraction : 0.0;
    near_probability_ = near_fraction_ > 0 ? kNearFraction / count : 0.0;
    table.tree().PrepareCut(x, n, &cut_);  // shared by every candidate drawn at x.
  }

  void SampleBatch(const double* u, int n, int* out, double* inverse_probability) const {
    const int count = static_cast<int>(near_end_ - near_begin_);
    for (int k = 0; k < n; ++k) {
      double p = 0.0;
      if (u[k] < near_fraction_) {
        out[k] = near_begin_[std::min(static_cast<int>(u[k] / near_fraction_ * count), count - 1)];
        p = near_probability_ + (1.0 - near_fraction_) * table_.tree().Probability(cut_, out[k]);
      } else {
        double p_tree = 0.0;
        out[k] =
            table_.tree().Sample(cut_, (u[k] - near_fraction_) / (1.0 - near_fraction_), &p_tree);
        if (out[k] < 0) {
          inverse_probability[k] = 0.0;
          continue;
        }
        p = (1.0 - near_fraction_) * p_tree + NearProbability(out[k]);
      }
      table_.Prefetch(out[k]);
      inverse_probability[k] = 1.0 / p;
    }
  }

  // 1 / the probability of record c (tests; the sampler's own draws carry theirs).
  double InverseProbability(int c) const {
    return 1.0 / ((1.0 - near_fraction_) * table_.tree().Probability(cut_, c) + NearProbability(c));
  }

 private:
  double NearProbability(int c) const {
    return near_probability_ > 0.0 && std::binary_search(near_begin_, near_end_, c)
               ? near_probability_
               : 0.0;
  }

  const MeshEdgeTable& table_;
  const int* near_begin_;
  const int* near_end_;
  double near_fraction_ = 0.0;
  double near_probability_ = 0.0;
  EdgeTree::Cut cut_;
};

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_MESH_EDGE_TABLE_H_
