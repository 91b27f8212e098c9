#include "src/optim/regularizers.h"

#include <cmath>

namespace sft {

bool RegularizerOptions::Check(std::string* why) const {
  for (double w : {laplacian_weight, albedo_smoothness, roughness_smoothness}) {
    if (!(w >= 0.0 && std::isfinite(w))) {
      *why = "regularizer weights must be finite and >= 0";
      return false;
    }
  }
  return true;
}

void AddRegularizers(const TriMesh& rest, const ActiveParameters& active,
                     const RegularizerOptions& options, const ParameterBounds& bounds,
                     const Material& material, SceneParameters* params, ceres::Problem* problem) {
  // Filled in with the cost functions of cost_functions/ (merge pending).
}

}  // namespace sft
