// libFuzzer target: NeRF transforms.json parser, then each frame's camera at a fixed image size.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "src/io/nerf_transforms.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<sft::NerfFrame> frames;
  if (!sft::ParseNerfTransforms(text, "transforms.json", &frames).ok()) return 0;
  for (const sft::NerfFrame& frame : frames) {
    sft::Camera camera;
    (void)sft::NerfCamera(frame.intrinsics, 64, 48, "frame", &camera);
  }
  return 0;
}
