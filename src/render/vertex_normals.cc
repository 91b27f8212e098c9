#include "src/render/vertex_normals.h"

namespace sft {

void AngleWeightedNormalSums(const std::vector<Eigen::Vector3d>& positions,
                             const std::vector<Eigen::Vector3i>& faces,
                             const std::vector<int>& welded, std::vector<Eigen::Vector3d>* sums) {
  sums->assign(positions.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : faces) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d term = CornerNormalTerm<double>(
          positions[f[k]], positions[f[(k + 1) % 3]], positions[f[(k + 2) % 3]]);
      if (term.allFinite()) (*sums)[welded[f[k]]] += term;
    }
  }
}

}  // namespace sft
