// The vertex Laplacian regulariser (cost_functions/vertex_laplacian.h): Jacobians against numeric
// differences, zero on flat meshes, normal direction on a sphere, and smoothing in a Ceres solve.
#include "cost_functions/vertex_laplacian.h"

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "src/core/rng.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// Central numeric differences of a linear function are exact up to rounding (~1e-10 relative with
// Ceres' default step), so a wrong Jacobian entry shows far above this.
constexpr double kGradientTolerance = 1e-7;

double Uniform(uint64_t key) { return static_cast<double>(Mix64(key) >> 11) * 0x1.0p-53; }

// An n×n grid of vertices in the plane z = 0 (spacing 1), each cell split along its diagonal;
// `jitter` moves interior vertices in the plane by up to ±jitter.
TriMesh PlanarGrid(int n, double jitter) {
  TriMesh mesh;
  std::vector<TriMesh::VertexHandle> v;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const bool interior = x > 0 && y > 0 && x < n - 1 && y < n - 1;
      const double dx = interior ? jitter * (2 * Uniform(2 * (y * n + x)) - 1) : 0.0;
      const double dy = interior ? jitter * (2 * Uniform(2 * (y * n + x) + 1) - 1) : 0.0;
      v.push_back(mesh.add_vertex(TriMesh::Point(x + dx, y + dy, 0.0)));
    }
  }
  for (int y = 0; y + 1 < n; ++y) {
    for (int x = 0; x + 1 < n; ++x) {
      const int a = y * n + x;
      mesh.add_face(v[a], v[a + 1], v[a + n + 1]);
      mesh.add_face(v[a], v[a + n + 1], v[a + n]);
    }
  }
  return mesh;
}

std::vector<double> Coordinates(const TriMesh& mesh) {
  std::vector<double> xyz;
  for (TriMesh::VertexHandle v : mesh.vertices()) {
    for (int c = 0; c < 3; ++c) xyz.push_back(mesh.point(v)[c]);
  }
  return xyz;
}

// r = p_i − Σ w_ij p_j of one stencil (weight 1).
Eigen::Vector3d StencilResidual(const TriMesh& mesh, const LaplacianStencil& s) {
  const auto p = [&](int i) {
    const TriMesh::Point& q = mesh.point(TriMesh::VertexHandle(i));
    return Eigen::Vector3d(q[0], q[1], q[2]);
  };
  Eigen::Vector3d r = p(s.vertex);
  for (size_t k = 0; k < s.neighbours.size(); ++k) r -= s.weights[k] * p(s.neighbours[k]);
  return r;
}

TEST(VertexLaplacianCostTest, GradientCheckerAtRandomPoints) {
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const int n = 3 + trial;  // neighbours
    std::vector<double> weights(n);
    for (int k = 0; k < n; ++k) weights[k] = Uniform(100 * trial + k) - 0.2;  // some negative
    const VertexLaplacianCost cost(0.5 + trial, weights);
    ASSERT_EQ(cost.num_residuals(), 3);
    ASSERT_EQ(cost.parameter_block_sizes().size(), static_cast<size_t>(n + 1));
    std::vector<std::vector<double>> blocks(n + 1, std::vector<double>(3));
    std::vector<const double*> pointers;
    for (int b = 0; b <= n; ++b) {
      for (int c = 0; c < 3; ++c) blocks[b][c] = 4.0 * Uniform(1000 * trial + 3 * b + c) - 2.0;
      pointers.push_back(blocks[b].data());
    }
    ceres::NumericDiffOptions numeric;
    const ceres::GradientChecker checker(
        &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(pointers.data(), kGradientTolerance, &results)) << results.error_log;
    // And the residual itself: w·(p_0 − Σ w_k p_k).
    for (int c = 0; c < 3; ++c) {
      double expected = blocks[0][c];
      for (int k = 0; k < n; ++k) expected -= weights[k] * blocks[k + 1][c];
      EXPECT_NEAR(results.residuals[c], (0.5 + trial) * expected, 1e-12);
    }
  }
}

TEST(VertexLaplacianTest, WeightsSumToOne) {
  for (LaplacianKind kind : {LaplacianKind::kUniform, LaplacianKind::kCotangent}) {
    VertexLaplacianOptions options;
    options.kind = kind;
    for (const LaplacianStencil& s : LaplacianStencils(PlanarGrid(6, 0.3), options)) {
      double sum = 0.0;
      for (double w : s.weights) sum += w;
      EXPECT_NEAR(sum, 1.0, 1e-12);
    }
  }
}

// A ring of degenerate faces has no cotangents at all: uniform weights instead of 0/0.
TEST(VertexLaplacianTest, DegenerateRingFallsBackToUniformWeights) {
  TriMesh mesh;
  mesh.add_face(mesh.add_vertex({0, 0, 0}), mesh.add_vertex({1, 0, 0}), mesh.add_vertex({2, 0, 0}));
  VertexLaplacianOptions options;
  options.kind = LaplacianKind::kCotangent;
  options.include_boundary = true;
  const std::vector<LaplacianStencil> stencils = LaplacianStencils(mesh, options);
  ASSERT_EQ(stencils.size(), 3u);
  for (const LaplacianStencil& s : stencils) {
    ASSERT_EQ(s.weights.size(), 2u);
    EXPECT_EQ(s.weights[0], 0.5);
    EXPECT_EQ(s.weights[1], 0.5);
  }
}

// A regular planar grid: every interior vertex is the uniform average of its ring. Boundary
// vertices get no residual by default (their one-sided ring would pull them inwards).
TEST(VertexLaplacianTest, UniformIsZeroOnAPlanarGridInterior) {
  const TriMesh grid = PlanarGrid(6, 0.0);
  VertexLaplacianOptions options;
  options.kind = LaplacianKind::kUniform;
  const std::vector<LaplacianStencil> stencils = LaplacianStencils(grid, options);
  EXPECT_EQ(stencils.size(), 16u);  // the 4×4 interior vertices.
  for (const LaplacianStencil& s : stencils) {
    EXPECT_EQ(s.neighbours.size(), 6u);
    EXPECT_LT(StencilResidual(grid, s).norm(), 1e-12) << "vertex " << s.vertex;
  }
  options.include_boundary = true;
  const std::vector<LaplacianStencil> all = LaplacianStencils(grid, options);
  EXPECT_EQ(all.size(), 36u);
  double max_boundary = 0.0;
  for (const LaplacianStencil& s : all)
    max_boundary = std::max(max_boundary, StencilResidual(grid, s).norm());
  EXPECT_GT(max_boundary, 0.1);  // boundary rings are one-sided.
}

// An irregular planar mesh: the cotangent Laplacian is still zero at interior vertices (it is the
// gradient of the area, stationary for planar configurations), the uniform one is not (but has no
// normal component).
TEST(VertexLaplacianTest, CotangentIsZeroOnAnyPlanarMeshInterior) {
  const TriMesh grid = PlanarGrid(7, 0.3);
  VertexLaplacianOptions options;
  options.kind = LaplacianKind::kCotangent;
  for (const LaplacianStencil& s : LaplacianStencils(grid, options)) {
    EXPECT_LT(StencilResidual(grid, s).norm(), 1e-12) << "vertex " << s.vertex;
  }
  options.kind = LaplacianKind::kUniform;
  double max_uniform = 0.0;
  for (const LaplacianStencil& s : LaplacianStencils(grid, options)) {
    const Eigen::Vector3d r = StencilResidual(grid, s);
    EXPECT_LT(std::abs(r.z()), 1e-12);
    max_uniform = std::max(max_uniform, r.norm());
  }
  EXPECT_GT(max_uniform, 0.05);
}

// On a sphere-like mesh whose vertices were slid along the sphere (irregular rings), the cotangent
// residual points along the outward normal; the uniform residual has a tangential part.
TEST(VertexLaplacianTest, CotangentPointsAlongTheNormalOnASphere) {
  TriMesh sphere;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_1280f.obj", &sphere).ok());
  for (TriMesh::VertexHandle v : sphere.vertices()) {
    TriMesh::Point& p = sphere.point(v);
    for (int c = 0; c < 3; ++c) p[c] += 0.02 * (2 * Uniform(3 * v.idx() + c) - 1);
    p /= p.norm();  // back onto the unit sphere
  }
  std::vector<double> angles[2];
  for (LaplacianKind kind : {LaplacianKind::kCotangent, LaplacianKind::kUniform}) {
    VertexLaplacianOptions options;
    options.kind = kind;
    for (const LaplacianStencil& s : LaplacianStencils(sphere, options)) {
      const Eigen::Vector3d r = StencilResidual(sphere, s);
      const TriMesh::Point& p = sphere.point(TriMesh::VertexHandle(s.vertex));
      const Eigen::Vector3d normal = Eigen::Vector3d(p[0], p[1], p[2]).normalized();
      EXPECT_GT(r.dot(normal), 0.0);  // outwards: a convex vertex lies outside its ring's average.
      angles[kind == LaplacianKind::kUniform].push_back(
          std::atan2(r.cross(normal).norm(), r.dot(normal)));
    }
  }
  for (auto& a : angles) std::sort(a.begin(), a.end());
  const double cot_median = angles[0][angles[0].size() / 2];
  const double uniform_median = angles[1][angles[1].size() / 2];
  EXPECT_LT(cot_median, 0.05);       // radians
  EXPECT_LT(angles[0].back(), 0.1);  // the worst vertex too
  EXPECT_GT(uniform_median, 0.3);    // the uniform residual is far from normal on irregular rings
}

// A noisy grid with its boundary held fixed: the Laplacian alone flattens it (its minimum, cost 0,
// is the flat grid, since a harmonic height field with zero boundary values is zero).
TEST(VertexLaplacianTest, CeresSolveSmoothsANoisyMesh) {
  for (LaplacianKind kind : {LaplacianKind::kUniform, LaplacianKind::kCotangent}) {
    SCOPED_TRACE(kind == LaplacianKind::kUniform ? "uniform" : "cotangent");
    const TriMesh rest = PlanarGrid(8, 0.2);
    std::vector<double> xyz = Coordinates(rest);
    for (TriMesh::VertexHandle v : rest.vertices()) {
      if (!rest.is_boundary(v)) xyz[3 * v.idx() + 2] = 0.1 * (2 * Uniform(777 + v.idx()) - 1);
    }
    std::vector<double*> blocks;
    for (size_t v = 0; v < rest.n_vertices(); ++v) blocks.push_back(&xyz[3 * v]);
    ceres::Problem problem;
    VertexLaplacianOptions options;
    options.kind = kind;
    EXPECT_EQ(AddVertexLaplacian(rest, options, blocks, &problem), 36);
    for (TriMesh::VertexHandle v : rest.vertices()) {
      if (rest.is_boundary(v)) {
        problem.AddParameterBlock(blocks[v.idx()], 3);
        problem.SetParameterBlockConstant(blocks[v.idx()]);
      }
    }
    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    EXPECT_GT(summary.initial_cost, 1e-3);
    EXPECT_LT(summary.final_cost, 1e-12 * summary.initial_cost);
    double max_height = 0.0;
    for (size_t v = 0; v < rest.n_vertices(); ++v)
      max_height = std::max(max_height, std::abs(xyz[3 * v + 2]));
    EXPECT_LT(max_height, 1e-6);
  }
}

// A closed noisy sphere with three vertices fixed: the cost drops. Its minimum is not 0 (a closed
// surface whose every vertex is its ring's average is a single point, which the three fixed
// vertices forbid); measured: to 18% of the initial cost.
TEST(VertexLaplacianTest, CeresSolveReducesTheCostOnANoisySphere) {
  TriMesh rest;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &rest).ok());
  std::vector<double> xyz = Coordinates(rest);
  for (size_t i = 0; i < xyz.size(); ++i) xyz[i] += 0.05 * (2 * Uniform(5000 + i) - 1);
  std::vector<double*> blocks;
  for (size_t v = 0; v < rest.n_vertices(); ++v) blocks.push_back(&xyz[3 * v]);
  ceres::Problem problem;
  VertexLaplacianOptions options;
  options.kind = LaplacianKind::kCotangent;
  options.weight = 2.0;
  AddVertexLaplacian(rest, options, blocks, &problem);
  for (int v : {0, 40, 100}) problem.SetParameterBlockConstant(blocks[v]);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = 20;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  EXPECT_LT(summary.final_cost, 0.25 * summary.initial_cost) << summary.BriefReport();
}

}  // namespace
}  // namespace sft
