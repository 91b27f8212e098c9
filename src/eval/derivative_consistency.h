// How much of a derivative is signal: the renderer's directional derivative image Σ_θ J_θ·δ_θ
// (the direction δ of `sft gradcheck`, src/eval/gradcheck.h) rendered with K different sample
// seeds and compared with itself. Finite differences say whether a derivative is right on
// average; this says whether one render's Jacobian at the fit's spp carries a step or mostly noise
// (docs/design-notes.md, "Why the glossy dragon's geometry does not move").
//
// Per view and overall: the mean correlation over seed pairs (Σ a·b / √(Σa²·Σb²), 1 = the same
// image, 0 = unrelated) per pixel and over B×B block sums, and the noise-to-signal ratio
// √(Σ_p var_s(D_sp)) / √(Σ_p mean_s(D_sp)²) over pixels and channels (0 = noiseless; well above
// 1 = the seed decides more than the parameters).
#ifndef SFT_EVAL_DERIVATIVE_CONSISTENCY_H_
#define SFT_EVAL_DERIVATIVE_CONSISTENCY_H_

#include <vector>

#include "src/core/status.h"
#include "src/eval/gradcheck.h"

namespace sft {

struct ConsistencyViewResult {
  int view = 0;
  double pixel_correlation = 0.0;  // mean over seed pairs, per pixel.
  double block_correlation = 0.0;  // mean over seed pairs, B×B block sums.
  double noise_to_signal = 0.0;    // per pixel, over the K seeds.
};

struct ConsistencyResult {
  int seeds = 0;
  int block = 1;
  std::vector<ConsistencyViewResult> views;
  double pixel_correlation = 0.0;  // means over the views.
  double block_correlation = 0.0;
  double noise_to_signal = 0.0;
};

// Renders the derivative images of `options` (kind, direction, render settings, edge budgets,
// views, block: 0 = 8 for vertices, else 1) at seeds options.render.seed + 0 … seeds − 1.
// `seeds` in [2, 64].
Status MeasureDerivativeConsistency(const Dataset& dataset, const TriMesh& mesh,
                                    const Material& material, const GradcheckOptions& options,
                                    int seeds, ConsistencyResult* result);

}  // namespace sft

#endif  // SFT_EVAL_DERIVATIVE_CONSISTENCY_H_
