// The pose prior (cost_functions/pose_prior.h): residuals by hand and the Jacobian by Ceres'
// gradient checker.
#include "cost_functions/pose_prior.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <vector>

namespace sft {
namespace {

// Central differences of a linear function: exact up to rounding.
constexpr double kGradientTolerance = 1e-7;

TEST(PosePriorCostTest, ResidualsAndGradientChecker) {
  Eigen::Matrix<double, 6, 1> w;
  w << 100.0, 100.0, 30.0, 20.0, 20.0, 4.0;
  const PosePriorCost cost(w);
  const double delta[6] = {0.01, -0.02, 0.0, 0.005, 0.0, -0.05};
  const double* parameters[] = {delta};
  double r[6];
  ASSERT_TRUE(cost.Evaluate(parameters, r, nullptr));
  const double expected[6] = {1.0, -2.0, 0.0, 0.1, 0.0, -0.2};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(r[k], expected[k], 1e-12) << k;
  ceres::NumericDiffOptions numeric;
  const ceres::GradientChecker checker(
      &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, kGradientTolerance, &results)) << results.error_log;
  // The Jacobian is diagonal: the weights.
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) EXPECT_DOUBLE_EQ(results.jacobians[0](i, j), i != j ? 0.0 : w[i]);
  }
}

}  // namespace
}  // namespace sft
