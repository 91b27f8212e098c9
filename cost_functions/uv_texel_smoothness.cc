#include "cost_functions/uv_texel_smoothness.h"

namespace sft {

std::vector<TexelPair> UvTexelNeighbourPairs(const UvTexelCharts& charts) {
  std::vector<TexelPair> pairs;
  const int w = charts.width, h = charts.height;
  auto add = [&](int a, int b) {
    const int ca = charts.chart_of_texel[a];
    if (ca >= 0 && ca == charts.chart_of_texel[b]) pairs.push_back({a, b, false});
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x + 1 < w; ++x) add(y * w + x, y * w + x + 1);
  }
  for (int y = 0; y + 1 < h; ++y) {
    for (int x = 0; x < w; ++x) add(y * w + x, (y + 1) * w + x);
  }
  return pairs;
}

}  // namespace sft
