#include "src/render/internal/edge_tree.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sft {
namespace render_internal {
namespace {

// Segments per leaf at most.
constexpr int kLeafSize = 4;

// The largest double below 1: where a rescaled random number must stay.
constexpr double kOneMinus = 1.0 - 1.0 / 9007199254740992.0;

}  // namespace

EdgeTree::EdgeTree(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b,
                   const std::vector<float>& lengths) {
  CHECK_EQ(a.size(), b.size());
  CHECK_EQ(a.size(), lengths.size());
  if (a.empty()) return;
  std::vector<Eigen::Vector3f> mid(a.size());
  for (size_t i = 0; i < a.size(); ++i) mid[i] = 0.5f * (a[i] + b[i]);
  order_.resize(a.size());
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(2 * a.size() / kLeafSize + 1);
  Build(a, b, mid, 0, static_cast<int>(a.size()));
  lengths_.resize(a.size());
  for (size_t j = 0; j < a.size(); ++j) lengths_[j] = lengths[order_[j]];
  // Node lengths summed over the final order (the leaves' sums, as Sample recomputes them).
  for (Node& node : nodes_) {
    double sum = 0.0;
    for (int j = node.begin; j < node.end; ++j) sum += lengths_[j];
    node.length = static_cast<float>(sum);
  }
}

inline __attribute__((always_inline)) double EdgeTree::Importance(const Node& node,
                                                                  const Eigen::Vector3f& x,
                                                                  const Eigen::Vector3f& n) const {
  const Eigen::Vector3f d = node.center - x;
  const float above = n.dot(d) + node.radius;  // ≥ n·(p − x) for every point p of the sphere.
  if (!(above > 0.0f)) return 0.0;
  // L/r² times a bound of the cosine at x, min(1, above/r); the square root in float (its
  // precision only moves the proposal, which Sample and Probability compute alike), the
  // quotient in double (r³ leaves float's range for scenes far from unit scale).
  const float r2 = d.squaredNorm() + node.radius * node.radius;
  const float r = std::sqrt(r2);
  return static_cast<double>(node.length) * std::min(r, above) /
         (static_cast<double>(r2) * static_cast<double>(r));
}

int EdgeTree::Build(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b,
                    const std::vector<Eigen::Vector3f>& mid, int begin, int end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  Eigen::Vector3f mid_lo = lo, mid_hi = hi;
  for (int j = begin; j < end; ++j) {
    const int i = order_[j];
    lo = lo.cwiseMin(a[i]).cwiseMin(b[i]);
    hi = hi.cwiseMax(a[i]).cwiseMax(b[i]);
    mid_lo = mid_lo.cwiseMin(mid[i]);
    mid_hi = mid_hi.cwiseMax(mid[i]);
  }
  Node node;
  node.center = 0.5f * (lo + hi);
  // Inflated so that float rounding (of the centre, and of x at lookup) cannot put a segment
  // point outside the sphere: the below-the-plane test must never drop a visible segment.
  const float half_diagonal = 0.5f * (hi - lo).norm();
  node.radius = half_diagonal * (1.0f + 1e-5f) + 1e-5f * node.center.norm();
  node.begin = begin;
  node.end = end;
  if (end - begin > kLeafSize) {
    int axis;
    (mid_hi - mid_lo).maxCoeff(&axis);
    const int half = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + half, order_.begin() + end,
                     [&](int p, int q) { return mid[p][axis] < mid[q][axis]; });
    Build(a, b, mid, begin, half);
    node.right = Build(a, b, mid, half, end);
  }
  nodes_[index] = node;
  return index;
}

double EdgeTree::LeftProbability(int node, const Eigen::Vector3f& x,
                                 const Eigen::Vector3f& n) const {
  const double i_left = Importance(nodes_[node + 1], x, n);
  const double i_right = Importance(nodes_[nodes_[node].right], x, n);
  const double total = i_left + i_right;
  if (!(total > 0.0) || !std::isfinite(total)) return -1.0;
  return i_left / total;
}

double EdgeTree::LeafLength(const Node& leaf) const {
  double sum = 0.0;
  for (int j = leaf.begin; j < leaf.end; ++j) sum += lengths_[j];
  return sum;
}

int EdgeTree::Sample(const Eigen::Vector3d& x_in, const Eigen::Vector3d& n_in, double u,
                     double* probability) const {
  *probability = 0.0;
  if (nodes_.empty()) return -1;
  const Eigen::Vector3f x = x_in.cast<float>(), n = n_in.cast<float>();
  double p = 1.0;
  int node = 0;
  while (nodes_[node].right >= 0) {
    const int left = node + 1, right = nodes_[node].right;
    const double p_left = LeftProbability(node, x, n);
    if (p_left < 0.0) return -1;
    if (u < p_left) {
      u /= p_left;
      p *= p_left;
      node = left;
    } else {
      u = (u - p_left) / (1.0 - p_left);
      p *= 1.0 - p_left;
      node = right;
    }
    u = std::min(u, kOneMinus);
  }
  const Node& leaf = nodes_[node];
  const double sum = LeafLength(leaf);
  const double level = u * sum;
  double cumulative = 0.0;
  int j = leaf.begin;
  for (; j + 1 < leaf.end; ++j) {
    cumulative += lengths_[j];
    if (level < cumulative) break;
  }
  *probability = p * lengths_[j] / sum;
  return j;
}

double EdgeTree::Probability(const Eigen::Vector3d& x_in, const Eigen::Vector3d& n_in,
                             int position) const {
  if (nodes_.empty()) return 0.0;
  const Eigen::Vector3f x = x_in.cast<float>(), n = n_in.cast<float>();
  double p = 1.0;
  int node = 0;
  while (nodes_[node].right >= 0) {
    const int left = node + 1, right = nodes_[node].right;
    const double p_left = LeftProbability(node, x, n);
    if (p_left < 0.0) return 0.0;
    if (position < nodes_[left].end) {
      p *= p_left;
      node = left;
    } else {
      p *= 1.0 - p_left;
      node = right;
    }
  }
  return p * lengths_[position] / LeafLength(nodes_[node]);
}

}  // namespace render_internal
}  // namespace sft
