// Conversions between the project's TriMesh (OpenMesh) and CGAL's Surface_mesh for the CGAL 5.5
// Polygon Mesh Processing algorithms of src/init (remeshing, self-intersection tests). The way
// in repairs the triangle set into a combinatorial 2-manifold first, since TriMesh may hold
// pinched vertices (several fans of faces at one vertex) and position seams that CGAL's mesh
// algorithms do not accept.
//
// Kernel: Exact_predicates_inexact_constructions_kernel (double coordinates, exact predicates),
// which PMP's remeshing and self-intersection tests are documented to accept.
#ifndef SFT_INIT_CGAL_SURFACE_MESH_H_
#define SFT_INIT_CGAL_SURFACE_MESH_H_

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <Eigen/Core>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/mesh.h"

namespace sft {

using CgalKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalPoint = CgalKernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<CgalPoint>;

// What the repair on the way into CGAL changed.
struct SoupRepairReport {
  int merged_points = 0;      // vertices with the coordinates of an earlier vertex, merged into it.
  int degenerate_faces = 0;   // faces with a repeated corner after merging, dropped.
  int duplicate_faces = 0;    // faces with the corners of an earlier face (any order), dropped.
  int duplicated_points = 0;  // vertex copies made at non-manifold vertices and edges.
  bool closed = false;        // the repaired surface has no border edge.
};

// Builds `out` from the triangles `faces` over `positions`: merges vertices with equal
// coordinates, drops faces with a repeated corner and repeated faces, then copies vertices where
// the faces around a vertex or an edge do not form one disk (or are incompatibly oriented) so
// that the result is an oriented 2-manifold (CGAL PMP orient_polygon_soup, which keeps a
// consistently oriented input's orientation; then polygon_soup_to_polygon_mesh and
// duplicate_non_manifold_vertices). Vertices no face uses are left out. Faces with zero area but
// three distinct corners are kept. Errors: an index out of range, no face left, a CGAL failure.
Status ArraysToSurfaceMesh(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<Eigen::Vector3i>& faces, SurfaceMesh* out,
                           SoupRepairReport* report);
// The same from a TriMesh (its faces as MeshToArrays lists them).
Status TriMeshToSurfaceMesh(const TriMesh& mesh, SurfaceMesh* out, SoupRepairReport* report);

// Flat copies of a triangle Surface_mesh's vertices and faces (indices compacted past removed
// elements; corner order follows each face's halfedge cycle, so orientation is kept).
void SurfaceMeshToArrays(const SurfaceMesh& mesh, std::vector<Eigen::Vector3d>* positions,
                         std::vector<Eigen::Vector3i>* faces);

// A TriMesh with these vertices and faces, in order. Error when OpenMesh refuses a face (a
// non-manifold or inconsistently oriented face set).
Status ArraysToTriMesh(const std::vector<Eigen::Vector3d>& positions,
                       const std::vector<Eigen::Vector3i>& faces, TriMesh* out);

}  // namespace sft

#endif  // SFT_INIT_CGAL_SURFACE_MESH_H_
