// The prior of one view's exposure gains towards 1 (docs/reconstruct.md, "Exposure and white
// balance").
//
// Residual (3 residuals), for the gains g = (g_R, g_G, g_B) of one fitted view:
//
//   r_c = w_c · (g_c − 1)
//
// Parameter blocks: [g], 3 doubles (the view's gains in the flat parameter vector,
// src/optim/parameters.h). Jacobian: ∂r/∂g = diag(w) (exact: the residual is linear).
// Evaluate never returns false. Derivative terms it does not have: none.
//
// The weights are relative (src/optim/regularizers.cc): w_c² = exposure_prior · E_c, with E_c =
// Σ_l Σ_p w_lp T_lpc² the view's photograph energy in channel c over the active pixels of every
// pyramid level, weighted like the residuals (RenderCache::GainCurvature) — the image term's
// curvature in g_c at a fit that matches the photograph. exposure_prior is then the prior's
// weight as a fraction of the photograph's evidence, whatever the image size and brightness: a
// gain the photographs alone put at g* ends at about (g* + λ)/(1 + λ) for λ = exposure_prior.
#ifndef SFT_COST_FUNCTIONS_EXPOSURE_PRIOR_H_
#define SFT_COST_FUNCTIONS_EXPOSURE_PRIOR_H_

#include <ceres/sized_cost_function.h>

namespace sft {

class ExposurePriorCost : public ceres::SizedCostFunction<3, 3> {
 public:
  // `weights` are w_R, w_G, w_B, finite and ≥ 0.
  ExposurePriorCost(double w_r, double w_g, double w_b) : weights_{w_r, w_g, w_b} {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int c = 0; c < 3; ++c) residuals[c] = weights_[c] * (parameters[0][c] - 1.0);
    if (jacobians == nullptr || jacobians[0] == nullptr) return true;
    for (int e = 0; e < 9; ++e) jacobians[0][e] = e % 4 == 0 ? weights_[e / 4] : 0.0;
    return true;
  }

 private:
  double weights_[3];
};

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_EXPOSURE_PRIOR_H_
