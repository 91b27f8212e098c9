#include "src/optim/pyramid.h"

#include <gtest/gtest.h>

#include <random>

namespace sft {
namespace {

Image RandomImage(int w, int h, int c, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Image image(w, h, c);
  for (float& v : image.data) v = u(rng);
  return image;
}

TEST(PyramidTest, LevelSizesAndMeans) {
  Image image(5, 3, 1);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) image.at(x, y) = static_cast<float>(10 * y + x);
  }
  const std::vector<Image> pyramid = BuildPyramid(image, 8);
  ASSERT_EQ(pyramid.size(), 4u);  // 5x3, 3x2, 2x1, 1x1.
  EXPECT_EQ(pyramid[1].width, 3);
  EXPECT_EQ(pyramid[1].height, 2);
  EXPECT_FLOAT_EQ(pyramid[1].at(0, 0), (0 + 1 + 10 + 11) / 4.0f);
  EXPECT_FLOAT_EQ(pyramid[1].at(2, 0), (4 + 14) / 2.0f);  // odd width: two children.
  EXPECT_FLOAT_EQ(pyramid[1].at(2, 1), 24.0f);            // a single child.
  EXPECT_EQ(pyramid[3].width, 1);
  EXPECT_EQ(pyramid[3].height, 1);
}

// ⟨g, D x⟩ = ⟨Dᵀ g, x⟩ for random g and x, odd and even sizes: the adjoint used by the
// gradient of first-order solvers is the transpose of the downsampling.
TEST(PyramidTest, AdjointIsTheTranspose) {
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{8, 6}, {7, 5}, {1, 3}}) {
    const Image x = RandomImage(w, h, 3, 1);
    const Image g = RandomImage(CoarserSize(w), CoarserSize(h), 3, 2);
    const Image dx = DownsampleMean(x);
    const Image dtg = DownsampleMeanAdjoint(g, w, h);
    double a = 0.0, b = 0.0;
    for (size_t i = 0; i < g.data.size(); ++i) a += g.data[i] * dx.data[i];
    for (size_t i = 0; i < x.data.size(); ++i) b += dtg.data[i] * x.data[i];
    EXPECT_NEAR(a, b, 1e-5 * (std::abs(a) + 1)) << w << "x" << h;
  }
}

// The rows of a coarse pixel are the mean of its children's rows: for any direction δ, the
// coarse rows applied to δ equal the pyramid of the fine rows applied to δ.
TEST(PyramidTest, CoarseRowsAreTheMeanOfChildRows) {
  const int w = 7, h = 5, params = 9;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, params - 1);
  LevelRows fine;
  fine.width = w;
  fine.height = h;
  fine.offsets.push_back(0);
  for (int p = 0; p < w * h; ++p) {
    std::vector<int> ids;
    for (int k = 0; k < 3; ++k) ids.push_back(pick(rng));
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    for (int id : ids) fine.entries.push_back({id, {u(rng), u(rng), u(rng)}});
    fine.offsets.push_back(fine.entries.size());
  }
  std::vector<double> delta(params);
  for (double& d : delta) d = u(rng);
  auto apply = [&](const LevelRows& rows) {
    Image image(rows.width, rows.height, 3);
    for (int p = 0; p < rows.width * rows.height; ++p) {
      for (uint64_t i = rows.offsets[p]; i < rows.offsets[p + 1]; ++i) {
        for (int c = 0; c < 3; ++c) {
          image.data[3 * p + c] +=
              static_cast<float>(rows.entries[i].d[c] * delta[rows.entries[i].param]);
        }
      }
      for (uint64_t i = rows.offsets[p] + 1; i < rows.offsets[p + 1]; ++i) {
        EXPECT_LT(rows.entries[i - 1].param, rows.entries[i].param);  // sorted, no duplicates.
      }
    }
    return image;
  };
  const LevelRows coarse = DownsampleRows(fine);
  const Image expected = DownsampleMean(apply(fine));
  const Image got = apply(coarse);
  ASSERT_EQ(got.width, expected.width);
  for (size_t i = 0; i < got.data.size(); ++i) EXPECT_NEAR(got.data[i], expected.data[i], 1e-5);
}

TEST(PyramidTest, MaskPyramidIsTheUnionOfChildren) {
  std::vector<uint8_t> mask(5 * 4, 0);
  mask[3 * 5 + 4] = 1;  // pixel (4, 3).
  const auto pyramid = MaskPyramid(mask, 5, 4, 3);
  ASSERT_EQ(pyramid.size(), 3u);
  EXPECT_EQ(pyramid[1].size(), 6u);  // 3x2.
  EXPECT_EQ(pyramid[1][1 * 3 + 2], 1);
  EXPECT_EQ(pyramid[1][0], 0);
  EXPECT_EQ(pyramid[2][1], 1);  // 2x1: (1, 0).
}

}  // namespace
}  // namespace sft
