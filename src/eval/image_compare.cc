#include "src/eval/image_compare.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>

namespace sft {

ImageAgreement CompareImages(const Image& ours, const Image& reference, const Image& mask,
                             const ImageCompareOptions& options) {
  CHECK_EQ(ours.width, reference.width);
  CHECK_EQ(ours.height, reference.height);
  CHECK_EQ(mask.width, reference.width);
  CHECK_EQ(mask.height, reference.height);
  CHECK_GE(ours.channels, 3);
  CHECK_GE(reference.channels, 3);
  ImageAgreement result;
  double sum_ref = 0.0, sum_ours = 0.0, sum_abs = 0.0;
  for (int y = 0; y < reference.height; ++y) {
    for (int x = 0; x < reference.width; ++x) {
      if (mask.at(x, y) <= 0.5f) continue;
      ++result.object_pixels;
      for (int c = 0; c < 3; ++c) {
        sum_ref += reference.at(x, y, c);
        sum_ours += ours.at(x, y, c);
        sum_abs += std::abs(ours.at(x, y, c) - reference.at(x, y, c));
      }
    }
  }
  if (result.object_pixels == 0) return result;
  const double n = 3.0 * result.object_pixels;
  result.mean_reference = sum_ref / n;
  result.mean_abs_difference = sum_abs / n;
  if (result.mean_reference > 0) {
    result.relative_mean_abs_difference = result.mean_abs_difference / result.mean_reference;
    result.relative_mean_difference = (sum_ours - sum_ref) / sum_ref;
  }
  const int b = options.block;
  double sum_block_rel = 0.0;
  for (int by = 0; by + b <= reference.height; by += b) {
    for (int bx = 0; bx + b <= reference.width; bx += b) {
      double coverage = 0.0, block_ref = 0.0, block_ours = 0.0;
      for (int y = by; y < by + b; ++y) {
        for (int x = bx; x < bx + b; ++x) {
          coverage += mask.at(x, y) > 0.5f ? 1.0 : 0.0;
          for (int c = 0; c < 3; ++c) {
            block_ref += reference.at(x, y, c);
            block_ours += ours.at(x, y, c);
          }
        }
      }
      coverage /= b * b;
      block_ref /= 3.0 * b * b;
      block_ours /= 3.0 * b * b;
      if (coverage < options.min_block_coverage) continue;
      if (block_ref < options.min_block_brightness * result.mean_reference) continue;
      const double rel = std::abs(block_ours - block_ref) / block_ref;
      ++result.blocks_compared;
      sum_block_rel += rel;
      result.max_block_relative_difference = std::max(result.max_block_relative_difference, rel);
    }
  }
  if (result.blocks_compared > 0) {
    result.mean_block_relative_difference = sum_block_rel / result.blocks_compared;
  }
  return result;
}

}  // namespace sft
