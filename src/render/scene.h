// The Embree scene of one mesh state. Positions are kept in double for shading and derivatives;
// Embree traces a float copy. The scene is built with RTC_SCENE_FLAG_DYNAMIC and refit quality so
// that vertex updates (SetVertices) refit the BVH instead of rebuilding it (measured: 2–3 ms vs 32
// ms at 100k triangles), and RTC_SCENE_FLAG_ROBUST so that rays do not slip through shared edges.
#ifndef SFT_RENDER_SCENE_H_
#define SFT_RENDER_SCENE_H_

#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"

namespace sft {

struct RayHit {
  bool hit = false;
  double t = 0.0;
  int face = -1;
  double u = 0.0, v = 0.0;  // barycentrics: p = (1 − u − v)·p0 + u·p1 + v·p2 (Embree's).
};

// An edge of the welded mesh and the faces containing it (for edge sampling of visibility
// derivatives). Edges join welded vertices (RenderScene::WeldedVertex): split copies of a position
// (UV seams, per-face normals, triangle soups) are one point of the surface, so the edge between
// two faces that use different copies is still one interior edge, not two boundaries.
struct MeshEdge {
  int v0 = 0, v1 = 0;    // welded vertex indices, v0 < v1.
  int f0 = -1, f1 = -1;  // the first two faces containing the edge; -1 = none.
  int num_faces = 0;     // 1 = boundary edge, 2 = manifold, > 2 = non-manifold.
  // Winding of f1 relative to f0 across the edge: +1 when they traverse it in opposite
  // directions (consistently oriented), −1 when in the same direction (one is flipped relative to
  // the other, as in meshes with mixed winding or non-orientable ones). flip1·FaceNormal(f1) is
  // f1's normal oriented consistently with f0's, which is what classifying the edge (silhouette,
  // crease, coplanar) must use: face winding is not trusted.
  int flip1 = 1;
  // The original vertices that the faces use at the ends (RenderScene::edge_copies()): entries
  // [first_copy, first_copy + num_copies0) are copies of v0, the next num_copies1 copies of v1.
  int first_copy = 0;
  int num_copies0 = 0, num_copies1 = 0;
};

// An original vertex at an end of a welded edge and the share of the edge's motion derivative it
// receives: each face containing the edge contributes 1/num_faces to its own copy. The shares sum
// to one, so any displacement that moves all copies of a position together (the mesh stays
// closed) gets the welded edge's full derivative. Moving one copy alone tears the mesh open on
// one side and overlaps it on the other, where the image is not differentiable; the equal split
// is the symmetric choice there.
struct EdgeCopy {
  int vertex = 0;
  double weight = 0.0;
};

// One process-wide Embree device (its thread settings are process-wide anyway).
RTCDevice EmbreeDevice();

class RenderScene {
 public:
  RenderScene(const std::vector<Eigen::Vector3d>& positions,
              const std::vector<Eigen::Vector3i>& faces);
  explicit RenderScene(const TriMesh& mesh);
  ~RenderScene();
  RenderScene(const RenderScene&) = delete;
  RenderScene& operator=(const RenderScene&) = delete;

  // Moves the vertices (same count) and refits the BVH.
  void SetVertices(const std::vector<Eigen::Vector3d>& positions);

  // Ray queries. A ray Embree cannot take (non-finite or out-of-range origin or direction — Embree
  // rejects coordinates beyond ~1.8e18 —, a t_near that is negative or not finite, t_far < t_near)
  // is never passed to Embree: it hits nothing and is not occluded.
  RayHit Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_near,
                   double t_far) const;
  // Up to 8 rays from a common origin (camera rays) as one Embree packet (rtcIntersect8); lanes
  // are independent, so the results equal Intersect's up to Embree's packet arithmetic.
  void Intersect8(const Eigen::Vector3d& origin, const Eigen::Vector3d* dirs, int count,
                  RayHit* hits) const;
  bool Occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_near,
                double t_far) const;

  // Hit point from barycentrics (double precision, on the triangle's plane).
  Eigen::Vector3d Point(int face, double u, double v) const;
  // Unit geometric normal n = normalize((p1 − p0) × (p2 − p0)) (counter-clockwise = front);
  // zero for a degenerate face.
  Eigen::Vector3d FaceNormal(int face) const { return face_normals_[face]; }
  // The unit angle-weighted normal of vertex v's welded vertex (vertex_normals.h): faces are
  // taken counter-clockwise = front, so a mesh with mixed winding gets cancelling terms. Zero
  // when the sum vanishes (no non-degenerate face, or cancelling ones).
  const Eigen::Vector3d& VertexNormal(int v) const { return vertex_normals_[v]; }
  // The smooth shading normal at barycentrics (1 − u − v, u, v) of `face`: normalize(Σ b_j·N_j)
  // over its corners' vertex normals, as Cycles interpolates them. Falls back to the face's
  // geometric normal where that sum vanishes; zero for a degenerate face (never shaded).
  Eigen::Vector3d SmoothNormal(int face, double u, double v) const;

  const std::vector<Eigen::Vector3d>& positions() const { return positions_; }
  const std::vector<Eigen::Vector3i>& faces() const { return faces_; }
  // Unique edges of the welded mesh (topology fixed by construction: the welding uses the
  // positions given to the constructor and SetVertices keeps it); edges between two corners of a
  // face at the same welded vertex are left out (they have no length).
  const std::vector<MeshEdge>& edges() const { return edges_; }
  const std::vector<EdgeCopy>& edge_copies() const { return edge_copies_; }
  // The welded vertex of original vertex v: the smallest index among the referenced vertices with
  // exactly the same coordinates (no tolerance: only exact copies are welded, as exporters write
  // them; unreferenced and non-finite vertices are their own).
  int WeldedVertex(int v) const { return welded_[v]; }
  // Length of the bounding-box diagonal of the referenced vertices (those of some face: vertices
  // no face uses are not part of the surface and change nothing), for scale-relative tolerances.
  double extent() const { return extent_; }
  // Bounds of the referenced vertices (both zero when there are none).
  void Bounds(Eigen::Vector3d* lo, Eigen::Vector3d* hi) const;
  bool IsReferenced(int vertex) const { return referenced_[vertex] != 0; }
  // max_k |p_k|∞ over the face's corners: the magnitude that float rounding of the face (Embree
  // traces a float copy, and translates it to the ray origin) is relative to. Local ray offsets
  // and distance thresholds scale with it, so far-away faces do not change those of the others.
  double FaceScale(int face) const { return face_scales_[face]; }
  RTCScene embree_scene() const { return scene_; }
  // Identifies the geometry state (faces and positions): unique within the process, a new one
  // at construction and at every SetVertices. Caches of per-mesh-state structures (texel
  // segments, edge tables, shadow-edge candidates) key on it.
  uint64_t state_id() const { return state_id_; }

 private:
  void Build();
  void Weld();
  void BuildEdges();
  void UpdateDerived();

  std::vector<Eigen::Vector3d> positions_;
  std::vector<Eigen::Vector3i> faces_;
  std::vector<Eigen::Vector3d> face_normals_;
  std::vector<Eigen::Vector3d> vertex_normals_;  // per original vertex (its welded one's).
  std::vector<double> face_scales_;
  std::vector<char> referenced_;
  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero(), hi_ = Eigen::Vector3d::Zero();
  std::vector<MeshEdge> edges_;
  std::vector<EdgeCopy> edge_copies_;
  std::vector<int> welded_;
  double extent_ = 1.0;
  uint64_t state_id_ = 0;
  RTCScene scene_ = nullptr;
  RTCGeometry geometry_ = nullptr;
  float* vertex_buffer_ = nullptr;  // owned by Embree.
};

}  // namespace sft

#endif  // SFT_RENDER_SCENE_H_
