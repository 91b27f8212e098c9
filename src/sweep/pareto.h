// The Pareto front of accuracy against cost (`sft sweep`'s report): the points that no other
// point beats on both, i.e. for which every other point is slower or less accurate.
#ifndef SFT_SWEEP_PARETO_H_
#define SFT_SWEEP_PARETO_H_

#include <vector>

namespace sft {

// Indices of the points on the front of value against cost, in increasing cost. Lower cost is
// better; a higher value is better when `higher_is_better` (F1, PSNR), a lower one otherwise
// (Chamfer). Point i is dominated when some j has cost_j <= cost_i and a value at least as good,
// with at least one of the two strictly better; the front is the points not dominated (equal
// points are all on it). Points with a non-finite cost or value are left out. `cost` and `value`
// have the same length.
std::vector<int> ParetoFront(const std::vector<double>& cost, const std::vector<double>& value,
                             bool higher_is_better);

}  // namespace sft

#endif  // SFT_SWEEP_PARETO_H_
