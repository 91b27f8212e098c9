// Internal to src/render: a bounding-sphere hierarchy over line segments for drawing a segment
// in proportion to an estimate of the angle it subtends at a shading point — the "edge
// hierarchy" of Li et al. 2018 §5.2, used by secondary edge samples (A) (MeshEdgeTable).
//
// The tree is 4-wide: each node holds its up to four children's spheres side by side, so one
// SIMD evaluation scores all of them. A child's importance at x (unit normal n) is
//   I(child, x, n) = L/r² · min(1, (n·d + R)/r),   r² = |d|² + R²,  d = c − x,
// with L the child's total segment length, c and R its bounding sphere: ≈ the angle a far
// cluster subtends times a bound of the cosine at x, bounded for clusters around x, and 0 when
// the sphere is wholly below x's plane (its segments' integrand is zero there).
//
// A draw starts from a cut: the root's grandchildren (the root's children where they are
// leaves), at most 16 clusters, each chosen ∝ its own importance. The cut depends only on
// (x, n), so the several candidates drawn at one path vertex share it (PrepareCut once, then
// Sample and Probability with it). Below the cut a draw descends choosing a child ∝ its
// importance, and at a leaf picks a segment ∝ its length. A segment's probability is the
// product of the choices on its path, so it can be evaluated for any segment (Probability),
// which mixtures with other proposals need. The importance is a proposal only: estimators stay
// unbiased wherever it is positive, which it is for every segment with a point above x's plane.
#ifndef SFT_RENDER_INTERNAL_EDGE_TREE_H_
#define SFT_RENDER_INTERNAL_EDGE_TREE_H_

#include <Eigen/Core>
#include <vector>

namespace sft {
namespace render_internal {

class EdgeTree {
 public:
  // The clusters a draw at one point starts from, with their importances there.
  struct Cut {
    static constexpr int kMaxEntries = 16;
    Eigen::Vector3f x, n;  // the point and its normal, in float as the tree scores them.
    int count = 0;
    int node[kMaxEntries];           // the cluster's node, or −1 for a leaf.
    int end[kMaxEntries];            // its tree positions end; they begin where the previous ends.
    double importance[kMaxEntries];  // the cluster's importance at (x, n).
    double total = 0.0;              // Σ importances; ≤ 0 when every segment is below x's plane.
  };

  EdgeTree() = default;
  // The hierarchy over segments (a[i], b[i]) of lengths lengths[i] > 0 (all vectors the same
  // size). Segments are reordered: order()[j] is the input index of the segment at tree
  // position j, and every node and cut entry covers a contiguous range of positions.
  EdgeTree(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b,
           const std::vector<float>& lengths);

  bool empty() const { return nodes_.empty(); }
  const std::vector<int>& order() const { return order_; }

  // The cut at point x with unit normal n.
  void PrepareCut(const Eigen::Vector3d& x, const Eigen::Vector3d& n, Cut* cut) const;
  // The tree position drawn for u ∈ [0, 1) from `cut`, and its probability in *probability;
  // −1 (probability 0) when the draw ends below x's plane.
  int Sample(const Cut& cut, double u, double* probability) const;
  // The probability that Sample draws tree position `position` from `cut`.
  double Probability(const Cut& cut, int position) const;

  // The same for one draw at (x, n) (tests and single draws).
  int Sample(const Eigen::Vector3d& x, const Eigen::Vector3d& n, double u,
             double* probability) const;
  double Probability(const Eigen::Vector3d& x, const Eigen::Vector3d& n, int position) const;

 private:
  // Four children side by side (structure of arrays, for one SIMD evaluation). An unused slot
  // has length 0 (importance 0) and an empty position range.
  struct alignas(16) Node {
    float cx[4], cy[4], cz[4], radius[4];
    float length[4];  // Σ lengths of the child's segments.
    int child[4];     // the child's node, or −1 for a leaf (≤ kLeafSize segments).
    int end[4];       // the child's positions end; child k begins where child k − 1 ends.
    int begin = 0;    // child 0's positions begin.
  };

  // The four children's importances at (x, n), with their sum.
  static double Importances(const Node& node, const Eigen::Vector3f& x, const Eigen::Vector3f& n,
                            float importance[4]);
  int Build(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b,
            const std::vector<Eigen::Vector3f>& mid, int begin, int end);
  // Splits [begin, end) at the median of the midpoints along their longest axis; returns the
  // split position.
  int Split(const std::vector<Eigen::Vector3f>& mid, int begin, int end);
  // Σ lengths of positions [begin, end), in position order (Sample and Probability sum alike).
  double RangeLength(int begin, int end) const;
  int ChildBegin(const Node& node, int k) const { return k == 0 ? node.begin : node.end[k - 1]; }
  // Draws a position below internal node `node` (probability so far *p) for u ∈ [0, 1).
  int Descend(int node, double u, const Eigen::Vector3f& x, const Eigen::Vector3f& n,
              double* p) const;
  // Picks a position of leaf range [begin, end) ∝ length for u ∈ [0, 1); multiplies *p.
  int PickInLeaf(int begin, int end, double u, double* p) const;

  std::vector<Node> nodes_;     // depth-first: node 0 is the root.
  std::vector<int> order_;      // tree position → input index.
  std::vector<float> lengths_;  // per tree position.
};

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_EDGE_TREE_H_
