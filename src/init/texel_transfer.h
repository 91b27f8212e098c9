// Carrying mesh-colour texels across a topology change (remeshing) by re-projection onto the old
// surface.
//
// For every texel of the new mesh (layout: src/geometry/mesh_colors.h) its representative point
// x = MeshColors::TexelCenter on the new face is taken to the closest point of the old surface
// (CGAL 5.5 AABB_tree over the old triangles, closest_point_and_primitive), and the new texel
// gets the value of the old texel at that point (barycentrics on the old face, then
// MeshColors::TexelIndex): nearest-texel sampling, no filtering.
//
// Ties. A texel centre on an edge or a vertex of the new mesh (the zero-area texels i + j = r)
// would be equally close to several old faces where the surfaces agree; the old face is chosen
// with the query point moved a millionth of the way towards the new face's centroid, then the
// barycentrics are those of the closest point of that old face to the unmoved centre. So
// transferring onto the same mesh reproduces every texel exactly.
//
// Error of a transfer onto a mesh on the same surface: a texel's value stands for its whole
// region, whose points are at most (2/3)(|e1| + |e2|)/r from its centre (e1, e2 the edges from
// the face's first corner, r the old resolution), so a function with gradient g is reproduced
// within |g|·(2/3)(|e1| + |e2|)/r plus |g| times the distance between the surfaces.
//
// Old faces with collinear corners are left out of the search (they have no area to carry
// colour); the old mesh needs at least one other. Parallel over new faces (TBB).
#ifndef SFT_INIT_TEXEL_TRANSFER_H_
#define SFT_INIT_TEXEL_TRANSFER_H_

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/geometry/mesh_colors.h"

namespace sft {

// Mesh colours on `new_mesh` at `new_resolution` (in [0, 1024]) with old_colors' channels, each
// texel read from old_colors at the closest point of old_mesh. Errors: old_colors not sized for
// old_mesh, an empty mesh, no old face with area, a resolution out of range.
Status TransferMeshColors(const TriMesh& old_mesh, const MeshColors& old_colors,
                          const TriMesh& new_mesh, int new_resolution, MeshColors* out);

// The material's albedo and roughness transferred as above (one closest-point search per texel
// for both); specular and the Fresnel mode copied.
Status TransferMaterial(const TriMesh& old_mesh, const Material& old_material,
                        const TriMesh& new_mesh, int new_resolution, Material* out);

}  // namespace sft

#endif  // SFT_INIT_TEXEL_TRANSFER_H_
