// OUT/report.html of `sft reconstruct`: the run's summary, the cost and mean-PSNR curves against
// wall time, and target | render | |difference| for up to four views at the final state.
#ifndef SFT_EVAL_RECONSTRUCT_REPORT_H_
#define SFT_EVAL_RECONSTRUCT_REPORT_H_

#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/io/dataset.h"
#include "src/optim/reconstruct.h"

namespace sft {

Status WriteReconstructReport(const std::string& out, const Dataset& dataset,
                              const std::vector<IterationRecord>& records,
                              Reconstruction* reconstruction);

}  // namespace sft

#endif  // SFT_EVAL_RECONSTRUCT_REPORT_H_
