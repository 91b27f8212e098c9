// Agreement between a rendering and a reference image of the same view, as used to validate the
// renderer against Blender Cycles (issue 2): the mean absolute difference over object pixels
// relative to the reference's mean there, and block averages (which average Monte Carlo noise
// away) compared block by block.
#ifndef SFT_EVAL_IMAGE_COMPARE_H_
#define SFT_EVAL_IMAGE_COMPARE_H_

#include "src/core/image.h"

namespace sft {

struct ImageAgreement {
  int object_pixels = 0;
  double mean_reference = 0.0;       // mean over object pixels and RGB of the reference.
  double mean_abs_difference = 0.0;  // mean over object pixels and RGB of |ours − reference|.
  double relative_mean_abs_difference = 0.0;  // mean_abs_difference / mean_reference.
  double relative_mean_difference = 0.0;      // (mean(ours) − mean(reference)) / mean(reference).
  int blocks_compared = 0;
  double max_block_relative_difference = 0.0;  // over compared blocks, on RGB block means.
  double mean_block_relative_difference = 0.0;
};

struct ImageCompareOptions {
  int block = 8;                    // block size in pixels.
  double min_block_coverage = 0.5;  // a block is compared when its mean mask is at least this...
  double min_block_brightness =
      0.1;  // ...and its reference mean is at least this × mean_reference.
};

// `ours` and `reference` have ≥ 3 channels (RGB first) and equal sizes; `mask` 1 channel, > 0.5 =
// object. Only RGB enters the measures.
ImageAgreement CompareImages(const Image& ours, const Image& reference, const Image& mask,
                             const ImageCompareOptions& options = ImageCompareOptions());

}  // namespace sft

#endif  // SFT_EVAL_IMAGE_COMPARE_H_
