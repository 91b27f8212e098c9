// libFuzzer target: COLMAP binary model parsers (cameras.bin, images.bin, points3D.bin) on the same
// input, then the cross-file check when all three parse.
#include <cstddef>
#include <cstdint>
#include <string>

#include "src/io/colmap_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  sft::ColmapModel model;
  const bool ok = sft::ParseColmapCamerasBinary(bytes, "cameras.bin", &model.cameras).ok() &
                  sft::ParseColmapImagesBinary(bytes, "images.bin", &model.images).ok() &
                  sft::ParseColmapPointsBinary(bytes, "points3D.bin", &model.points).ok();
  if (ok) (void)sft::CheckColmapModel(model, "model");
  return 0;
}
