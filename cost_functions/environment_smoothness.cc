#include "cost_functions/environment_smoothness.h"

#include <glog/logging.h>

namespace sft {

std::vector<TexelPair> EnvironmentNeighbourPairs(int width, int height) {
  CHECK(width >= 1 && height >= 1);
  std::vector<TexelPair> pairs;
  if (width >= 2) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        // W = 2 would pair (0, 1) twice (right and wrap-around): once is enough.
        if (width == 2 && x == 1) continue;
        pairs.push_back({y * width + x, y * width + (x + 1) % width, false});
      }
    }
  }
  for (int y = 0; y + 1 < height; ++y) {
    for (int x = 0; x < width; ++x) pairs.push_back({y * width + x, (y + 1) * width + x, false});
  }
  return pairs;
}

}  // namespace sft
