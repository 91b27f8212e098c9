// The prior of one view's pose correction towards the dataset's pose (docs/reconstruct.md,
// "Camera poses").
//
// Residual (6 residuals), for the correction δ = (ω, τ) of one fitted view
// (src/optim/pose_corrections.h: ω a rotation vector in radians, τ a translation in scene units,
// both in the camera frame):
//
//   r_k = w_rot · ω_k,  r_{3+k} = w_trans · τ_k,  k = 0, 1, 2.
//
// Parameter blocks: [δ], 6 doubles (the view's pose correction in the flat parameter vector,
// src/optim/parameters.h). Jacobian: diag(w_rot ×3, w_trans ×3) (exact: the residual is linear).
// Evaluate never returns false. Derivative terms it does not have: none.
//
// The weights are relative (src/optim/regularizers.cc): w² = pose_prior · C, with C the image
// term's curvature along a correction that shifts the view's image by one pixel per unit
// (RenderCache::PoseCurvature: the targets' gradient energy times f² for ω and (f/z)² for τ, f
// the focal length in pixels and z the object's depth). A correction the photographs determine
// well (one that slides the image) then moves by about a fraction pose_prior of its size, while
// one they hardly see (a turn about the object with the matching shift, which moves the image
// little under world-fixed lights) is held near the dataset's pose instead of wandering.
#ifndef SFT_COST_FUNCTIONS_POSE_PRIOR_H_
#define SFT_COST_FUNCTIONS_POSE_PRIOR_H_

#include <ceres/sized_cost_function.h>

namespace sft {

class PosePriorCost : public ceres::SizedCostFunction<6, 6> {
 public:
  // `w_rotation`, `w_translation`: finite and ≥ 0.
  PosePriorCost(double w_rotation, double w_translation)
      : weights_{w_rotation, w_rotation, w_rotation, w_translation, w_translation, w_translation} {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int k = 0; k < 6; ++k) residuals[k] = weights_[k] * parameters[0][k];
    if (jacobians == nullptr || jacobians[0] == nullptr) return true;
    for (int e = 0; e < 36; ++e) jacobians[0][e] = e % 7 == 0 ? weights_[e / 7] : 0.0;
    return true;
  }

 private:
  double weights_[6];
};

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_POSE_PRIOR_H_
