// Smoothness of a fitted environment map (lighting as parameters, docs/reconstruct.md "Unknown
// lighting"): a low-resolution equirectangular map whose texels are RGB radiance parameters.
//
// Residual (3 residuals), for a pair (a, b) of neighbouring texels:
//
//   r = w · (T_a − T_b)
//
// Parameter blocks: [T_a, T_b], each 3 doubles (the texel's linear RGB radiance).
// Jacobians: ∂r/∂T_a = w·I₃, ∂r/∂T_b = −w·I₃ (exact: the residual is linear; the cost is
// TexelDifferenceCost<3>, cost_functions/texel_smoothness.h).
// Evaluate never returns false. Derivative terms it does not have: none.
//
// Neighbours (EnvironmentNeighbourPairs) on the W × H lat-long grid (texel index y·W + x, the
// layout of src/render/environment.h): (x, y)–(x + 1 mod W, y), since u wraps around, and
// (x, y)–(x, y + 1). Texels of the top (bottom) row all meet at the pole, where the renderer holds
// each column's row value: the term does not tie them to each other beyond their ring neighbours.
// The grid's texels shrink towards the poles; the term weighs every pair alike (a prior on the
// map, not on the sphere's solid angle), which smooths the poles, seen least, the most.
#ifndef SFT_COST_FUNCTIONS_ENVIRONMENT_SMOOTHNESS_H_
#define SFT_COST_FUNCTIONS_ENVIRONMENT_SMOOTHNESS_H_

#include <vector>

#include "cost_functions/texel_smoothness.h"

namespace sft {

// Every neighbouring pair of a width × height lat-long grid (above): W·H horizontal pairs for
// W ≥ 3 (H for W = 2, none for W = 1), then W·(H − 1) vertical ones.
std::vector<TexelPair> EnvironmentNeighbourPairs(int width, int height);

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_ENVIRONMENT_SMOOTHNESS_H_
