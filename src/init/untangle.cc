#include "src/init/untangle.h"

#include <set>
#include <vector>

#include "src/init/self_intersection.h"

namespace sft {
namespace {

// The vertices of `faces` and those within `ring` edges of them.
std::vector<TriMesh::VertexHandle> Neighbourhood(const TriMesh& mesh, const std::vector<int>& faces,
                                                 int ring) {
  std::set<int> seen;
  std::vector<TriMesh::VertexHandle> frontier;
  for (int f : faces) {
    for (TriMesh::VertexHandle v : mesh.fv_range(mesh.face_handle(f))) {
      if (seen.insert(v.idx()).second) frontier.push_back(v);
    }
  }
  for (int r = 0; r < ring; ++r) {
    std::vector<TriMesh::VertexHandle> next;
    for (TriMesh::VertexHandle v : frontier) {
      for (TriMesh::VertexHandle n : mesh.vv_range(v)) {
        if (seen.insert(n.idx()).second) next.push_back(n);
      }
    }
    frontier = std::move(next);
  }
  std::vector<TriMesh::VertexHandle> out;
  for (int v : seen) out.push_back(mesh.vertex_handle(v));
  return out;
}

// One umbrella step on `vertices` (Jacobi: every move uses the positions before the step).
void SmoothStep(const std::vector<TriMesh::VertexHandle>& vertices, double step, TriMesh* mesh) {
  std::vector<TriMesh::Point> moved(vertices.size());
  for (size_t k = 0; k < vertices.size(); ++k) {
    const TriMesh::Point p = mesh->point(vertices[k]);
    TriMesh::Point mean(0, 0, 0);
    int count = 0;
    for (TriMesh::VertexHandle n : mesh->vv_range(vertices[k])) {
      mean += mesh->point(n);
      ++count;
    }
    moved[k] = count > 0 ? p + step * (mean / count - p) : p;
  }
  for (size_t k = 0; k < vertices.size(); ++k) mesh->set_point(vertices[k], moved[k]);
}

}  // namespace

bool UntangleOptions::Check(std::string* why) const {
  if (max_rounds < 1 || max_rounds > 100) {
    *why = "untangle: max_rounds must be in [1, 100]";
    return false;
  }
  if (ring < 0 || ring > 8 || smooth_steps < 1 || smooth_steps > 50) {
    *why = "untangle: ring must be in [0, 8] and smooth_steps in [1, 50]";
    return false;
  }
  if (!(step > 0 && step <= 1)) {
    *why = "untangle: step must be in (0, 1]";
    return false;
  }
  return true;
}

Status Untangle(const UntangleOptions& options, TriMesh* mesh, UntangleReport* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  *report = UntangleReport();
  std::vector<int> faces;
  if (!SelfIntersectingFaces(*mesh, &faces)) {
    return Status::Error("untangle: cannot list the self-intersecting faces of the mesh");
  }
  report->faces_before = report->faces_after = static_cast<int>(faces.size());
  if (faces.empty()) return Status::Ok();
  // Smoothing can also make things worse (a thin part shrinks until its sides cross): the mesh
  // ends at the round with the fewest intersecting faces, the input itself if none improved.
  const TriMesh input = *mesh;
  TriMesh best = *mesh;
  std::set<int> moved, best_moved;
  while (!faces.empty() && report->rounds < options.max_rounds) {
    // Each round widens the neighbourhood by one ring: a tangle that the first rounds' smoothing
    // cannot open is given more room.
    const std::vector<TriMesh::VertexHandle> vertices =
        Neighbourhood(*mesh, faces, options.ring + report->rounds);
    for (int s = 0; s < options.smooth_steps; ++s) SmoothStep(vertices, options.step, mesh);
    for (TriMesh::VertexHandle v : vertices) moved.insert(v.idx());
    ++report->rounds;
    if (!SelfIntersectingFaces(*mesh, &faces)) {
      *mesh = input;
      return Status::Error("untangle: cannot list the self-intersecting faces of the mesh");
    }
    if (static_cast<int>(faces.size()) < report->faces_after) {
      report->faces_after = static_cast<int>(faces.size());
      best = *mesh;
      best_moved = moved;
    }
  }
  *mesh = std::move(best);
  report->moved_vertices = static_cast<int>(best_moved.size());
  return Status::Ok();
}

}  // namespace sft
