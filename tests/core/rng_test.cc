#include "src/core/rng.h"

#include <gtest/gtest.h>

#include <set>
#include <vector>

namespace sft {
namespace {

// For 2^m samples of one pixel, every Next2D pair is a (0, m, 2)-net: each of the 2^m elementary
// intervals of shape 2^-a × 2^-(m−a) holds exactly one point (checked for all a), in every pair.
TEST(SamplerTest, Next2DPairsAreStratifiedNets) {
  for (int m : {2, 4, 6}) {
    const int n = 1 << m;
    for (int pair = 0; pair < 4; ++pair) {
      std::vector<std::pair<double, double>> points;
      for (int s = 0; s < n; ++s) {
        Sampler sampler(9, 3, 1234, s);
        double u1 = 0, u2 = 0;
        for (int k = 0; k <= pair; ++k) sampler.Next2D(&u1, &u2);
        ASSERT_GT(u1, 0.0);
        ASSERT_LT(u1, 1.0);
        points.emplace_back(u1, u2);
      }
      for (int a = 0; a <= m; ++a) {
        std::set<std::pair<int, int>> cells;
        for (const auto& [x, y] : points) {
          cells.insert({static_cast<int>(x * (1 << a)), static_cast<int>(y * (1 << (m - a)))});
        }
        EXPECT_EQ(static_cast<int>(cells.size()), n) << "m " << m << " pair " << pair << " a " << a;
      }
    }
  }
}

// Same key, same numbers; different pixels or seeds, different numbers.
TEST(SamplerTest, DeterministicAndDecorrelated) {
  Sampler a(1, 2, 3, 4), b(1, 2, 3, 4), c(1, 2, 5, 4), d(2, 2, 3, 4);
  double a1, a2, b1, b2, c1, c2, d1, d2;
  a.Next2D(&a1, &a2);
  b.Next2D(&b1, &b2);
  c.Next2D(&c1, &c2);
  d.Next2D(&d1, &d2);
  EXPECT_EQ(a1, b1);
  EXPECT_EQ(a2, b2);
  EXPECT_NE(a1, c1);
  EXPECT_NE(a1, d1);
  EXPECT_EQ(a.Next1D(), b.Next1D());
  EXPECT_NE(Sampler(1, 2, 3, 4).Next1D(), Sampler(1, 2, 3, 5).Next1D());
}

// The mean of many hashed uniforms is 1/2 and they fill [0, 1) evenly (16 bins, χ²-style bound).
TEST(SamplerTest, Next1DIsUniform) {
  std::vector<int> bins(16, 0);
  const int n = 160000;
  for (int s = 0; s < n; ++s) {
    Sampler sampler(0, 0, s % 97, s);
    const double u = sampler.Next1D();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    ++bins[static_cast<int>(u * 16)];
  }
  double chi2 = 0;
  for (int count : bins) chi2 += (count - n / 16.0) * (count - n / 16.0) / (n / 16.0);
  EXPECT_LT(chi2, 45.0);  // 15 degrees of freedom: p < 1e-4 above 45.
}

// The byte-table evaluation of Sobol dimension 1 equals the direct definition (XOR of the direction
// numbers v_k = v_{k−1} ^ (v_{k−1} >> 1) of the index's set bits), and dimension 0 is the bit
// reversal, for small, large and random indices.
TEST(SamplerTest, Sobol2DMatchesDirectDefinition) {
  auto direct = [](uint32_t index) {
    uint32_t result = 0, v = 0x80000000u;
    for (uint32_t i = index; i != 0; i >>= 1) {
      if (i & 1u) result ^= v;
      v ^= v >> 1;
    }
    return result;
  };
  std::vector<uint32_t> indices;
  for (uint32_t i = 0; i < 4096; ++i) indices.push_back(i);
  for (uint64_t i = 0; i < 4096; ++i) indices.push_back(static_cast<uint32_t>(Mix64(i)));
  indices.push_back(0xFFFFFFFFu);
  for (const uint32_t index : indices) {
    uint32_t x, y;
    Sobol2D(index, &x, &y);
    EXPECT_EQ(y, direct(index)) << index;
    EXPECT_EQ(x, ReverseBits32(index)) << index;
  }
}

}  // namespace
}  // namespace sft
