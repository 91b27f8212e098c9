#include "cost_functions/texel_smoothness.h"

#include <glog/logging.h>

#include <cmath>

#include "src/geometry/mesh_colors.h"

namespace sft {
namespace {

// Global index of the texel of `face` that the mesh-colors lookup assigns to the point of the edge
// (u, v) at parameter s (weight 1 − s on u, s on v). `corners` is the face's vertex order.
int EdgePointTexel(const MeshColors& one_face, int face, const Eigen::Vector3i& corners, int u,
                   int v, double s) {
  double weights[3] = {0.0, 0.0, 0.0};
  for (int c = 0; c < 3; ++c) {
    if (corners[c] == u) weights[c] = 1.0 - s;
    if (corners[c] == v) weights[c] = s;
  }
  // α is the weight of the face's second vertex, β of its third.
  return face * MeshColors::TexelsPerFace(one_face.resolution()) +
         one_face.TexelIndex(0, weights[1], weights[2]);
}

void AddInFacePairs(int num_faces, int r, std::vector<TexelPair>* pairs) {
  const int per_face = MeshColors::TexelsPerFace(r);
  for (int f = 0; f < num_faces; ++f) {
    const int base = f * per_face;
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; i + j + 1 <= r; ++j) {
        const int here = base + MeshColors::LocalIndex(r, i, j);
        const int right = base + MeshColors::LocalIndex(r, i + 1, j);
        const int up = base + MeshColors::LocalIndex(r, i, j + 1);
        pairs->push_back({here, right, false});
        pairs->push_back({here, up, false});
        pairs->push_back({right, up, false});
      }
    }
  }
}

}  // namespace

std::vector<TexelPair> TexelNeighbourPairs(const TriMesh& mesh, int resolution) {
  CHECK_GE(resolution, 0);
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, nullptr, &faces);
  std::vector<TexelPair> pairs;
  AddInFacePairs(static_cast<int>(faces.size()), resolution, &pairs);

  const MeshColors one_face(1, resolution, 1);
  const int intervals = std::max(resolution, 1);
  for (TriMesh::EdgeHandle e : mesh.edges()) {
    if (mesh.is_boundary(e)) continue;
    const TriMesh::HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    const int u = mesh.from_vertex_handle(h).idx();
    const int v = mesh.to_vertex_handle(h).idx();
    const int f0 = mesh.face_handle(h).idx();
    const int f1 = mesh.face_handle(mesh.opposite_halfedge_handle(h)).idx();
    for (int k = 0; k < intervals; ++k) {
      const double s = (k + 0.5) / intervals;
      pairs.push_back({EdgePointTexel(one_face, f0, faces[f0], u, v, s),
                       EdgePointTexel(one_face, f1, faces[f1], u, v, s), true});
    }
  }
  return pairs;
}

bool TexelSmoothnessOptions::Check(std::string* why) const {
  if (!(weight >= 0.0 && std::isfinite(weight))) {
    *why = "weight: must be finite and >= 0, got " + std::to_string(weight);
    return false;
  }
  if (!(cross_face_weight >= 0.0 && std::isfinite(cross_face_weight))) {
    *why = "cross_face_weight: must be finite and >= 0, got " + std::to_string(cross_face_weight);
    return false;
  }
  return true;
}

int AddTexelSmoothness(const std::vector<TexelPair>& pairs, int channels,
                       const TexelSmoothnessOptions& options,
                       const std::vector<double*>& texel_blocks, ceres::Problem* problem) {
  std::string why;
  CHECK(options.Check(&why)) << "AddTexelSmoothness: " << why;
  CHECK(channels == 1 || channels == 3) << "AddTexelSmoothness: channels " << channels;
  int added = 0;
  for (const TexelPair& p : pairs) {
    CHECK(p.a >= 0 && p.b >= 0 && p.a < static_cast<int>(texel_blocks.size()) &&
          p.b < static_cast<int>(texel_blocks.size()))
        << "AddTexelSmoothness: pair (" << p.a << ", " << p.b << ") out of range";
    const double w = p.cross_face ? options.weight * options.cross_face_weight : options.weight;
    if (w == 0.0) continue;
    ceres::CostFunction* cost = nullptr;
    if (options.log_ratio) {
      cost = channels == 3 ? static_cast<ceres::CostFunction*>(new TexelLogRatioCost<3>(w))
                           : new TexelLogRatioCost<1>(w);
    } else {
      cost = channels == 3 ? static_cast<ceres::CostFunction*>(new TexelDifferenceCost<3>(w))
                           : new TexelDifferenceCost<1>(w);
    }
    problem->AddResidualBlock(cost, nullptr, texel_blocks[p.a], texel_blocks[p.b]);
    ++added;
  }
  return added;
}

}  // namespace sft
