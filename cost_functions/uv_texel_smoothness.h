// Smoothness between neighbouring texels of a UV texture (albedo: 3 channels; roughness: 1): the
// texel prior of the schedule's uv stage (docs/reconstruct.md, "The uv stage").
//
// Residual (C residuals, C = channels), for a pair (a, b) of neighbouring texels:
//
//   r = w · (t_a − t_b)
//
// the residual of texel_smoothness.h, evaluated by the same cost function (TexelDifferenceCost<C>;
// for albedo in a phase that also fits light scales or the environment, its log-ratio form,
// TexelLogRatioCost<C>, whose Jacobians are w·0.5/(t + ε)).
// Parameter blocks: [t_a, t_b], each C doubles (texel k's channel values, k = y·W + x as in
// src/geometry/uv_texture.h). Jacobians: ∂r/∂t_a = w·I_C, ∂r/∂t_b = −w·I_C (exact: the residual
// is linear). Evaluate never returns false. Derivative terms it does not have: none.
//
// Which texels are neighbours (UvTexelNeighbourPairs): the 4-neighbourhood of the texel grid,
// (x, y)–(x+1, y) and (x, y)–(x, y+1), when both texels are used (some face's bilinear lookups
// read them: src/geometry/uv_texel_charts.h) and belong to the same chart. Texels across a UV
// seam are neighbours in the grid but not on the surface, and gutter texels are no parameters of
// the fit, so neither is paired. No wrap-around at the texture's border (atlas charts keep a
// gutter from it).
#ifndef SFT_COST_FUNCTIONS_UV_TEXEL_SMOOTHNESS_H_
#define SFT_COST_FUNCTIONS_UV_TEXEL_SMOOTHNESS_H_

#include <vector>

#include "cost_functions/texel_smoothness.h"
#include "src/geometry/uv_texel_charts.h"

namespace sft {

// Every neighbouring pair of used texels of one chart (above), as texel indices y·W + x; first
// the horizontal pairs row by row, then the vertical ones. `cross_face` is false for all (the
// weight is one for every pair; faces do not partition a texel grid).
std::vector<TexelPair> UvTexelNeighbourPairs(const UvTexelCharts& charts);

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_UV_TEXEL_SMOOTHNESS_H_
