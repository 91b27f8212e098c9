#include "src/init/surface_cleanup.h"

#include <glog/logging.h>

#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModAspectRatioT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>

namespace sft {
namespace {

class UnionFind {
 public:
  explicit UnionFind(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int Find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Unite(int a, int b) { parent_[Find(a)] = Find(b); }

 private:
  std::vector<int> parent_;
};

uint64_t EdgeKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b);
}

// Triangles sharing each undirected edge.
std::unordered_map<uint64_t, std::vector<int>> EdgeTriangles(
    const std::vector<Eigen::Vector3i>& triangles) {
  std::unordered_map<uint64_t, std::vector<int>> edges;
  edges.reserve(triangles.size() * 2);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    for (int c = 0; c < 3; ++c) {
      edges[EdgeKey(triangles[t][c], triangles[t][(c + 1) % 3])].push_back(t);
    }
  }
  return edges;
}

// Gives each extra fan of triangles around a vertex its own copy of the vertex. `points` grows by
// the copies; returns how many vertices were split.
int SplitPinchedVertices(std::vector<Eigen::Vector3d>* points,
                         std::vector<Eigen::Vector3i>* triangles) {
  const int num_points = static_cast<int>(points->size());
  std::vector<std::vector<int>> incident(num_points);
  for (int t = 0; t < static_cast<int>(triangles->size()); ++t) {
    for (int c = 0; c < 3; ++c) incident[(*triangles)[t][c]].push_back(t);
  }
  int split = 0;
  for (int v = 0; v < num_points; ++v) {
    const std::vector<int>& faces = incident[v];
    if (faces.size() < 2) continue;
    // Two triangles around v are in the same fan when they share an edge (v, w).
    UnionFind fans(static_cast<int>(faces.size()));
    std::unordered_map<int, int> first_with_neighbour;  // w -> index into `faces`.
    for (int n = 0; n < static_cast<int>(faces.size()); ++n) {
      for (int c = 0; c < 3; ++c) {
        const int w = (*triangles)[faces[n]][c];
        if (w == v) continue;
        auto [it, inserted] = first_with_neighbour.emplace(w, n);
        if (!inserted) fans.Unite(n, it->second);
      }
    }
    std::unordered_map<int, int> copy_of_fan;  // fan root -> vertex index.
    const int first_root = fans.Find(0);
    copy_of_fan[first_root] = v;
    bool was_split = false;
    for (int n = 0; n < static_cast<int>(faces.size()); ++n) {
      const int root = fans.Find(n);
      auto it = copy_of_fan.find(root);
      if (it == copy_of_fan.end()) {
        points->push_back((*points)[v]);
        it = copy_of_fan.emplace(root, static_cast<int>(points->size()) - 1).first;
        was_split = true;
      }
      if (it->second == v) continue;
      Eigen::Vector3i& tri = (*triangles)[faces[n]];
      for (int c = 0; c < 3; ++c) {
        if (tri[c] == v) tri[c] = it->second;
      }
    }
    split += was_split;
  }
  return split;
}

double SignedVolume(const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Eigen::Vector3i>& triangles) {
  double volume = 0.0;
  for (const Eigen::Vector3i& t : triangles) {
    volume += points[t[0]].dot(points[t[1]].cross(points[t[2]]));
  }
  return volume / 6.0;
}

}  // namespace

Status BuildClosedSurface(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector3i>& triangles, TriMesh* mesh,
                          SurfaceCleanupReport* report) {
  *report = SurfaceCleanupReport();
  report->input_triangles = static_cast<int>(triangles.size());
  std::vector<Eigen::Vector3i> valid;
  valid.reserve(triangles.size());
  for (const Eigen::Vector3i& t : triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++report->degenerate_triangles;
    } else {
      valid.push_back(t);
    }
  }
  if (valid.empty()) return Status::Error("the extracted surface has no valid triangle");
  // Components over shared edges; keep the one with the most triangles.
  UnionFind components(static_cast<int>(valid.size()));
  for (const auto& [key, faces] : EdgeTriangles(valid)) {
    for (size_t n = 1; n < faces.size(); ++n) components.Unite(faces[0], faces[n]);
  }
  std::unordered_map<int, int> sizes;
  for (int t = 0; t < static_cast<int>(valid.size()); ++t) ++sizes[components.Find(t)];
  report->components = static_cast<int>(sizes.size());
  const int largest =
      std::max_element(sizes.begin(), sizes.end(), [](const auto& a, const auto& b) {
        return a.second < b.second;
      })->first;
  std::vector<Eigen::Vector3i> kept;
  for (int t = 0; t < static_cast<int>(valid.size()); ++t) {
    if (components.Find(t) == largest) kept.push_back(valid[t]);
  }
  report->dropped_triangles = static_cast<int>(valid.size() - kept.size());
  int open_edges = 0, non_manifold_edges = 0;
  for (const auto& [key, faces] : EdgeTriangles(kept)) {
    open_edges += faces.size() == 1;
    non_manifold_edges += faces.size() > 2;
  }
  if (open_edges > 0 || non_manifold_edges > 0) {
    return Status::Error("the extracted surface is not closed: " + std::to_string(open_edges) +
                         " open and " + std::to_string(non_manifold_edges) +
                         " non-manifold edges in its largest component");
  }
  // Compact the vertices to those the kept triangles use, then split pinched vertices.
  std::vector<int> remap(points.size(), -1);
  std::vector<Eigen::Vector3d> used;
  for (Eigen::Vector3i& t : kept) {
    for (int c = 0; c < 3; ++c) {
      if (remap[t[c]] < 0) {
        remap[t[c]] = static_cast<int>(used.size());
        used.push_back(points[t[c]]);
      }
      t[c] = remap[t[c]];
    }
  }
  report->split_vertices = SplitPinchedVertices(&used, &kept);
  if (SignedVolume(used, kept) < 0) {
    report->flipped = true;
    for (Eigen::Vector3i& t : kept) std::swap(t[1], t[2]);
  }
  mesh->clear();
  std::vector<TriMesh::VertexHandle> handles;
  handles.reserve(used.size());
  for (const Eigen::Vector3d& p : used) handles.push_back(mesh->add_vertex({p.x(), p.y(), p.z()}));
  for (const Eigen::Vector3i& t : kept) {
    if (!mesh->add_face(handles[t[0]], handles[t[1]], handles[t[2]]).is_valid()) {
      // With every edge shared by two consistently oriented triangles and single-fan vertices
      // this cannot happen; an inconsistent orientation between neighbours would.
      return Status::Error("the extracted surface is not orientable (OpenMesh refused a face)");
    }
  }
  std::string why;
  if (!IsClosedManifold(*mesh, &why)) return Status::Error("the extracted surface: " + why);
  return Status::Ok();
}

bool DecimationGuards::Check(std::string* why) const {
  if (!(max_normal_deviation_degrees > 0.0 && max_normal_deviation_degrees <= 180.0)) {
    *why = "max_normal_deviation_degrees must be in (0, 180], got " +
           std::to_string(max_normal_deviation_degrees);
    return false;
  }
  if (!(max_aspect_ratio == 0.0 || (max_aspect_ratio >= 1.2 && std::isfinite(max_aspect_ratio)))) {
    *why = "max_aspect_ratio must be 0 (off) or finite and at least 1.2, got " +
           std::to_string(max_aspect_ratio);
    return false;
  }
  return true;
}

void DecimateMesh(int target_faces, TriMesh* mesh, const DecimationGuards& guards) {
  std::string why;
  CHECK(guards.Check(&why)) << why;
  if (static_cast<int>(mesh->n_faces()) <= target_faces) return;
  using Decimater = OpenMesh::Decimater::DecimaterT<TriMesh>;
  using Quadric = OpenMesh::Decimater::ModQuadricT<TriMesh>::Handle;
  using NormalFlipping = OpenMesh::Decimater::ModNormalFlippingT<TriMesh>::Handle;
  using AspectRatio = OpenMesh::Decimater::ModAspectRatioT<TriMesh>::Handle;
  mesh->request_vertex_status();
  mesh->request_edge_status();
  mesh->request_face_status();
  mesh->request_face_normals();
  mesh->update_face_normals();
  {
    Decimater decimater(*mesh);
    Quadric quadric;
    NormalFlipping flipping;
    AspectRatio aspect;
    decimater.add(quadric);
    decimater.add(flipping);
    decimater.module(quadric).unset_max_err();
    decimater.module(flipping).set_max_normal_deviation(guards.max_normal_deviation_degrees);
    if (guards.max_aspect_ratio > 0.0) {
      decimater.add(aspect);
      decimater.module(aspect).set_aspect_ratio(static_cast<float>(guards.max_aspect_ratio));
    }
    decimater.initialize();
    decimater.decimate_to_faces(0, static_cast<size_t>(target_faces));
  }
  mesh->garbage_collection();
  mesh->release_face_normals();
}

bool IsClosedManifold(const TriMesh& mesh, std::string* why) {
  int boundary = 0;
  for (auto heh : mesh.halfedges()) boundary += mesh.is_boundary(heh);
  if (boundary > 0) {
    *why = std::to_string(boundary) + " boundary halfedges (not closed)";
    return false;
  }
  std::vector<int> face_count(mesh.n_vertices(), 0);
  for (auto fh : mesh.faces()) {
    for (auto vh : mesh.fv_range(fh)) ++face_count[vh.idx()];
  }
  int pinched = 0;
  for (auto vh : mesh.vertices()) {
    int fan = 0;
    for (auto fh : mesh.vf_range(vh)) {
      (void)fh;
      ++fan;
    }
    pinched += fan != face_count[vh.idx()] || fan == 0;
  }
  if (pinched > 0) {
    *why = std::to_string(pinched) + " vertices without exactly one fan of faces";
    return false;
  }
  return true;
}

double EnclosedVolume(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  return SignedVolume(positions, faces);
}

}  // namespace sft
