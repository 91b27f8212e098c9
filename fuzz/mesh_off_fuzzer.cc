// libFuzzer target: the mesh reader's OFF parser (ParseMesh in src/geometry/mesh.h), including the
// triangulation of polygons and the OpenMesh build.
#include <cstddef>
#include <cstdint>
#include <string>

#include "src/geometry/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sft::TriMesh mesh;
  sft::MeshReport report;
  (void)sft::ParseMesh(std::string(reinterpret_cast<const char*>(data), size), "mesh.off", &mesh,
                       &report);
  return 0;
}
