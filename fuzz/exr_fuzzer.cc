// libFuzzer target: the EXR reader (DecodeImage in src/image/image_io.h, the decoder behind
// ReadImage).
#include <cstddef>
#include <cstdint>
#include <string>

#include "src/core/image.h"
#include "src/image/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sft::Image image;
  (void)sft::DecodeImage(std::string(reinterpret_cast<const char*>(data), size), "image.exr",
                         &image);
  return 0;
}
