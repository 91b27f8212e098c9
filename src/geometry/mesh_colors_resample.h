// Changing the texel resolution of mesh colours on an unchanged mesh (stages of the
// reconstruction with a different texel resolution).
//
// Nearest-texel resampling in the layout of src/geometry/mesh_colors.h: each texel of the new
// resolution takes the value of the old texel that contains its representative point
// (MeshColors::TexelCenter), on the same face. No filtering: going to a coarser resolution picks
// one old texel per new texel rather than averaging. Exact round trips: r → r is the identity,
// and r → k·r → r (k ≥ 1) gives back the original values, since the centre of texel (i, j) at r
// lies in a texel at k·r whose centre lies in (i, j) again.
#ifndef SFT_GEOMETRY_MESH_COLORS_RESAMPLE_H_
#define SFT_GEOMETRY_MESH_COLORS_RESAMPLE_H_

#include "src/geometry/mesh_colors.h"

namespace sft {

// `colors` at `new_resolution` (>= 0; a programming error otherwise), same faces and channels.
// A default-constructed (empty) MeshColors gives an empty one.
MeshColors ResampleMeshColors(const MeshColors& colors, int new_resolution);

}  // namespace sft

#endif  // SFT_GEOMETRY_MESH_COLORS_RESAMPLE_H_
