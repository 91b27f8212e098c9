// Mesh colors (Yuksel et al. 2010, in the layout of the Shape-from-Tracing report's appendix):
// per-triangle texels on a regular barycentric grid of resolution r.
//
// Layout. Triangle t with vertices (v0, v1, v2); a point p = (1 - α - β)·v0 + α·v1 + β·v2, i.e.
// α is the barycentric weight of the face's second vertex and β of its third (Embree's u, v).
// Its texel is (i, j) = (floor(r·α), floor(r·β)), and the global texel index is
//   k = (t·(r+1)(r+2) + i·(2r − i + 3)) / 2 + j,
// so each triangle owns (r+1)(r+2)/2 consecutive texels, row i holding r − i + 1 texels
// (j = 0..r−i). Vertex and edge texels are duplicated per triangle (not shared), as in the report.
// Since floor(rα) + floor(rβ) ≤ floor(r(α+β)) ≤ r, i + j ≤ r for every point of the triangle;
// points outside it (α, β < 0 or α + β > 1 by rounding) are clamped into it first.
// Texel (i, j)'s representative point (used to sample materials into texels) is the centroid of
// the part of the triangle that maps to it.
#ifndef SFT_GEOMETRY_MESH_COLORS_H_
#define SFT_GEOMETRY_MESH_COLORS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

class MeshColors {
 public:
  MeshColors() = default;
  // `channels` values per texel, all set to `fill`.
  MeshColors(int num_faces, int resolution, int channels, double fill = 0.0);

  static int TexelsPerFace(int resolution) { return (resolution + 1) * (resolution + 2) / 2; }
  // Index of (i, j) within a face's texels: i·(2r − i + 3)/2 + j.
  static int LocalIndex(int resolution, int i, int j) {
    return i * (2 * resolution - i + 3) / 2 + j;
  }
  // Global texel index of the point (alpha, beta) of `face` (see the layout above).
  int TexelIndex(int face, double alpha, double beta) const;
  // Barycentric (α, β) of the representative point of local texel (i, j).
  static Eigen::Vector2d TexelCenter(int resolution, int i, int j);

  int num_faces() const { return num_faces_; }
  int resolution() const { return resolution_; }
  int channels() const { return channels_; }
  int num_texels() const { return num_faces_ * TexelsPerFace(resolution_); }

  double* texel(int k) { return &values_[static_cast<size_t>(k) * channels_]; }
  const double* texel(int k) const { return &values_[static_cast<size_t>(k) * channels_]; }
  std::vector<double>& values() { return values_; }
  const std::vector<double>& values() const { return values_; }

 private:
  int num_faces_ = 0;
  int resolution_ = 0;
  int channels_ = 0;
  std::vector<double> values_;
};

// The mesh-colors file, one file per attribute set: a one-line JSON header terminated by '\n'
//   {"format": "sft-mesh-colors/1", "num_faces": F, "resolution": r, "channels": C,
//    "names": [...], "dtype": "float32", "byte_order": "little"}
// followed by F·(r+1)(r+2)/2·C little-endian float32 values in texel order.
// Written atomically. Reading checks the header fields and the payload size.
Status WriteMeshColors(const std::string& path, const MeshColors& colors,
                       const std::vector<std::string>& channel_names);
Status ReadMeshColors(const std::string& path, MeshColors* colors,
                      std::vector<std::string>* channel_names = nullptr);
// The same from a file's contents held in memory; `path` names the file in errors.
Status ParseMeshColors(const std::string& data, const std::string& path, MeshColors* colors,
                       std::vector<std::string>* channel_names = nullptr);

}  // namespace sft

#endif  // SFT_GEOMETRY_MESH_COLORS_H_
