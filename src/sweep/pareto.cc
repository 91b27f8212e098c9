#include "src/sweep/pareto.h"

#include <algorithm>
#include <cmath>

namespace sft {

std::vector<int> ParetoFront(const std::vector<double>& cost, const std::vector<double>& value,
                             bool higher_is_better) {
  // Quality q: higher is better in both cases.
  std::vector<int> order;
  for (size_t i = 0; i < cost.size() && i < value.size(); ++i) {
    if (std::isfinite(cost[i]) && std::isfinite(value[i])) order.push_back(static_cast<int>(i));
  }
  auto quality = [&](int i) { return higher_is_better ? value[i] : -value[i]; };
  // By cost, then best quality first: a point is on the front when its quality beats every point
  // before it, or equals the best so far at the same cost (an equal point).
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (cost[a] != cost[b]) return cost[a] < cost[b];
    if (quality(a) != quality(b)) return quality(a) > quality(b);
    return a < b;
  });
  std::vector<int> front;
  for (int i : order) {
    if (front.empty() || quality(i) > quality(front.back()) ||
        (quality(i) == quality(front.back()) && cost[i] == cost[front.back()])) {
      front.push_back(i);
    }
  }
  return front;
}

}  // namespace sft
