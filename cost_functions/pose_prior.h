// The prior of one view's pose correction towards the dataset's pose (docs/reconstruct.md,
// "Camera poses").
//
// Residual (6 residuals), for the correction δ = (ω, τ) of one fitted view
// (src/optim/pose_corrections.h: ω a rotation vector in radians, τ a translation in scene units,
// both in the camera frame):
//
//   r_k = w_k · δ_k,  k = 0 … 5.
//
// Parameter blocks: [δ], 6 doubles (the view's pose correction in the flat parameter vector,
// src/optim/parameters.h). Jacobian: diag(w) (exact: the residual is linear).
// Evaluate never returns false. Derivative terms it does not have: none.
//
// The weights are relative (src/optim/regularizers.cc): w_k² = pose_prior · C_k, with C_k the
// image term's curvature along component k (RenderCache::PoseCurvature: the targets' gradient
// energy times the squared image motion per unit of the component: f² for a pan or tilt, r² for
// the roll about the optical axis, (f/z)² for a sideways shift and (r/z)² for a move along the
// axis, f the focal length and r a pixel's distance from the principal point in pixels, z the
// object's depth). A correction the photographs determine well (one that slides the image) then
// moves by about a fraction pose_prior of its size, while one they hardly see (a turn about the
// object with the matching shift, which moves the image little under world-fixed lights) is held
// near the dataset's pose instead of wandering.
#ifndef SFT_COST_FUNCTIONS_POSE_PRIOR_H_
#define SFT_COST_FUNCTIONS_POSE_PRIOR_H_

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace sft {

class PosePriorCost : public ceres::SizedCostFunction<6, 6> {
 public:
  // `weights`: w_0 … w_5 (ω then τ), finite and ≥ 0.
  explicit PosePriorCost(const Eigen::Matrix<double, 6, 1>& weights)
      : weights_{weights[0], weights[1], weights[2], weights[3], weights[4], weights[5]} {}

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
