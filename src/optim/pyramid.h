// Image pyramids for the multi-scale residual (docs/reconstruct.md). Level 0 is the image; level
// l+1 has ⌈w/2⌉ × ⌈h/2⌉ pixels, each the mean of its (up to 2 × 2) children at level l — a box
// filter, the same for renderings and targets. Because the map is linear, the pyramid of the
// expected rendering equals the expected pyramid of the renderings, and the Jacobian row of a
// coarse pixel is the same mean of its children's rows ("coarse rows as sums of child rows": exact,
// shares the level-0 samples; see docs/design-notes.md for the choice against per-level renders).
#ifndef SFT_OPTIM_PYRAMID_H_
#define SFT_OPTIM_PYRAMID_H_

#include <cstdint>
#include <vector>

#include "cost_functions/pyramid_pixel.h"
#include "src/core/image.h"
#include "src/render/derivatives.h"

namespace sft {

// RowEntry, LevelRows and LevelCache (what a residual block reads) are defined with the residual
// in cost_functions/pyramid_pixel.h.

// ⌈n/2⌉.
inline int CoarserSize(int n) { return (n + 1) / 2; }

// The next coarser level of `fine` (any channel count).
Image DownsampleMean(const Image& fine);
// Levels 0..levels−1 of `image` (levels ≥ 1; stops early when a level is 1 × 1).
std::vector<Image> BuildPyramid(const Image& image, int levels);

// Level-0 rows in double from the renderer's float rows.
LevelRows RowsFromRenderer(const JacobianRows& rows);
// The rows of the next coarser level (each coarse row the mean of its children's rows).
LevelRows DownsampleRows(const LevelRows& fine);

// The adjoint of DownsampleMean: returns the level-l image g with ⟨g, x⟩ = ⟨coarse, D x⟩ for
// every x of size fine_width × fine_height (each fine pixel receives its parent's value over the
// parent's child count).
Image DownsampleMeanAdjoint(const Image& coarse, int fine_width, int fine_height);

// A mask pyramid: a coarse pixel is active when any of its children is.
std::vector<std::vector<uint8_t>> MaskPyramid(const std::vector<uint8_t>& mask, int width,
                                              int height, int levels);

}  // namespace sft

#endif  // SFT_OPTIM_PYRAMID_H_
