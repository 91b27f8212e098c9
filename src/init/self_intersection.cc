#include "src/init/self_intersection.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <exception>
#include <iterator>
#include <unordered_set>
#include <utility>
#include <vector>

#include "src/init/cgal_surface_mesh.h"

namespace sft {

int CountSelfIntersectingFaces(const TriMesh& mesh) {
  if (mesh.n_faces() == 0) return -1;
  SurfaceMesh surface;
  SoupRepairReport repair;
  if (!TriMeshToSurfaceMesh(mesh, &surface, &repair).ok()) return -1;
  using Face = SurfaceMesh::Face_index;
  std::vector<std::pair<Face, Face>> pairs;
  try {
    CGAL::Polygon_mesh_processing::self_intersections(surface, std::back_inserter(pairs));
  } catch (const std::exception&) {
    return -1;
  }
  // A degenerate face comes back as the pair (f, f).
  std::unordered_set<int> faces;
  for (const auto& [a, b] : pairs) {
    faces.insert(static_cast<int>(a.idx()));
    faces.insert(static_cast<int>(b.idx()));
  }
  return static_cast<int>(faces.size()) + repair.degenerate_faces + repair.duplicate_faces;
}

}  // namespace sft
