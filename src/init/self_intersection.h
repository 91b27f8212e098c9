// Counting self-intersecting faces of a triangle mesh, to detect an optimisation that pushed the
// surface through itself (a topology change is then due).
//
// CGAL 5.5 Polygon_mesh_processing::self_intersections over a CGAL::Surface_mesh with the
// Exact_predicates_inexact_constructions_kernel: the test only evaluates predicates on the input
// coordinates (box overlap, then exact triangle-triangle and segment-triangle predicates), so the
// answer is exact for the double-precision vertices. Faces that share a vertex or an edge count
// only when they meet beyond what they share.
#ifndef SFT_INIT_SELF_INTERSECTION_H_
#define SFT_INIT_SELF_INTERSECTION_H_

#include <vector>

#include "src/geometry/mesh.h"

namespace sft {

// The number of distinct faces that intersect some other face. The mesh goes through the repair
// of src/init/cgal_surface_mesh.h first (vertices with equal coordinates merged, non-manifold
// vertices and edges given copies), with these consequences: sheets that only touch at a
// non-manifold vertex or edge count as intersecting there; a degenerate face (collinear corners,
// or a corner repeated after merging) counts as self-intersecting, and so does each extra copy of
// a repeated face. Returns −1 when the mesh has no faces or CGAL fails.
int CountSelfIntersectingFaces(const TriMesh& mesh);

// The indices (into `mesh`'s faces, increasing) of the faces that intersect some other face.
// False when the answer cannot be given in `mesh`'s indices: no faces, a CGAL failure, or a
// repair that dropped faces (degenerate or repeated ones).
bool SelfIntersectingFaces(const TriMesh& mesh, std::vector<int>* faces);

}  // namespace sft

#endif  // SFT_INIT_SELF_INTERSECTION_H_
