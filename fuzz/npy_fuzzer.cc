// libFuzzer target: the .npy parser, then the IDR camera conversion of the array as world_mat_0
// and scale_mat_0.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include "src/io/idr_cameras.h"
#include "src/io/npy.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  sft::NpyArray array;
  if (!sft::ParseNpy(bytes, "a.npy", &array).ok()) return 0;
  std::map<std::string, sft::NpyArray> arrays = {{"world_mat_0", array}, {"scale_mat_0", array}};
  sft::IdrCameras cameras;
  (void)sft::IdrCamerasFromArrays(arrays, "cameras.npz", &cameras);
  return 0;
}
