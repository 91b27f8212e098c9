// Runs COLMAP's command-line programs (COLMAP 3.8, CPU only: docs/design-notes.md "Platform facts")
// for `sft import video`. Each stage runs as `colmap STAGE ARGS...` through popen with
// QT_QPA_PLATFORM=offscreen and OMP_WAIT_POLICY=passive; its whole output (stdout and stderr) is
// appended to a log file and never printed. Progress counts are read from the lines COLMAP prints:
//   feature_extractor   "Processed file [i/n]"
//   exhaustive_matcher  "Matching block [i/n, j/n]"   (block i·n + j of n²)
//   sequential_matcher  "Matching image [i/n]"
//   mapper              "Registering image #ID (k)"    (k = images registered so far)
#ifndef SFT_CAPTURE_COLMAP_RUNNER_H_
#define SFT_CAPTURE_COLMAP_RUNNER_H_

#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

// Progress read from one line of COLMAP output: `done` of `total` (total 0 = unknown). False when
// the line carries no progress for `stage`.
bool ParseColmapProgress(const std::string& stage, const std::string& line, int* done, int* total);

// Runs `colmap_binary stage args...`, appending its output to `log_path`. `expected_total` is the
// progress total used when COLMAP's lines do not give one (mapper: the number of images). Prints a
// progress line (with ETA) labelled "import video: STAGE" when `progress`. Errors: the program
// cannot be started, or exits non-zero (naming the stage, the exit code and the log).
Status RunColmapStage(const std::string& colmap_binary, const std::string& stage,
                      const std::vector<std::string>& args, const std::string& log_path,
                      int expected_total, bool progress, double* seconds);

}  // namespace sft

#endif  // SFT_CAPTURE_COLMAP_RUNNER_H_
