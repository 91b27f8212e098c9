// Procedural albedo patterns (the "procedural" material form): wood rings and value-noise fBm,
// evaluated in object space at the mesh-colors texels' representative points. Deterministic from
// the seed, independent of thread count.
#ifndef SFT_GEOMETRY_PROCEDURAL_PATTERN_H_
#define SFT_GEOMETRY_PROCEDURAL_PATTERN_H_

#include <cstdint>
#include <vector>

#include "src/geometry/mesh.h"
#include "src/geometry/mesh_colors.h"

namespace sft {

struct ProceduralPattern {
  bool wood = true;   // true: rings around the bounding box's longest axis; false: value noise.
  double scale = 10;  // features across the bounding-box diagonal; > 0.
  uint64_t seed = 0;  // noise seed.
};

// The pattern's mixing weight in [0, 1] of the second colour at every texel of mesh colors of
// `resolution` on `mesh` (texel order of MeshColors). Coordinates are normalized by the mesh's
// bounding box (centre, diagonal) so that `scale` counts features across the object whatever its
// size.
std::vector<double> ProceduralWeights(const TriMesh& mesh, const ProceduralPattern& pattern,
                                      int resolution);

}  // namespace sft

#endif  // SFT_GEOMETRY_PROCEDURAL_PATTERN_H_
