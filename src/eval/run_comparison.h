// Compares reconstruction runs (`sft compare`): reads each run's metrics.json and writes one CSV
// and an HTML report with cost, Chamfer distance and F1 against wall time, one line per run — the
// "what accuracy costs in time" figure of solver-configuration experiments.
#ifndef SFT_EVAL_RUN_COMPARISON_H_
#define SFT_EVAL_RUN_COMPARISON_H_

#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

// `runs` are sft reconstruct output folders, `labels` their names (same length). Writes
// OUT/comparison.csv (run, seconds, cost per iteration; seconds, cost, chamfer, f1 per outer
// iteration, chamfer and f1 empty when the run had no --reference) and OUT/report.html.
Status CompareRuns(const std::vector<std::string>& runs, const std::vector<std::string>& labels,
                   const std::string& out);

}  // namespace sft

#endif  // SFT_EVAL_RUN_COMPARISON_H_
