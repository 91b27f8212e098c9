// The image residual of one pyramid pixel (docs/reconstruct.md): for view v, level l, pixel p,
//
//   r_c = √w_l · √w_lp · (P_l(I(θ))_pc − P_l(T)_pc),   c ∈ {R, G, B},
//
// with I(θ) the path-traced rendering, T the photograph, P_l the level-l pyramid
// (src/optim/pyramid.h), w_l the level's weight and w_lp the pixel's weight (1 for the L2 loss;
// for the relative loss a function of the target alone, src/optim/render_cache.h). 3 residuals.
//
// Parameter blocks: a fixed superset chosen when the problem is built (the blocks that the
// pixel's samples touched in a few renders), each a span [offset, offset + size) of the flat
// parameter vector (src/optim/parameters.h), given in increasing offset order. The cost function
// does not read the parameter values: the render cache (an EvaluationCallback) has rendered the
// current point before Evaluate is called, and Evaluate copies the residual and the Jacobian row
// from it. Jacobian entries of parameters outside the superset are dropped (the residual stays
// exact); blocks the render did not touch get zeros.
//
// Evaluate returns false when the cache's current render is not finite (a non-finite sample or
// derivative was reported by the renderer): Ceres then rejects the trial step.
//
// Derivative terms it does not have: those the renderer does not produce (see
// src/render/derivatives.h) and the entries dropped outside the superset. The Jacobian is a
// Monte Carlo estimate from the same samples as the residual.
#ifndef SFT_COST_FUNCTIONS_PYRAMID_PIXEL_H_
#define SFT_COST_FUNCTIONS_PYRAMID_PIXEL_H_

#include <ceres/cost_function.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "src/core/image.h"

namespace sft {

// One Jacobian entry in double: ∂(pixel RGB)/∂(parameter `param`).
struct RowEntry {
  int32_t param;
  double d[3];
};

// Sparse rows of one pyramid level, pixel-major, entries of each pixel sorted by parameter with no
// duplicates: pixel p's entries are entries[offsets[p] .. offsets[p + 1]).
struct LevelRows {
  int width = 0;
  int height = 0;
  std::vector<uint64_t> offsets;
  std::vector<RowEntry> entries;

  size_t MemoryBytes() const {
    return offsets.capacity() * sizeof(uint64_t) + entries.capacity() * sizeof(RowEntry);
  }
};

// One level of one view as the residual blocks read it (owned by the render cache, updated in
// place at every evaluation point; see cost_functions/pyramid_pixel.h).
struct LevelCache {
  Image render;              // the rendering's pyramid level, RGB.
  Image target;              // the target's pyramid level, RGB.
  LevelRows rows;            // Jacobian rows of `render`; empty when not rendered with derivatives.
  double sqrt_weight = 1.0;  // the level's residual weight √w_l.
  // Per-pixel weights √w_lp (row-major, width × height); empty = all 1. Fixed for a run: they
  // depend on the target only, so the loss stays an unbiased function of the render.
  std::vector<float> pixel_sqrt_weight;

  // √w_l · √w_lp of pixel p.
  double SqrtWeight(int p) const {
    return pixel_sqrt_weight.empty() ? sqrt_weight : sqrt_weight * pixel_sqrt_weight[p];
  }
};

// Residuals per pixel block: its R, G and B differences.
constexpr int kPixelResiduals = 3;

class PyramidPixelCost : public ceres::CostFunction {
 public:
  // `level` and `finite` are owned by the render cache and outlive the cost function.
  PyramidPixelCost(const LevelCache* level, const bool* finite, int pixel,
                   std::vector<int> block_offsets, const std::vector<int>& block_sizes)
      : level_(level), finite_(finite), pixel_(pixel), offsets_(std::move(block_offsets)) {
    set_num_residuals(kPixelResiduals);
    for (int size : block_sizes) mutable_parameter_block_sizes()->push_back(size);
  }

  // The parameter offsets of the blocks, increasing.
  const std::vector<int>& block_offsets() const { return offsets_; }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (!*finite_) return false;
    const int x = pixel_ % level_->render.width, y = pixel_ / level_->render.width;
    const double sqrt_weight = level_->SqrtWeight(pixel_);
    for (int c = 0; c < 3; ++c) {
      residuals[c] = sqrt_weight *
                     (static_cast<double>(level_->render.at(x, y, c)) - level_->target.at(x, y, c));
    }
    if (jacobians == nullptr) return true;
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    for (size_t b = 0; b < sizes.size(); ++b) {
      if (jacobians[b] != nullptr) std::memset(jacobians[b], 0, sizeof(double) * 3 * sizes[b]);
    }
    const LevelRows& rows = level_->rows;
    if (rows.offsets.empty()) return true;
    // Entries and blocks are both sorted by parameter index: one merge pass.
    size_t b = 0;
    for (uint64_t i = rows.offsets[pixel_]; i < rows.offsets[pixel_ + 1]; ++i) {
      const RowEntry& e = rows.entries[i];
      while (b < offsets_.size() && offsets_[b] + sizes[b] <= e.param) ++b;
      if (b == offsets_.size()) break;
      if (e.param < offsets_[b] || jacobians[b] == nullptr) continue;
      const int col = e.param - offsets_[b];
      for (int c = 0; c < 3; ++c) jacobians[b][c * sizes[b] + col] = sqrt_weight * e.d[c];
    }
    return true;
  }

 private:
  const LevelCache* level_;
  const bool* finite_;
  int pixel_;
  std::vector<int> offsets_;
};

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_PYRAMID_PIXEL_H_
