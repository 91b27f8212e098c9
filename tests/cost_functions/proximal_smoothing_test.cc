// The smoothing proximal term (cost_functions/proximal_smoothing.h): Jacobians against numeric
// differences, zero at the anchor, the assembled Jacobian is w·(I + λL) with L = D − A built here
// from the faces, and a proximal step is smoother than a Tikhonov step for the same data term.
#include "cost_functions/proximal_smoothing.h"

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <set>
#include <utility>

#include "src/core/rng.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// Central numeric differences of a linear function are exact up to rounding (~1e-10 relative with
// Ceres' default step), so a wrong Jacobian entry shows far above this.
constexpr double kGradientTolerance = 1e-7;

double Uniform(uint64_t key) { return static_cast<double>(Mix64(key) >> 11) * 0x1.0p-53; }

TriMesh Sphere() {
  TriMesh mesh;
  CHECK(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &mesh).ok());
  return mesh;
}

std::vector<double> Coordinates(const TriMesh& mesh) {
  std::vector<double> xyz;
  for (TriMesh::VertexHandle v : mesh.vertices()) {
    for (int c = 0; c < 3; ++c) xyz.push_back(mesh.point(v)[c]);
  }
  return xyz;
}

// The undirected edges of the mesh's faces, (i, j) with i < j: built from the faces, not from the
// halfedge structure the cost function uses.
std::set<std::pair<int, int>> Edges(const TriMesh& mesh) {
  std::set<std::pair<int, int>> edges;
  for (TriMesh::FaceHandle f : mesh.faces()) {
    std::vector<int> v;
    for (TriMesh::VertexHandle h : mesh.fv_range(f)) v.push_back(h.idx());
    for (int k = 0; k < 3; ++k) {
      const int a = v[k], b = v[(k + 1) % 3];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  return edges;
}

// L = D − A of the mesh (dense: the test meshes are small).
Eigen::MatrixXd CombinatorialLaplacian(const TriMesh& mesh) {
  const int n = static_cast<int>(mesh.n_vertices());
  Eigen::MatrixXd laplacian = Eigen::MatrixXd::Zero(n, n);
  for (const auto& [i, j] : Edges(mesh)) {
    laplacian(i, j) = laplacian(j, i) = -1.0;
    laplacian(i, i) += 1.0;
    laplacian(j, j) += 1.0;
  }
  return laplacian;
}

// δᵀLδ / δᵀδ summed over x, y, z: the Dirichlet energy per unit squared norm of a displacement
// field (n × 3), low for smooth fields, up to the largest eigenvalue of L for alternating ones.
double RelativeLaplacianEnergy(const Eigen::MatrixXd& laplacian, const Eigen::MatrixXd& delta) {
  return (delta.transpose() * laplacian * delta).trace() / delta.squaredNorm();
}

TEST(ProximalSmoothingCostTest, GradientCheckerAndResidualAtRandomPoints) {
  for (int degree = 0; degree <= 6; ++degree) {
    SCOPED_TRACE(degree);
    const double weight = 0.5 + degree, lambda = 3.0 * degree + 0.25;
    std::vector<Eigen::Vector3d> anchors(degree + 1);
    std::vector<std::vector<double>> blocks(degree + 1, std::vector<double>(3));
    std::vector<const double*> pointers;
    for (int b = 0; b <= degree; ++b) {
      for (int c = 0; c < 3; ++c) {
        anchors[b][c] = 2.0 * Uniform(100 * degree + 3 * b + c) - 1.0;
        blocks[b][c] = 4.0 * Uniform(5000 + 100 * degree + 3 * b + c) - 2.0;
      }
      pointers.push_back(blocks[b].data());
    }
    const ProximalSmoothingCost cost(weight, lambda, anchors);
    ASSERT_EQ(cost.num_residuals(), 3);
    ASSERT_EQ(cost.parameter_block_sizes().size(), static_cast<size_t>(degree + 1));
    ceres::NumericDiffOptions numeric;
    const ceres::GradientChecker checker(
        &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(pointers.data(), kGradientTolerance, &results)) << results.error_log;
    // The residual itself: w·((1 + λ·deg)(x_i − a_i) − λ Σ_j (x_j − a_j)).
    for (int c = 0; c < 3; ++c) {
      double expected = (1.0 + lambda * degree) * (blocks[0][c] - anchors[0][c]);
      for (int k = 1; k <= degree; ++k) expected -= lambda * (blocks[k][c] - anchors[k][c]);
      EXPECT_NEAR(results.residuals[c], weight * expected, 1e-12);
    }
  }
}

// At the anchor every residual is exactly zero; one vertex moved changes only its own residual
// and its neighbours'.
TEST(ProximalSmoothingTest, ZeroAtTheAnchorAndLocal) {
  const TriMesh sphere = Sphere();
  std::vector<double> xyz = Coordinates(sphere);
  std::vector<double*> blocks;
  for (size_t v = 0; v < sphere.n_vertices(); ++v) blocks.push_back(&xyz[3 * v]);
  ceres::Problem problem;
  ProximalSmoothingOptions options;
  options.weight = 3.0;
  EXPECT_EQ(AddProximalSmoothing(sphere, options, blocks, &problem),
            static_cast<int>(sphere.n_vertices()));
  double cost = -1.0;
  std::vector<double> residuals;
  ASSERT_TRUE(
      problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &residuals, nullptr, nullptr));
  EXPECT_EQ(cost, 0.0);
  const int moved = 17;
  xyz[3 * moved] += 0.01;
  ASSERT_TRUE(
      problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &residuals, nullptr, nullptr));
  const std::vector<std::vector<int>> neighbours = VertexNeighbours(sphere);
  std::set<int> touched(neighbours[moved].begin(), neighbours[moved].end());
  touched.insert(moved);
  for (size_t v = 0; v < sphere.n_vertices(); ++v) {
    const double norm = std::abs(residuals[3 * v]);
    if (touched.count(static_cast<int>(v))) {
      EXPECT_GT(norm, 0.0) << v;
    } else {
      EXPECT_EQ(norm, 0.0) << v;
    }
  }
}

// The stacked Jacobian is w·(I + λL) ⊗ I₃ with L = D − A built independently from the faces, on
// a closed mesh and on an open one (boundary vertices keep their one-sided degree).
TEST(ProximalSmoothingTest, JacobianIsIPlusLambdaL) {
  TriMesh open;
  std::vector<TriMesh::VertexHandle> v;
  for (int k = 0; k < 5; ++k) v.push_back(open.add_vertex({1.0 * k, 0.5 * (k % 2), 0.1 * k}));
  open.add_face(v[0], v[1], v[2]);
  open.add_face(v[1], v[3], v[2]);
  open.add_face(v[2], v[3], v[4]);
  for (const TriMesh& mesh : {Sphere(), open}) {
    const int n = static_cast<int>(mesh.n_vertices());
    std::vector<double> xyz = Coordinates(mesh);
    for (size_t i = 0; i < xyz.size(); ++i) xyz[i] += 0.1 * Uniform(900 + i);
    std::vector<double*> blocks;
    for (int k = 0; k < n; ++k) blocks.push_back(&xyz[3 * k]);
    ceres::Problem problem;
    ProximalSmoothingOptions options;
    options.weight = 2.0;
    options.lambda = 25.0;
    AddProximalSmoothing(mesh, options, blocks, &problem);
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.parameter_blocks = blocks;
    ceres::CRSMatrix crs;
    ASSERT_TRUE(problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs));
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i) jacobian(r, crs.cols[i]) = crs.values[i];
    }
    const Eigen::MatrixXd m =
        Eigen::MatrixXd::Identity(n, n) + options.lambda * CombinatorialLaplacian(mesh);
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        expected.block<3, 3>(3 * i, 3 * j) = options.weight * m(i, j) * Eigen::Matrix3d::Identity();
      }
    }
    EXPECT_LT((jacobian - expected).cwiseAbs().maxCoeff(), 1e-12) << n << " vertices";
  }
}

// r = x − target (3 residuals): a data term whose gradient at the anchor a is −t when
// target = a + t, i.e. the step the data alone asks for is t.
struct DataResidual {
  template <typename T>
  bool operator()(const T* x, T* r) const {
    for (int c = 0; c < 3; ++c) r[c] = x[c] - target[c];
    return true;
  }
  Eigen::Vector3d target;
};

// Solves min ½‖x − (a + t)‖² + the proximal term (μ, λ) with Ceres and returns the step x − a
// (n × 3). Both terms are linear: the solution is (I + μM²)⁻¹t, M = I + λL.
Eigen::MatrixXd ProximalStep(const TriMesh& anchor, const Eigen::MatrixXd& t, double mu,
                             double lambda) {
  const int n = static_cast<int>(anchor.n_vertices());
  std::vector<double> xyz = Coordinates(anchor);
  const std::vector<double> a = xyz;
  std::vector<double*> blocks;
  for (int v = 0; v < n; ++v) blocks.push_back(&xyz[3 * v]);
  ceres::Problem problem;
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d target =
        Eigen::Vector3d(a[3 * v], a[3 * v + 1], a[3 * v + 2]) + t.row(v).transpose();
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<DataResidual, 3, 3>(new DataResidual{target}), nullptr,
        blocks[v]);
  }
  ProximalSmoothingOptions options;
  options.weight = std::sqrt(mu);
  options.lambda = lambda;
  AddProximalSmoothing(anchor, options, blocks, &problem);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.initial_trust_region_radius = 1e12;  // near Gauss–Newton steps.
  solver.function_tolerance = solver.gradient_tolerance = solver.parameter_tolerance = 1e-16;
  solver.max_num_iterations = 20;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  Eigen::MatrixXd step(n, 3);
  for (int v = 0; v < n; ++v) {
    for (int c = 0; c < 3; ++c) step(v, c) = xyz[3 * v + c] - a[3 * v + c];
  }
  return step;
}

// A gradient-like data term asking for a smooth displacement plus vertex noise: the Tikhonov step
// (λ = 0) is the request scaled by 1/(1 + μ), exactly as rough; the proximal step with λ = 25 has
// a much lower relative Laplacian energy. A translation (L·1 = 0) passes both alike.
TEST(ProximalSmoothingTest, StepIsSmootherThanTikhonov) {
  const TriMesh sphere = Sphere();
  const int n = static_cast<int>(sphere.n_vertices());
  const Eigen::MatrixXd laplacian = CombinatorialLaplacian(sphere);
  Eigen::MatrixXd t(n, 3);
  for (int v = 0; v < n; ++v) {
    const TriMesh::Point& p = sphere.point(TriMesh::VertexHandle(v));
    for (int c = 0; c < 3; ++c) t(v, c) = 0.05 * (2 * Uniform(7000 + 3 * v + c) - 1);
    t(v, 2) += 0.1 * p[2];  // the smooth part: a stretch along z.
  }
  const double mu = 1.0;
  const Eigen::MatrixXd tikhonov = ProximalStep(sphere, t, mu, 0.0);
  const Eigen::MatrixXd proximal = ProximalStep(sphere, t, mu, 25.0);
  // Both solves against the dense solution (I + μM²)⁻¹t.
  EXPECT_LT((tikhonov - t / (1.0 + mu)).cwiseAbs().maxCoeff(), 1e-9);
  const Eigen::MatrixXd m = Eigen::MatrixXd::Identity(n, n) + 25.0 * laplacian;
  const Eigen::MatrixXd normal = Eigen::MatrixXd::Identity(n, n) + mu * m * m;
  EXPECT_LT((proximal - normal.ldlt().solve(t)).cwiseAbs().maxCoeff(), 1e-9);
  const double e_request = RelativeLaplacianEnergy(laplacian, t);
  const double e_tikhonov = RelativeLaplacianEnergy(laplacian, tikhonov);
  const double e_proximal = RelativeLaplacianEnergy(laplacian, proximal);
  EXPECT_NEAR(e_tikhonov, e_request, 1e-9 * e_request);
  EXPECT_LT(e_proximal, 0.1 * e_tikhonov) << e_proximal << " vs " << e_tikhonov;
  // A translation is in L's null space: the proximal term damps it like Tikhonov does.
  const Eigen::MatrixXd shift = Eigen::MatrixXd::Constant(n, 3, 0.02);
  EXPECT_LT((ProximalStep(sphere, shift, mu, 25.0) - shift / (1.0 + mu)).cwiseAbs().maxCoeff(),
            1e-9);
}

}  // namespace
}  // namespace sft
