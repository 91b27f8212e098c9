#include "tests/testing/test_images.h"

#include <cmath>

namespace sft {
namespace testing {

Image SmoothPattern(int width, int height, int shift) {
  Image image(width, height, 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double u = x + shift;
      for (int c = 0; c < 3; ++c) {
        image.at(x, y, c) = static_cast<float>(0.5 + 0.2 * std::sin(0.4 * u + 0.3 * y + c) +
                                               0.2 * std::cos(0.23 * u * (c + 1) - 0.5 * y));
      }
    }
  }
  return image;
}

}  // namespace testing
}  // namespace sft
