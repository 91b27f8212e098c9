// Internal to src/render: a bounding-sphere hierarchy over line segments for drawing a segment
// in proportion to an estimate of the angle it subtends at a shading point — the "edge
// hierarchy" of Li et al. 2018 §5.2, used by secondary edge samples (A) (MeshEdgeTable).
//
// A traversal from the root picks a child with probability ∝ its importance
//   I(node, x, n) = L / (|c − x|² + R²)   (0 when the node's sphere is wholly below x's plane),
// with L the node's total segment length, c and R its bounding sphere: ≈ L/r², the angle a far
// cluster subtends, and bounded for the clusters around x. At a leaf a segment is drawn ∝ its
// length. A segment's probability is the product of the choices on its root-to-leaf path, so it
// can be evaluated for any segment (Probability), which mixtures with other proposals need. The
// importance is a proposal only: estimators stay unbiased wherever it is positive, which it is
// for every segment with a point above x's plane.
#ifndef SFT_RENDER_INTERNAL_EDGE_TREE_H_
#define SFT_RENDER_INTERNAL_EDGE_TREE_H_

#include <Eigen/Core>
#include <vector>

namespace sft {
namespace render_internal {

class EdgeTree {
 public:
  EdgeTree() = default;
  // The hierarchy over segments (a[i], b[i]) of lengths lengths[i] > 0 (all vectors the same
  // size). Segments are reordered: order()[j] is the input index of the segment at tree
  // position j, and every node covers a contiguous range of positions.
  EdgeTree(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b,
           const std::vector<float>& lengths);

  bool empty() const { return nodes_.empty(); }
  const std::vector<int>& order() const { return order_; }

  // The tree position drawn for u ∈ [0, 1) at point x with unit normal n, and its probability
  // in *probability; −1 when every segment is below x's plane.
  int Sample(const Eigen::Vector3d& x, const Eigen::Vector3d& n, double u,
             double* probability) const;
  // The probability that Sample draws tree position `position` at (x, n).
  double Probability(const Eigen::Vector3d& x, const Eigen::Vector3d& n, int position) const;

 private:
  struct Node {
    Eigen::Vector3f center;
    float radius = 0.0f;
    float length = 0.0f;  // Σ lengths of the node's segments.
    int begin = 0;        // its tree positions [begin, end).
    int end = 0;
    int right = -1;  // the second child (the first is the next node); −1 for a leaf.
  };
  static_assert(sizeof(Node) == 32, "two nodes per cache line");

  int Build(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b,
            const std::vector<Eigen::Vector3f>& mid, int begin, int end);
  double Importance(const Node& node, const Eigen::Vector3f& x, const Eigen::Vector3f& n) const;
  // The probability of descending from internal node `node` to its first child; −1 when both
  // children are wholly below x's plane (the draw ends empty).
  double LeftProbability(int node, const Eigen::Vector3f& x, const Eigen::Vector3f& n) const;
  // Σ lengths of a leaf's segments, in position order (Sample and Probability sum alike).
  double LeafLength(const Node& leaf) const;

  std::vector<Node> nodes_;     // depth-first: node 0 is the root.
  std::vector<int> order_;      // tree position → input index.
  std::vector<float> lengths_;  // per tree position.
};

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_EDGE_TREE_H_
