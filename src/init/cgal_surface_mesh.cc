#include "src/init/cgal_surface_mesh.h"

#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <array>
#include <exception>
#include <map>
#include <set>
#include <string>

namespace sft {
namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

// Merges vertices with equal coordinates and drops faces that become degenerate or repeat an
// earlier face. Only vertices some kept face uses enter `points`.
Status WeldSoup(const std::vector<Eigen::Vector3d>& positions,
                const std::vector<Eigen::Vector3i>& faces, std::vector<CgalPoint>* points,
                std::vector<std::vector<std::size_t>>* polygons, SoupRepairReport* report) {
  const int num_positions = static_cast<int>(positions.size());
  std::map<std::array<double, 3>, int> index_of_coordinates;
  std::vector<int> welded(positions.size(), -1);
  std::set<std::array<int, 3>> seen_faces;
  for (size_t f = 0; f < faces.size(); ++f) {
    std::array<int, 3> corners;
    for (int c = 0; c < 3; ++c) {
      const int v = faces[f][c];
      if (v < 0 || v >= num_positions) {
        return Status::Error("face " + std::to_string(f) + " has vertex index " +
                             std::to_string(v) + " out of range [0, " +
                             std::to_string(num_positions) + ")");
      }
      if (welded[v] < 0) {
        const Eigen::Vector3d& p = positions[v];
        const auto [it, inserted] = index_of_coordinates.emplace(
            std::array<double, 3>{p.x(), p.y(), p.z()}, static_cast<int>(points->size()));
        if (inserted) points->emplace_back(p.x(), p.y(), p.z());
        welded[v] = it->second;
        if (!inserted) ++report->merged_points;
      }
      corners[c] = welded[v];
    }
    if (corners[0] == corners[1] || corners[1] == corners[2] || corners[0] == corners[2]) {
      ++report->degenerate_faces;
      continue;
    }
    std::array<int, 3> sorted = corners;
    std::sort(sorted.begin(), sorted.end());
    if (!seen_faces.insert(sorted).second) {
      ++report->duplicate_faces;
      continue;
    }
    polygons->push_back({static_cast<std::size_t>(corners[0]), static_cast<std::size_t>(corners[1]),
                         static_cast<std::size_t>(corners[2])});
  }
  // Leave out the points that only dropped faces used (the mesh would keep them as isolated
  // vertices).
  std::vector<std::size_t> compact(points->size(), points->size());
  std::vector<CgalPoint> kept;
  for (std::vector<std::size_t>& polygon : *polygons) {
    for (std::size_t& v : polygon) {
      if (compact[v] == points->size()) {
        compact[v] = kept.size();
        kept.push_back((*points)[v]);
      }
      v = compact[v];
    }
  }
  points->swap(kept);
  return Status::Ok();
}

}  // namespace

Status ArraysToSurfaceMesh(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<Eigen::Vector3i>& faces, SurfaceMesh* out,
                           SoupRepairReport* report) {
  *report = SoupRepairReport();
  out->clear();
  std::vector<CgalPoint> points;
  std::vector<std::vector<std::size_t>> polygons;
  SFT_RETURN_IF_ERROR(WeldSoup(positions, faces, &points, &polygons, report));
  if (polygons.empty()) {
    return Status::Error("no face with three distinct vertices among " +
                         std::to_string(faces.size()) + " faces");
  }
  try {
    const size_t points_before = points.size();
    PMP::orient_polygon_soup(points, polygons);
    report->duplicated_points = static_cast<int>(points.size() - points_before);
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
      return Status::Error("the faces could not be made a 2-manifold (CGAL orient_polygon_soup)");
    }
    PMP::polygon_soup_to_polygon_mesh(points, polygons, *out);
    report->duplicated_points += static_cast<int>(PMP::duplicate_non_manifold_vertices(*out));
    report->closed = CGAL::is_closed(*out);
  } catch (const std::exception& e) {
    out->clear();
    return Status::Error(std::string("CGAL failed while building the surface mesh: ") + e.what());
  }
  return Status::Ok();
}

Status TriMeshToSurfaceMesh(const TriMesh& mesh, SurfaceMesh* out, SoupRepairReport* report) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  return ArraysToSurfaceMesh(positions, faces, out, report);
}

void SurfaceMeshToArrays(const SurfaceMesh& mesh, std::vector<Eigen::Vector3d>* positions,
                         std::vector<Eigen::Vector3i>* faces) {
  positions->clear();
  faces->clear();
  std::vector<int> compact(mesh.num_vertices(), -1);  // num_vertices counts removed ones too.
  for (SurfaceMesh::Vertex_index v : mesh.vertices()) {
    compact[v.idx()] = static_cast<int>(positions->size());
    const CgalPoint& p = mesh.point(v);
    positions->emplace_back(p.x(), p.y(), p.z());
  }
  faces->reserve(mesh.number_of_faces());
  for (SurfaceMesh::Face_index f : mesh.faces()) {
    Eigen::Vector3i face(-1, -1, -1);
    int c = 0;
    for (SurfaceMesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      if (c < 3) face[c] = compact[v.idx()];
      ++c;
    }
    faces->push_back(face);
  }
}

Status ArraysToTriMesh(const std::vector<Eigen::Vector3d>& positions,
                       const std::vector<Eigen::Vector3i>& faces, TriMesh* out) {
  out->clear();
  std::vector<TriMesh::VertexHandle> handles;
  handles.reserve(positions.size());
  for (const Eigen::Vector3d& p : positions)
    handles.push_back(out->add_vertex({p.x(), p.y(), p.z()}));
  const int num_positions = static_cast<int>(positions.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    const Eigen::Vector3i& t = faces[f];
    if (t.minCoeff() < 0 || t.maxCoeff() >= num_positions) {
      return Status::Error("face " + std::to_string(f) + " has a vertex index out of range");
    }
    if (!out->add_face(handles[t[0]], handles[t[1]], handles[t[2]]).is_valid()) {
      return Status::Error("OpenMesh refused face " + std::to_string(f) +
                           " (non-manifold or inconsistently oriented)");
    }
  }
  return Status::Ok();
}

}  // namespace sft
