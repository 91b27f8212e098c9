// libFuzzer target: the scene.json reader (ParseSceneJson in src/io/dataset.h: the whole of
// ReadDataset but the file read; it opens no image).
#include <cstddef>
#include <cstdint>
#include <string>

#include "src/io/dataset.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sft::Dataset dataset;
  (void)sft::ParseSceneJson(std::string(reinterpret_cast<const char*>(data), size), "dataset",
                            &dataset);
  return 0;
}
