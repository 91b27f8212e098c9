// libFuzzer target: the .npz reader (libzip container, then .npy members) and the IDR camera
// conversion of what it read.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include "src/io/idr_cameras.h"
#include "src/io/npz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  std::map<std::string, sft::NpyArray> arrays;
  if (!sft::ParseNpz(bytes, "cameras.npz", &arrays).ok()) return 0;
  sft::IdrCameras cameras;
  (void)sft::IdrCamerasFromArrays(arrays, "cameras.npz", &cameras);
  return 0;
}
