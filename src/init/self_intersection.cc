#include "src/init/self_intersection.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <algorithm>
#include <exception>
#include <iterator>
#include <unordered_set>
#include <utility>
#include <vector>

#include "src/init/cgal_surface_mesh.h"

namespace sft {
namespace {

// The repaired surface's intersecting faces (surface face indices); false on failure.
bool IntersectingSurfaceFaces(const TriMesh& mesh, std::unordered_set<int>* faces,
                              SoupRepairReport* repair) {
  if (mesh.n_faces() == 0) return false;
  SurfaceMesh surface;
  if (!TriMeshToSurfaceMesh(mesh, &surface, repair).ok()) return false;
  using Face = SurfaceMesh::Face_index;
  std::vector<std::pair<Face, Face>> pairs;
  try {
    CGAL::Polygon_mesh_processing::self_intersections(surface, std::back_inserter(pairs));
  } catch (const std::exception&) {
    return false;
  }
  // A degenerate face comes back as the pair (f, f).
  for (const auto& [a, b] : pairs) {
    faces->insert(static_cast<int>(a.idx()));
    faces->insert(static_cast<int>(b.idx()));
  }
  return true;
}

}  // namespace

int CountSelfIntersectingFaces(const TriMesh& mesh) {
  std::unordered_set<int> faces;
  SoupRepairReport repair;
  if (!IntersectingSurfaceFaces(mesh, &faces, &repair)) return -1;
  return static_cast<int>(faces.size()) + repair.degenerate_faces + repair.duplicate_faces;
}

bool SelfIntersectingFaces(const TriMesh& mesh, std::vector<int>* faces) {
  faces->clear();
  std::unordered_set<int> found;
  SoupRepairReport repair;
  if (!IntersectingSurfaceFaces(mesh, &found, &repair)) return false;
  // The soup keeps the faces in order unless the repair dropped some (vertex merges and copies
  // do not renumber faces).
  if (repair.degenerate_faces > 0 || repair.duplicate_faces > 0) return false;
  faces->assign(found.begin(), found.end());
  std::sort(faces->begin(), faces->end());
  return true;
}

}  // namespace sft
