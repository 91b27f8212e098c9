// libFuzzer target: COLMAP text model parsers (cameras.txt, images.txt, points3D.txt) on the same
// input, then the cross-file check when all three parse.
#include <cstddef>
#include <cstdint>
#include <string>

#include "src/io/colmap_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  sft::ColmapModel model;
  const bool ok = sft::ParseColmapCamerasText(text, "cameras.txt", &model.cameras).ok() &
                  sft::ParseColmapImagesText(text, "images.txt", &model.images).ok() &
                  sft::ParseColmapPointsText(text, "points3D.txt", &model.points).ok();
  if (ok) (void)sft::CheckColmapModel(model, "model");
  return 0;
}
