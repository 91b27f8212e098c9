// Image: a float image, row-major with interleaved channels (1 = grey/mask, 3 = RGB, 4 = RGBA).
// Values are linear radiance for renders and decoded photographs; row 0 is the top row and pixel
// (x, y) covers [x, x+1] x [y, y+1] in image coordinates (docs/dataset.md).
#ifndef SFT_CORE_IMAGE_H_
#define SFT_CORE_IMAGE_H_

#include <cstddef>
#include <vector>

namespace sft {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> data;  // width * height * channels values.

  Image() = default;
  Image(int w, int h, int c, float fill = 0.0f)
      : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, fill) {}

  bool empty() const { return data.empty(); }
  size_t Index(int x, int y, int c = 0) const {
    return (static_cast<size_t>(y) * width + x) * channels + c;
  }
  float& at(int x, int y, int c = 0) { return data[Index(x, y, c)]; }
  float at(int x, int y, int c = 0) const { return data[Index(x, y, c)]; }
};

// The first three channels of `image` as RGB (a 1- or 2-channel image repeats its first channel;
// alpha and further channels are dropped).
inline Image ToRgb(const Image& image) {
  if (image.channels == 3) return image;
  Image rgb(image.width, image.height, 3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = image.at(x, y, image.channels >= 3 ? c : 0);
    }
  }
  return rgb;
}

}  // namespace sft

#endif  // SFT_CORE_IMAGE_H_
