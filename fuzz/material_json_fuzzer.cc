// libFuzzer target: the material JSON reader (LoadMaterial in src/geometry/material.h) on inline
// JSON, for a two-triangle mesh with per-corner UVs. Inputs that do not start with '{' would be
// taken as a file path and are skipped. File references inside the JSON are relative to the
// working directory (scripts/fuzz.sh runs the target in an empty folder).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"

namespace {

const sft::TriMesh& QuadMesh() {
  static const sft::TriMesh* mesh = [] {
    auto* m = new sft::TriMesh;
    const std::string obj =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
        "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    if (!sft::ParseMesh(obj, "quad.obj", m).ok()) std::abort();
    return m;
  }();
  return *mesh;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string spec(reinterpret_cast<const char*>(data), size);
  const size_t first = spec.find_first_not_of(" \t\r\n");
  if (first == std::string::npos || spec[first] != '{') return 0;
  sft::Material material;
  (void)sft::LoadMaterial(spec, QuadMesh(), &material);
  return 0;
}
