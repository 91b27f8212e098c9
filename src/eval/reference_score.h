// Per-outer geometric scores against a reference mesh: what `sft reconstruct --reference` and
// `sft sweep` cells with a reference record in metrics.json's "outer" entries, so that accuracy
// can be drawn against time over a run.
#ifndef SFT_EVAL_REFERENCE_SCORE_H_
#define SFT_EVAL_REFERENCE_SCORE_H_

#include <nlohmann/json.hpp>
#include <string>

#include "src/core/status.h"
#include "src/geometry/mesh.h"

namespace sft {

// Surface samples per mesh of a per-outer score by default: cheaper than `sft eval`'s 1M (a few
// hundred ms on a 50k-face mesh). It reads high when there are fewer samples than faces: a
// sample's distance is taken to the faces its nearest samples lie on, which can miss the nearest
// face (docs/design-notes.md, "The warp acceptance: three knobs", item "Per-outer Chamfer reads
// high").
constexpr int kOuterScoreSamples = 50000;

// Sets *out to {"chamfer", "f1", "f1_tolerance"} of `mesh` against `reference` with `samples`
// per surface; `tolerance` is the F1 distance as a fraction of the reference's diagonal. Errors
// name `reference_name` or "mesh" (see ComputeMeshMetrics).
Status ScoreAgainstReference(const TriMesh& reference, double tolerance, const TriMesh& mesh,
                             const std::string& reference_name, nlohmann::json* out,
                             int samples = kOuterScoreSamples);

}  // namespace sft

#endif  // SFT_EVAL_REFERENCE_SCORE_H_
