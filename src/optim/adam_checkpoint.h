// adam_state.bin in a reconstruction's run folder: Adam's moments (AdamState, src/optim/solvers.h)
// at a checkpoint, so that a resumed Adam stage continues with the moments and the step count
// (bias correction, per-step seeds and minibatches) of the run it continues.
//
// Format (version 1), all little-endian:
//   8 bytes   magic "SFTADAM" followed by a zero byte
//   uint32    version (1)
//   uint32    stage: index of the stage whose fit the moments belong to
//   int64     outer_done: outer iterations completed over the run at the checkpoint
//   uint64    n: moments per vector (the parameter layout's size)
//   int64     t: Adam steps taken
//   float64   lambda: the large-steps λ the vertex moments belong to
//   n float64 m (first moments), then n float64 v (second moments)
// The file is written before state.json, which stays the checkpoint's commit point: a file whose
// stage or outer_done differ from state.json's is not applied (Adam then starts fresh).
#ifndef SFT_OPTIM_ADAM_CHECKPOINT_H_
#define SFT_OPTIM_ADAM_CHECKPOINT_H_

#include <cstdint>
#include <string>

#include "src/core/status.h"
#include "src/optim/solvers.h"

namespace sft {

constexpr char kAdamStateFile[] = "adam_state.bin";

struct AdamCheckpoint {
  int stage = 0;           // the stage the moments belong to.
  int64_t outer_done = 0;  // ScheduleProgress::outer_done at the checkpoint.
  AdamState state;         // m and v of equal size.
};

// Writes `out`/adam_state.bin atomically.
Status WriteAdamCheckpoint(const std::string& out, const AdamCheckpoint& checkpoint);
// Reads `out`/adam_state.bin. A missing file (a run folder of an older sft, or a run without
// Adam moments) is OK with *found = false. A corrupt or truncated file is one error line naming
// the file.
Status ReadAdamCheckpoint(const std::string& out, AdamCheckpoint* checkpoint, bool* found);
// Removes `out`/adam_state.bin if it exists (the checkpoint holds no moments).
void RemoveAdamCheckpoint(const std::string& out);

}  // namespace sft

#endif  // SFT_OPTIM_ADAM_CHECKPOINT_H_
