// libFuzzer target: the mesh-colors file reader (ParseMeshColors in src/geometry/mesh_colors.h).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "src/geometry/mesh_colors.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sft::MeshColors colors;
  std::vector<std::string> names;
  (void)sft::ParseMeshColors(std::string(reinterpret_cast<const char*>(data), size),
                             "albedo.meshcolors", &colors, &names);
  return 0;
}
