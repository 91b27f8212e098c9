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

// Picks an index k < count with w[k] > 0 for u ∈ [0, 1), ∝ w (total = Σ w > 0), and rescales u
// to [0, 1) within the pick. Rounding that leaves u·total at or past the sum gives the last
// positive weight.
template <typename T>
int PickWeighted(const T* w, int count, double total, double* u) {
  const double level = *u * total;
  int pick = -1;
  double before = 0.0, at = 0.0;
  for (int k = 0; k < count; ++k) {
    if (!(w[k] > 0)) continue;
    pick = k;
    at = before;
    before += w[k];
    if (level < before) break;
  }
  DCHECK_GE(pick, 0);
  *u = std::clamp((level - at) / w[pick], 0.0, kOneMinus);
  return pick;
}

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
  nodes_.reserve(a.size() / kLeafSize / 2 + 1);
  Build(a, b, mid, 0, static_cast<int>(a.size()));
  lengths_.resize(a.size());
  for (size_t j = 0; j < a.size(); ++j) lengths_[j] = lengths[order_[j]];
  // Children's lengths summed over the final order (as leaves are summed when drawing).
  for (Node& node : nodes_) {
    for (int k = 0; k < 4; ++k) {
      node.length[k] = static_cast<float>(RangeLength(ChildBegin(node, k), node.end[k]));
    }
  }
}

double EdgeTree::Importances(const Node& node, const Eigen::Vector3f& x, const Eigen::Vector3f& n,
                             float importance[4]) {
  using Array4 = Eigen::Array4f;
  using Map4 = Eigen::Map<const Array4, Eigen::Aligned16>;
  const Map4 cx(node.cx), cy(node.cy), cz(node.cz), radius(node.radius), length(node.length);
  const Array4 dx = cx - x.x(), dy = cy - x.y(), dz = cz - x.z();
  // ≥ n·(p − x) for every point p of the sphere.
  const Array4 above = n.x() * dx + n.y() * dy + n.z() * dz + radius;
  const Array4 r2 = dx * dx + dy * dy + dz * dz + radius * radius;
  // L/r² times min(1, above/r); in this order the terms stay within float's range for scenes
  // from about 1e−15 to 1e15 units (r³ would not).
  const Array4 value = (length / r2) * (above / r2.sqrt()).min(1.0f);
  Eigen::Map<Array4> out(importance);
  out = (above > 0.0f).select(value, Array4::Zero());
  return static_cast<double>(importance[0]) + importance[1] + importance[2] + importance[3];
}

int EdgeTree::Split(const std::vector<Eigen::Vector3f>& mid, int begin, int end) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (int j = begin; j < end; ++j) {
    lo = lo.cwiseMin(mid[order_[j]]);
    hi = hi.cwiseMax(mid[order_[j]]);
  }
  int axis;
  (hi - lo).maxCoeff(&axis);
  const int half = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + half, order_.begin() + end,
                   [&](int p, int q) { return mid[p][axis] < mid[q][axis]; });
  return half;
}

int EdgeTree::Build(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b,
                    const std::vector<Eigen::Vector3f>& mid, int begin, int end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  // The children's ranges: the halves of [begin, end), each halved again unless it is a leaf.
  std::vector<int> ends;
  if (end - begin <= kLeafSize) {
    ends = {end};  // only the root of a small tree.
  } else {
    const int half = Split(mid, begin, end);
    if (half - begin > kLeafSize) ends.push_back(Split(mid, begin, half));
    ends.push_back(half);
    if (end - half > kLeafSize) ends.push_back(Split(mid, half, end));
    ends.push_back(end);
  }
  Node node;
  node.begin = begin;
  for (int k = 0; k < 4; ++k) {
    node.cx[k] = node.cy[k] = node.cz[k] = 0.0f;
    node.radius[k] = 1.0f;  // keeps r² > 0 in an unused slot, whose length 0 zeroes it.
    node.length[k] = 0.0f;
    node.child[k] = -1;
    node.end[k] = end;
  }
  for (size_t k = 0; k < ends.size(); ++k) {
    const int child_begin = k == 0 ? begin : ends[k - 1];
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
    for (int j = child_begin; j < ends[k]; ++j) {
      lo = lo.cwiseMin(a[order_[j]]).cwiseMin(b[order_[j]]);
      hi = hi.cwiseMax(a[order_[j]]).cwiseMax(b[order_[j]]);
    }
    const Eigen::Vector3f center = 0.5f * (lo + hi);
    node.cx[k] = center.x();
    node.cy[k] = center.y();
    node.cz[k] = center.z();
    // Inflated so that float rounding (of the centre, and of x at lookup) cannot put a segment
    // point outside the sphere: the below-the-plane test must never drop a visible segment.
    node.radius[k] = 0.5f * (hi - lo).norm() * (1.0f + 1e-5f) + 1e-5f * center.norm();
    node.end[k] = ends[k];
    if (ends[k] - child_begin > kLeafSize) node.child[k] = Build(a, b, mid, child_begin, ends[k]);
  }
  nodes_[index] = node;
  return index;
}

double EdgeTree::RangeLength(int begin, int end) const {
  double sum = 0.0;
  for (int j = begin; j < end; ++j) sum += lengths_[j];
  return sum;
}

void EdgeTree::PrepareCut(const Eigen::Vector3d& x, const Eigen::Vector3d& n, Cut* cut) const {
  cut->x = x.cast<float>();
  cut->n = n.cast<float>();
  cut->count = 0;
  cut->total = 0.0;
  if (nodes_.empty()) return;
  auto add = [cut](int node, int end, double importance) {
    const int e = cut->count++;
    cut->node[e] = node;
    cut->end[e] = end;
    cut->importance[e] = importance;
    cut->total += importance;
  };
  const Node& root = nodes_[0];
  float root_importance[4];
  bool root_scored = false;
  for (int k = 0; k < 4; ++k) {
    if (ChildBegin(root, k) == root.end[k]) continue;  // an unused slot.
    if (root.child[k] < 0) {
      if (!root_scored) Importances(root, cut->x, cut->n, root_importance);
      root_scored = true;
      add(-1, root.end[k], root_importance[k]);
      continue;
    }
    const Node& child = nodes_[root.child[k]];
    float importance[4];
    Importances(child, cut->x, cut->n, importance);
    for (int j = 0; j < 4; ++j) {
      if (ChildBegin(child, j) < child.end[j]) add(child.child[j], child.end[j], importance[j]);
    }
  }
  if (!std::isfinite(cut->total)) cut->total = 0.0;  // nothing is drawn.
}

int EdgeTree::PickInLeaf(int begin, int end, double u, double* p) const {
  const double sum = RangeLength(begin, end);
  const double level = u * sum;
  double cumulative = 0.0;
  int j = begin;
  for (; j + 1 < end; ++j) {
    cumulative += lengths_[j];
    if (level < cumulative) break;
  }
  *p = *p * lengths_[j] / sum;
  return j;
}

int EdgeTree::Descend(int node, double u, const Eigen::Vector3f& x, const Eigen::Vector3f& n,
                      double* p) const {
  for (;;) {
    const Node& current = nodes_[node];
    float importance[4];
    const double total = Importances(current, x, n, importance);
    // Every child wholly below x's plane: the draw ends empty (their integrand is zero).
    if (!(total > 0.0) || !std::isfinite(total)) return -1;
    const int k = PickWeighted(importance, 4, total, &u);
    *p *= importance[k] / total;
    if (current.child[k] < 0) return PickInLeaf(ChildBegin(current, k), current.end[k], u, p);
    node = current.child[k];
  }
}

int EdgeTree::Sample(const Cut& cut, double u, double* probability) const {
  *probability = 0.0;
  if (!(cut.total > 0.0)) return -1;
  const int e = PickWeighted(cut.importance, cut.count, cut.total, &u);
  double p = cut.importance[e] / cut.total;
  const int position = cut.node[e] >= 0
                           ? Descend(cut.node[e], u, cut.x, cut.n, &p)
                           : PickInLeaf(e == 0 ? 0 : cut.end[e - 1], cut.end[e], u, &p);
  if (position >= 0) *probability = p;
  return position;
}

double EdgeTree::Probability(const Cut& cut, int position) const {
  if (!(cut.total > 0.0)) return 0.0;
  int e = 0;
  while (e < cut.count && position >= cut.end[e]) ++e;
  if (e == cut.count || !(cut.importance[e] > 0.0)) return 0.0;
  double p = cut.importance[e] / cut.total;
  int node = cut.node[e];
  int begin = e == 0 ? 0 : cut.end[e - 1], end = cut.end[e];
  while (node >= 0) {
    const Node& current = nodes_[node];
    float importance[4];
    const double total = Importances(current, cut.x, cut.n, importance);
    if (!(total > 0.0) || !std::isfinite(total)) return 0.0;
    int k = 0;
    while (position >= current.end[k]) ++k;
    if (!(importance[k] > 0.0f)) return 0.0;
    p *= importance[k] / total;
    begin = ChildBegin(current, k);
    end = current.end[k];
    node = current.child[k];
  }
  return p * lengths_[position] / RangeLength(begin, end);
}

int EdgeTree::Sample(const Eigen::Vector3d& x, const Eigen::Vector3d& n, double u,
                     double* probability) const {
  Cut cut;
  PrepareCut(x, n, &cut);
  return Sample(cut, u, probability);
}

double EdgeTree::Probability(const Eigen::Vector3d& x, const Eigen::Vector3d& n,
                             int position) const {
  Cut cut;
  PrepareCut(x, n, &cut);
  return Probability(cut, position);
}

}  // namespace render_internal
}  // namespace sft
