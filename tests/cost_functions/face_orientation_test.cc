#include "cost_functions/face_orientation.h"

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

namespace sft {
namespace {

// Away from the hinge's kink the residual is smooth: central differences agree with the
// automatic derivatives to 1e-7 relative (the residual is quadratic in the positions).
TEST(FaceOrientationTest, GradientCheckerOnBothSides) {
  const Eigen::Vector3d n(0, 0, 1);
  ceres::AutoDiffCostFunction<FaceOrientationResidual, 1, 3, 3, 3> cost(
      new FaceOrientationResidual(n, 0.5, 3.0, 0.25));
  // Folded (active) and healthy (zero) configurations.
  for (double z_flip : {-1.0, 1.0}) {
    double p0[3] = {0, 0, 0}, p1[3] = {1, 0.1, 0.05}, p2[3] = {0.2, z_flip, 0.1};
    const double* params[] = {p0, p1, p2};
    ceres::NumericDiffOptions numeric;
    ceres::GradientChecker checker(
        &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(params, 1e-7, &results)) << results.error_log;
    double residual = 0.0;
    cost.Evaluate(params, &residual, nullptr);
    if (z_flip > 0) {
      EXPECT_EQ(residual, 0.0);
    } else {
      // Signed area fraction: n·(u × v)/2 / 0.5 = (1·(−1) − 0.1·0.2) = −1.02; r = 3(−1.02 − 0.25).
      EXPECT_NEAR(residual, 3.0 * (-1.02 - 0.25), 1e-12);
    }
  }
}

// A Ceres solve with only the barrier unfolds a folded triangle (its signed area comes back
// above τ of the rest area).
TEST(FaceOrientationTest, SolveUnfoldsAFold) {
  TriMesh mesh;
  const auto a = mesh.add_vertex(TriMesh::Point(0, 0, 0));
  const auto b = mesh.add_vertex(TriMesh::Point(1, 0, 0));
  const auto c = mesh.add_vertex(TriMesh::Point(0, 1, 0));
  mesh.add_face(a, b, c);
  double p[3][3] = {{0, 0, 0}, {1, 0, 0}, {0.6, -0.4, 0}};  // c pulled across ab: folded.
  ceres::Problem problem;
  FaceOrientationOptions options;
  ASSERT_EQ(AddFaceOrientation(mesh, options, {p[0], p[1], p[2]}, &problem), 1);
  problem.SetParameterBlockConstant(p[0]);
  problem.SetParameterBlockConstant(p[1]);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  // Signed area over rest area (0.5): the y of c.
  EXPECT_GE(p[2][1], 0.25 - 1e-6);
}

}  // namespace
}  // namespace sft
