// Image pyramids for the multi-scale residual (docs/reconstruct.md). Level 0 is the image; level
// l+1 has ⌈w/2⌉ × ⌈h/2⌉ pixels, each a weighted mean of its children at level l (PyramidFilter: the
// 2 × 2 box by default, or a binomial filter), the same for renderings and targets. Because the
// map is linear, the pyramid of the expected rendering equals the expected pyramid of the
// renderings, and the Jacobian row of a coarse pixel is the same weighted mean of its children's
// rows ("coarse rows as sums of child rows": exact, shares the level-0 samples; see
// docs/design-notes.md for the choice against per-level renders).
#ifndef SFT_OPTIM_PYRAMID_H_
#define SFT_OPTIM_PYRAMID_H_

#include <cstdint>
#include <string>
#include <vector>

#include "cost_functions/pyramid_pixel.h"
#include "src/core/image.h"
#include "src/render/derivatives.h"

namespace sft {

// RowEntry, LevelRows and LevelCache (what a residual block reads) are defined with the residual
// in cost_functions/pyramid_pixel.h.

// ⌈n/2⌉.
inline int CoarserSize(int n) { return (n + 1) / 2; }

// The filter that makes level l+1 from level l; both are separable with stride 2, and the weights
// of every coarse pixel sum to 1 (a constant image stays constant).
enum class PyramidFilter {
  // The mean of the (up to 2 × 2) children (2x, 2x+1) × (2y, 2y+1); at an odd size the last
  // coarse column (row) has one child column (row).
  kBox,
  // [1 2 1]/4 in x times [1 2 1]/4 in y, centred on child (2x, 2y): taps 2x−1, 2x, 2x+1 (the
  // smallest binomial, i.e. Gaussian-like, kernel; Burt and Adelson 1983 use the 5-tap one). Border
  // rule: taps outside the image are dropped and the remaining ones renormalised (at x = 0 the
  // weights are 2/3, 1/3). Coarse pixel x sits on fine pixel 2x, half a fine pixel from the box's
  // 2x + ½: harmless, renders and targets share the filter.
  kBinomial,
};

// "box" or "binomial"; false for any other name.
bool PyramidFilterFromName(const std::string& name, PyramidFilter* filter);
const char* PyramidFilterName(PyramidFilter filter);

// The next coarser level of `fine` (any channel count).
Image DownsampleMean(const Image& fine, PyramidFilter filter = PyramidFilter::kBox);
// Levels 0..levels−1 of `image` (levels ≥ 1; stops early when a level is 1 × 1).
std::vector<Image> BuildPyramid(const Image& image, int levels,
                                PyramidFilter filter = PyramidFilter::kBox);

// Level-0 rows in double from the renderer's float rows.
LevelRows RowsFromRenderer(const JacobianRows& rows);
// The rows of the next coarser level (each coarse row the filter's weighted sum of its children's
// rows).
LevelRows DownsampleRows(const LevelRows& fine, PyramidFilter filter = PyramidFilter::kBox);

// The adjoint of DownsampleMean: returns the level-l image g with ⟨g, x⟩ = ⟨coarse, D x⟩ for
// every x of size fine_width × fine_height (each fine pixel receives the sum over the coarse
// pixels it feeds of their value times its weight in them).
Image DownsampleMeanAdjoint(const Image& coarse, int fine_width, int fine_height,
                            PyramidFilter filter = PyramidFilter::kBox);

// A mask pyramid: a coarse pixel is active when any child the filter gives a weight is.
std::vector<std::vector<uint8_t>> MaskPyramid(const std::vector<uint8_t>& mask, int width,
                                              int height, int levels,
                                              PyramidFilter filter = PyramidFilter::kBox);

}  // namespace sft

#endif  // SFT_OPTIM_PYRAMID_H_
