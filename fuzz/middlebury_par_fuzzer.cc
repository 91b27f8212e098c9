// libFuzzer target: Middlebury X_par.txt parser, then each entry's camera and pose.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "src/io/middlebury_par.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<sft::MiddleburyEntry> entries;
  if (!sft::ParseMiddleburyPar(text, "par.txt", &entries).ok()) return 0;
  for (const sft::MiddleburyEntry& entry : entries) {
    sft::Camera camera;
    sft::Rigid3d pose;
    (void)sft::MiddleburyCamera(entry, "par.txt", 640, 480, &camera);
    (void)sft::MiddleburyPose(entry, "par.txt", &pose);
  }
  return 0;
}
