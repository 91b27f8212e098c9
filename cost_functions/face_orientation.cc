#include "cost_functions/face_orientation.h"

#include <glog/logging.h>

namespace sft {

int AddFaceOrientation(const TriMesh& rest, const FaceOrientationOptions& options,
                       const std::vector<double*>& vertex_blocks, ceres::Problem* problem) {
  CHECK_EQ(vertex_blocks.size(), rest.n_vertices());
  if (!(options.weight > 0.0)) return 0;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(rest, &positions, &faces);
  Eigen::Vector3d lo, hi;
  MeshBounds(rest, &lo, &hi);
  const double min_area = 1e-12 * (hi - lo).squaredNorm();
  int added = 0;
  for (const Eigen::Vector3i& f : faces) {
    const Eigen::Vector3d cross =
        (positions[f[1]] - positions[f[0]]).cross(positions[f[2]] - positions[f[0]]);
    const double area = 0.5 * cross.norm();
    if (!(area > min_area)) continue;
    auto* cost = new ceres::AutoDiffCostFunction<FaceOrientationResidual, 1, 3, 3, 3>(
        new FaceOrientationResidual(cross.normalized(), area, options.weight,
                                    options.min_fraction));
    problem->AddResidualBlock(cost, nullptr, vertex_blocks[f[0]], vertex_blocks[f[1]],
                              vertex_blocks[f[2]]);
    ++added;
  }
  return added;
}

}  // namespace sft
