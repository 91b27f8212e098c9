// The large-steps reparameterisation (src/optim/large_steps.h) against known answers: on a closed
// ring of n vertices the combinatorial Laplacian's eigenvectors are the Fourier modes, with
// eigenvalue 2 − 2cos(2πk/n), so M⁻¹ = (I + λL)⁻¹ scales mode k by exactly 1 / (1 + λ(2 − 2cos)).
#include "src/optim/large_steps.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace sft {
namespace {

std::vector<std::vector<int>> Ring(int n) {
  std::vector<std::vector<int>> neighbours(n);
  for (int i = 0; i < n; ++i) {
    neighbours[i] = {(i + n - 1) % n, (i + 1) % n};
    std::sort(neighbours[i].begin(), neighbours[i].end());
  }
  return neighbours;
}

TEST(LargeStepsTest, DampsEachRingModeByItsEigenvalue) {
  const int n = 32;
  const double lambda = 25.0;
  std::unique_ptr<LargeSteps> steps;
  ASSERT_TRUE(LargeSteps::Create(Ring(n), lambda, &steps).ok());
  for (int k : {0, 1, 5, 16}) {
    // Mode k in x, mode k (phase-shifted) in y, a constant in z.
    std::vector<double> g(3 * n), out(3 * n);
    for (int i = 0; i < n; ++i) {
      const double angle = 2.0 * M_PI * k * i / n;
      g[3 * i] = std::cos(angle);
      g[3 * i + 1] = std::sin(angle + 0.3);
      g[3 * i + 2] = 1.0;
    }
    steps->GradientToU(g.data(), out.data());
    const double factor = 1.0 / (1.0 + lambda * (2.0 - 2.0 * std::cos(2.0 * M_PI * k / n)));
    for (int i = 0; i < 3 * n; ++i) {
      const double expected = (i % 3 == 2) ? 1.0 : factor * g[i];
      EXPECT_NEAR(out[i], expected, 1e-12) << "mode " << k << " entry " << i;
    }
  }
  // The highest mode (k = n/2, eigenvalue 4) is damped by 1 + 4λ = 101.
  EXPECT_NEAR(1.0 + lambda * 4.0, 101.0, 1e-12);
}

TEST(LargeStepsTest, ToXInvertsToU) {
  const int n = 9;
  std::unique_ptr<LargeSteps> steps;
  ASSERT_TRUE(LargeSteps::Create(Ring(n), 19.0, &steps).ok());
  std::vector<double> x(3 * n), u(3 * n), back(3 * n);
  for (int i = 0; i < 3 * n; ++i) x[i] = std::sin(1.7 * i) + 0.1 * i;
  steps->ToU(x.data(), u.data());
  // u_i = x_i + λ(2x_i − x_{i−1} − x_{i+1}) per coordinate.
  const int i = 4;
  EXPECT_NEAR(u[3 * i + 1], x[3 * i + 1] + 19.0 * (2 * x[3 * i + 1] - x[3 * 3 + 1] - x[3 * 5 + 1]),
              1e-12);
  steps->ToX(u.data(), back.data());
  for (int k = 0; k < 3 * n; ++k) EXPECT_NEAR(back[k], x[k], 1e-10);
}

TEST(LargeStepsTest, LambdaZeroIsTheIdentity) {
  std::unique_ptr<LargeSteps> steps;
  ASSERT_TRUE(LargeSteps::Create(Ring(5), 0.0, &steps).ok());
  std::vector<double> x = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15}, u(15);
  steps->ToU(x.data(), u.data());
  EXPECT_EQ(u, x);
}

TEST(LargeStepsTest, RejectsOneSidedNeighboursAndBadLambda) {
  std::vector<std::vector<int>> neighbours = Ring(4);
  neighbours[0] = {1, 2};  // 2 does not list 0.
  std::unique_ptr<LargeSteps> steps;
  Status status = LargeSteps::Create(neighbours, 25.0, &steps);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("vertex 0"), std::string::npos) << status.message();
  EXPECT_FALSE(LargeSteps::Create(Ring(4), -1.0, &steps).ok());
  EXPECT_FALSE(LargeSteps::Create(Ring(4), std::nan(""), &steps).ok());
  neighbours = Ring(4);
  neighbours[1].push_back(7);
  EXPECT_FALSE(LargeSteps::Create(neighbours, 25.0, &steps).ok());
}

}  // namespace
}  // namespace sft
