// Texel smoothness (cost_functions/texel_smoothness.h): Jacobians, the neighbour pairs of the
// mesh-colors layout (hand counts on one and two faces), connectivity, and a Ceres solve that
// fills the zero-area texels.
#include "cost_functions/texel_smoothness.h"

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>
#include <glog/logging.h>
#include <gtest/gtest.h>

#include <numeric>
#include <set>
#include <utility>

#include "src/core/rng.h"
#include "src/geometry/mesh_colors.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// Central differences of a linear function: exact up to rounding.
constexpr double kGradientTolerance = 1e-7;

double Uniform(uint64_t key) { return static_cast<double>(Mix64(key) >> 11) * 0x1.0p-53; }

TriMesh OneTriangle() {
  TriMesh mesh;
  mesh.add_face(mesh.add_vertex({0, 0, 0}), mesh.add_vertex({1, 0, 0}), mesh.add_vertex({0, 1, 0}));
  return mesh;
}

TriMesh Quad() {
  TriMesh mesh;
  const Status s = ReadMesh(testing::DataDir() + "/meshes/quad_z0_2x2_2f.obj", &mesh);
  CHECK(s.ok()) << s.message();
  return mesh;
}

std::set<std::pair<int, int>> Unordered(const std::vector<TexelPair>& pairs, bool cross_face) {
  std::set<std::pair<int, int>> out;
  for (const TexelPair& p : pairs) {
    if (p.cross_face == cross_face) out.insert({std::min(p.a, p.b), std::max(p.a, p.b)});
  }
  return out;
}

template <int kChannels>
void CheckGradient() {
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const TexelDifferenceCost<kChannels> cost(0.3 + trial);
    double a[kChannels], b[kChannels];
    for (int c = 0; c < kChannels; ++c) {
      a[c] = Uniform(10 * trial + c);
      b[c] = Uniform(10 * trial + c + 5);
    }
    const double* parameters[] = {a, b};
    ceres::NumericDiffOptions numeric;
    const ceres::GradientChecker checker(
        &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(parameters, kGradientTolerance, &results)) << results.error_log;
    for (int c = 0; c < kChannels; ++c) {
      EXPECT_NEAR(results.residuals[c], (0.3 + trial) * (a[c] - b[c]), 1e-12);
    }
  }
}

TEST(TexelDifferenceCostTest, GradientCheckerAlbedo) { CheckGradient<3>(); }
TEST(TexelDifferenceCostTest, GradientCheckerRoughness) { CheckGradient<1>(); }

// The log-ratio form against central differences with step h = 1e-6 per value: for texels in
// [0.02, 1] the truncation error relative to the derivative, h²/(3(t+ε)²), stays below 1e-9, and
// rounding (1e-16/h, relative to a derivative of at least w/4) below 1e-9; the tolerance 1e-6
// leaves a wide margin. (Ceres' GradientChecker's own numeric derivative was 0.3% off one
// component at these values, so the test differentiates itself.)
TEST(TexelLogRatioCostTest, JacobianAgainstCentralDifferencesAndKnownValues) {
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const double w = 0.3 + trial;
    const TexelLogRatioCost<3> cost(w);
    double a[3], b[3];
    for (int c = 0; c < 3; ++c) {
      a[c] = 0.02 + 0.98 * Uniform(10 * trial + c);
      b[c] = 0.02 + 0.98 * Uniform(10 * trial + c + 5);
    }
    double* blocks[] = {a, b};
    const double* parameters[] = {a, b};
    double residuals[3], jacobian_a[9], jacobian_b[9];
    double* jacobians[] = {jacobian_a, jacobian_b};
    ASSERT_TRUE(cost.Evaluate(parameters, residuals, jacobians));
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(
          residuals[c],
          w * kLogRatioReference * std::log((a[c] + kLogRatioEpsilon) / (b[c] + kLogRatioEpsilon)),
          1e-12);
    }
    constexpr double kStep = 1e-6;
    for (int block = 0; block < 2; ++block) {
      for (int k = 0; k < 3; ++k) {
        double plus[3], minus[3];
        const double saved = blocks[block][k];
        blocks[block][k] = saved + kStep;
        ASSERT_TRUE(cost.Evaluate(parameters, plus, nullptr));
        blocks[block][k] = saved - kStep;
        ASSERT_TRUE(cost.Evaluate(parameters, minus, nullptr));
        blocks[block][k] = saved;
        for (int row = 0; row < 3; ++row) {
          const double numeric = (plus[row] - minus[row]) / (2 * kStep);
          const double analytic = jacobians[block][3 * row + k];
          EXPECT_NEAR(analytic, numeric, 1e-6 * std::max(1.0, std::abs(numeric)))
              << "block " << block << " row " << row << " column " << k;
        }
      }
    }
  }
  // At the reference value the two forms have the same Jacobian (up to ε).
  const TexelLogRatioCost<1> log_cost(2.0);
  const TexelDifferenceCost<1> linear_cost(2.0);
  double t = kLogRatioReference, u = 0.3, r_log, r_lin, j_log[2], j_lin[2];
  double* jac_log[] = {&j_log[0], &j_log[1]};
  double* jac_lin[] = {&j_lin[0], &j_lin[1]};
  const double* at[] = {&t, &u};
  ASSERT_TRUE(log_cost.Evaluate(at, &r_log, jac_log));
  ASSERT_TRUE(linear_cost.Evaluate(at, &r_lin, jac_lin));
  EXPECT_NEAR(j_log[0], j_lin[0], 2.0 * kLogRatioEpsilon / kLogRatioReference * j_lin[0]);
  // Scaling both texels by k leaves the residual (up to ε) unchanged; the difference shrinks by k.
  double t4 = t / 4, u4 = u / 4, r_log4, r_lin4;
  const double* at4[] = {&t4, &u4};
  ASSERT_TRUE(log_cost.Evaluate(at4, &r_log4, nullptr));
  ASSERT_TRUE(linear_cost.Evaluate(at4, &r_lin4, nullptr));
  EXPECT_NEAR(r_log4, r_log, 0.01 * std::abs(r_log));
  EXPECT_NEAR(r_lin4, r_lin / 4, 1e-12);
  // Black texels (the lower bound) stay finite.
  double zero = 0.0, r_zero, j_zero[2];
  double* jac_zero[] = {&j_zero[0], &j_zero[1]};
  const double* at_zero[] = {&zero, &u};
  ASSERT_TRUE(log_cost.Evaluate(at_zero, &r_zero, jac_zero));
  EXPECT_TRUE(std::isfinite(r_zero) && std::isfinite(j_zero[0]) && std::isfinite(j_zero[1]));
  EXPECT_NEAR(j_zero[0], 2.0 * kLogRatioReference / kLogRatioEpsilon, 1e-9);
}

// Hand counts. In a face of resolution r the texels form a triangle of rows of r+1, r, ..., 1
// texels; each of the r(r+1)/2 small upward triangles (i,j), (i+1,j), (i,j+1) of the grid gives
// its three sides: 3·r(r+1)/2 pairs (r = 1: 3; r = 2: 9; r = 3: 18). Two faces sharing one edge
// add r cross pairs (one for r = 0).
TEST(TexelNeighbourPairsTest, CountsOnOneAndTwoFaces) {
  const int one_face[] = {0, 3, 9, 18, 30};
  const int two_faces[] = {1, 7, 20, 39, 64};
  for (int r = 0; r <= 4; ++r) {
    SCOPED_TRACE(r);
    const std::vector<TexelPair> one = TexelNeighbourPairs(OneTriangle(), r);
    EXPECT_EQ(static_cast<int>(one.size()), one_face[r]);
    const std::vector<TexelPair> two = TexelNeighbourPairs(Quad(), r);
    EXPECT_EQ(static_cast<int>(two.size()), two_faces[r]);
    EXPECT_EQ(static_cast<int>(Unordered(two, true).size()), std::max(r, 1));
    // No pair repeats or joins a texel to itself.
    EXPECT_EQ(Unordered(two, true).size() + Unordered(two, false).size(), two.size());
    for (const TexelPair& p : two) EXPECT_NE(p.a, p.b);
  }
}

// Resolution 1: texels (0,0) = 0, (0,1) = 1, (1,0) = 2 form one triangle of pairs.
TEST(TexelNeighbourPairsTest, ExactPairsAtResolutionOne) {
  EXPECT_EQ(Unordered(TexelNeighbourPairs(OneTriangle(), 1), false),
            (std::set<std::pair<int, int>>{{0, 1}, {0, 2}, {1, 2}}));
}

// The quad's faces are (v0, v1, v2) and (v0, v2, v3), sharing v0–v2. At r = 2, the half of the
// edge next to v0 is texel (0,0) in both faces (global 0 and 6); the half next to v2 is (0,1) in
// face 0 (v2 is its third vertex: β = 1 there; local 1) and (1,0) in face 1 (v2 is its second
// vertex: α; local 3, global 9).
TEST(TexelNeighbourPairsTest, CrossFacePairsCoverTheSameStretchOfTheEdge) {
  EXPECT_EQ(Unordered(TexelNeighbourPairs(Quad(), 2), true),
            (std::set<std::pair<int, int>>{{0, 6}, {1, 9}}));
}

// The same quad with the second face written (v2, v3, v0): its grid runs along the shared edge
// from v2 (β = 0) to v0 (β = 1). The half next to v0 is (0,1) there (β ∈ [0.5, 1): local 1, global
// 7), the half next to v2 is (0,0) (global 6). Pairing duplicated lattice points instead would
// give (0,8), (1,7), (2,6): shifted by one interval, and tying area texels to zero-area ones.
TEST(TexelNeighbourPairsTest, CrossFacePairsWhenTheGridsRunOppositeWays) {
  TriMesh mesh;
  std::vector<TriMesh::VertexHandle> v;
  for (const auto& p : {TriMesh::Point(-1, -1, 0), TriMesh::Point(1, -1, 0),
                        TriMesh::Point(1, 1, 0), TriMesh::Point(-1, 1, 0)}) {
    v.push_back(mesh.add_vertex(p));
  }
  mesh.add_face(v[0], v[1], v[2]);
  mesh.add_face(v[2], v[3], v[0]);
  EXPECT_EQ(Unordered(TexelNeighbourPairs(mesh, 2), true),
            (std::set<std::pair<int, int>>{{0, 7}, {1, 6}}));
}

// On a closed mesh every texel, the zero-area ones included, is linked to every other: the
// smoothness term leaves only the global constant undetermined. Without the cross-face pairs each
// face would be its own component.
TEST(TexelNeighbourPairsTest, ClosedMeshIsOneComponent) {
  TriMesh sphere;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &sphere).ok());
  const int r = 3;
  const std::vector<TexelPair> pairs = TexelNeighbourPairs(sphere, r);
  const int n = static_cast<int>(sphere.n_faces()) * MeshColors::TexelsPerFace(r);
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  int components = n;
  for (const TexelPair& p : pairs) {
    const int a = find(p.a), b = find(p.b);
    if (a != b) {
      parent[a] = b;
      --components;
    }
  }
  EXPECT_EQ(components, 1);
  EXPECT_EQ(pairs.size(), 320u * 18 + 480u * 3);  // 480 edges
}

// One face at r = 3 with every texel that covers area fixed: the solve moves each zero-area texel
// (i + j = 3, started far off at 5) to a weighted average of its neighbours, so (maximum principle)
// into the range of the fixed values, [0, 0.4].
TEST(TexelSmoothnessTest, FillsZeroAreaTexelsFromTheirNeighbours) {
  const int r = 3;
  const std::vector<TexelPair> pairs = TexelNeighbourPairs(OneTriangle(), r);
  const int n = MeshColors::TexelsPerFace(r);
  std::vector<double> values(n, 0.0);
  std::vector<double*> blocks;
  for (int k = 0; k < n; ++k) blocks.push_back(&values[k]);
  // A linear ramp 0.1·(i + 2j) on area texels; zero-area texels start at 5.
  for (int i = 0; i <= r; ++i) {
    for (int j = 0; i + j <= r; ++j) {
      values[MeshColors::LocalIndex(r, i, j)] = i + j == r ? 5.0 : 0.1 * (i + 2 * j);
    }
  }
  ceres::Problem problem;
  EXPECT_EQ(AddTexelSmoothness(pairs, 1, TexelSmoothnessOptions(), blocks, &problem), 18);
  for (int i = 0; i <= r; ++i) {
    for (int j = 0; i + j < r; ++j)
      problem.SetParameterBlockConstant(blocks[MeshColors::LocalIndex(r, i, j)]);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_LT(summary.final_cost, summary.initial_cost);
  for (int i = 0; i <= r; ++i) {
    const double value = values[MeshColors::LocalIndex(r, i, r - i)];
    EXPECT_GE(value, 0.0) << i;
    EXPECT_LE(value, 0.4 + 1e-9) << i;
  }
}

}  // namespace
}  // namespace sft
