// The exposure prior (cost_functions/exposure_prior.h): residuals by hand and the Jacobian by
// Ceres' gradient checker.
#include "cost_functions/exposure_prior.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <vector>

namespace sft {
namespace {

// Central differences of a linear function: exact up to rounding.
constexpr double kGradientTolerance = 1e-7;

TEST(ExposurePriorCostTest, ResidualsAndGradientChecker) {
  const ExposurePriorCost cost(2.0, 3.0, 4.0);
  const double g[3] = {1.5, 1.0, 0.25};
  const double* parameters[] = {g};
  double r[3];
  ASSERT_TRUE(cost.Evaluate(parameters, r, nullptr));
  EXPECT_DOUBLE_EQ(r[0], 1.0);
  EXPECT_DOUBLE_EQ(r[1], 0.0);
  EXPECT_DOUBLE_EQ(r[2], -3.0);
  ceres::NumericDiffOptions numeric;
  const ceres::GradientChecker checker(
      &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, kGradientTolerance, &results)) << results.error_log;
  // The Jacobian is diagonal: w_c on the diagonal, 0 elsewhere.
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      EXPECT_DOUBLE_EQ(results.jacobians[0](i, j), i == j ? 2.0 + i : 0.0);
  }
}

}  // namespace
}  // namespace sft
