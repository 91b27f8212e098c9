// Face adjacency of a triangle list for the UV atlas (src/atlas/charts.h): which faces meet
// across which edge, which faces use which vertex, and the per-face geometry the charting needs.
//
// An edge joins two faces only when exactly two faces use it and they traverse it in opposite
// directions (a consistently oriented manifold edge). Every other shared edge — a non-manifold edge
// (three or more faces), or two faces that disagree about orientation — is cut: it becomes a
// border of every chart, which is how the atlas "splits" non-manifold edges. A face with a
// repeated vertex index or (near-)zero area is "degenerate" and never enters a chart.
#ifndef SFT_ATLAS_MESH_TOPOLOGY_H_
#define SFT_ATLAS_MESH_TOPOLOGY_H_

#include <Eigen/Core>
#include <array>
#include <vector>

namespace sft {

class MeshTopology {
 public:
  // `faces` index into `positions`; indices must be in range (checked by the caller). Both are
  // referenced, not copied: they must outlive the topology.
  MeshTopology(const std::vector<Eigen::Vector3d>& positions,
               const std::vector<Eigen::Vector3i>& faces);

  int num_faces() const { return static_cast<int>(faces_.size()); }
  const std::vector<Eigen::Vector3d>& positions() const { return positions_; }
  const Eigen::Vector3i& face(int f) const { return faces_[f]; }

  // The face across edge e of face f (edge e runs from corner e to corner (e + 1) % 3), or -1 at a
  // border or a cut edge.
  int Neighbour(int f, int e) const { return neighbours_[f][e]; }
  // Every face that uses vertex v (non-degenerate faces only).
  const std::vector<int>& VertexFaces(int v) const { return vertex_faces_[v]; }

  bool degenerate(int f) const { return degenerate_[f]; }
  const Eigen::Vector3d& normal(int f) const { return normals_[f]; }  // unit; zero if degenerate.
  double area(int f) const { return areas_[f]; }
  const Eigen::Vector3d& centroid(int f) const { return centroids_[f]; }
  // The interior angle of face f at corner k (radians; 0 for degenerate faces).
  double angle(int f, int k) const { return angles_[f][k]; }

  int num_degenerate_faces() const { return num_degenerate_; }
  int num_nonmanifold_edges() const { return num_nonmanifold_edges_; }    // used by 3+ faces.
  int num_inconsistent_edges() const { return num_inconsistent_edges_; }  // orientation clash.

 private:
  const std::vector<Eigen::Vector3d>& positions_;
  const std::vector<Eigen::Vector3i>& faces_;
  std::vector<std::array<int, 3>> neighbours_;
  std::vector<std::vector<int>> vertex_faces_;
  std::vector<bool> degenerate_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<double> areas_;
  std::vector<Eigen::Vector3d> centroids_;
  std::vector<std::array<double, 3>> angles_;
  int num_degenerate_ = 0;
  int num_nonmanifold_edges_ = 0;
  int num_inconsistent_edges_ = 0;
};

}  // namespace sft

#endif  // SFT_ATLAS_MESH_TOPOLOGY_H_
