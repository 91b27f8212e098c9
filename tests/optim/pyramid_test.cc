#include "src/optim/pyramid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <utility>

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

constexpr PyramidFilter kFilters[] = {PyramidFilter::kBox, PyramidFilter::kBinomial};

// ⟨g, D x⟩ = ⟨Dᵀ g, x⟩ for random g and x, odd and even sizes, both filters: the adjoint used by
// the gradient of first-order solvers is the transpose of the downsampling. Float images: the
// inner products of ~50 terms of size ~1 agree to ~1e-6.
TEST(PyramidTest, AdjointIsTheTranspose) {
  for (PyramidFilter filter : kFilters) {
    for (const auto& [w, h] :
         std::vector<std::pair<int, int>>{{8, 6}, {7, 5}, {1, 3}, {2, 2}, {1, 1}, {9, 2}}) {
      const Image x = RandomImage(w, h, 3, 1);
      const Image g = RandomImage(CoarserSize(w), CoarserSize(h), 3, 2);
      const Image dx = DownsampleMean(x, filter);
      const Image dtg = DownsampleMeanAdjoint(g, w, h, filter);
      double a = 0.0, b = 0.0;
      for (size_t i = 0; i < g.data.size(); ++i) a += g.data[i] * dx.data[i];
      for (size_t i = 0; i < x.data.size(); ++i) b += dtg.data[i] * x.data[i];
      EXPECT_NEAR(a, b, 1e-5 * (std::abs(a) + 1))
          << PyramidFilterName(filter) << " " << w << "x" << h;
    }
  }
}

// The border rule keeps every coarse pixel's weights summing to 1: each binomial level of a
// constant image is that constant, at odd and even sizes down to 1 × 1.
TEST(PyramidTest, BinomialLevelsOfAConstantImageAreConstant) {
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{7, 5}, {8, 6}, {1, 3}, {13, 2}}) {
    const std::vector<Image> pyramid =
        BuildPyramid(Image(w, h, 3, 0.7f), 12, PyramidFilter::kBinomial);
    EXPECT_EQ(pyramid.back().width, 1);
    EXPECT_EQ(pyramid.back().height, 1);
    for (const Image& level : pyramid) {
      for (float v : level.data) EXPECT_NEAR(v, 0.7f, 1e-6f) << w << "x" << h;
    }
  }
}

// The weights themselves along one axis: [1 2 1]/4 inside, renormalised where a tap falls off.
TEST(PyramidTest, BinomialWeightsAndBorderRule) {
  Image row(5, 1, 1);
  for (int x = 0; x < 5; ++x) row.at(x, 0) = static_cast<float>(1 << (2 * x));  // 1, 4, 16, ...
  const Image coarse = DownsampleMean(row, PyramidFilter::kBinomial);
  ASSERT_EQ(coarse.width, 3);
  EXPECT_FLOAT_EQ(coarse.at(0, 0), (2 * 1 + 4) / 3.0f);             // taps 0, 1 (−1 is off).
  EXPECT_FLOAT_EQ(coarse.at(1, 0), (4 + 2 * 16 + 64) / 4.0f);       // taps 1, 2, 3.
  EXPECT_FLOAT_EQ(coarse.at(2, 0), (64 + 2 * 256) / 3.0f);          // taps 3, 4 (5 is off).
  EXPECT_FLOAT_EQ(DownsampleMean(row).at(1, 0), (16 + 64) / 2.0f);  // box: taps 2, 3.
}

// Random sparse Jacobian rows of a w × h level over `params` parameters (sorted, no duplicates).
LevelRows RandomRows(int w, int h, int params, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, params - 1);
  LevelRows rows;
  rows.width = w;
  rows.height = h;
  rows.offsets.push_back(0);
  for (int p = 0; p < w * h; ++p) {
    std::vector<int> ids;
    for (int k = 0; k < 3; ++k) ids.push_back(pick(rng));
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    for (int id : ids) rows.entries.push_back({id, {u(rng), u(rng), u(rng)}});
    rows.offsets.push_back(rows.entries.size());
  }
  return rows;
}

// The rows applied to a parameter direction δ: the image J·δ (RGB). Checks that each pixel's
// entries are sorted with no duplicates.
Image ApplyRows(const LevelRows& rows, const std::vector<double>& delta) {
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
}

// The rows of a coarse pixel are the filter's weighted mean of its children's rows: for any
// direction δ, the coarse rows applied to δ equal the pyramid of the fine rows applied to δ.
TEST(PyramidTest, CoarseRowsAreTheMeanOfChildRows) {
  const int params = 9;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> delta(params);
  for (double& d : delta) d = u(rng);
  for (PyramidFilter filter : kFilters) {
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{{7, 5}, {8, 6}, {1, 3}}) {
      SCOPED_TRACE(std::string(PyramidFilterName(filter)) + " " + std::to_string(w) + "x" +
                   std::to_string(h));
      const LevelRows fine = RandomRows(w, h, params, 4);
      const LevelRows coarse = DownsampleRows(fine, filter);
      const Image expected = DownsampleMean(ApplyRows(fine, delta), filter);
      const Image got = ApplyRows(coarse, delta);
      ASSERT_EQ(got.width, expected.width);
      ASSERT_EQ(got.height, expected.height);
      for (size_t i = 0; i < got.data.size(); ++i) EXPECT_NEAR(got.data[i], expected.data[i], 1e-5);
    }
  }
}

// For a level-0 image linear in the parameters, I(θ) = I₀ + J·θ, the downsampled rows equal the
// finite difference (D I(θ + hδ) − D I(θ))/h of the downsampled image. The images are float: with
// h = 0.05 and values of a few units, rounding gives ~1e-5 of difference error; 1e-4 allows it.
TEST(PyramidTest, DownsampledRowsAreTheFiniteDifferenceOfTheDownsampledImage) {
  const int w = 9, h = 6, params = 7;
  const double step = 0.05;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> theta(params), delta(params), moved(params);
  for (int k = 0; k < params; ++k) {
    theta[k] = u(rng);
    delta[k] = u(rng);
    moved[k] = theta[k] + step * delta[k];
  }
  const LevelRows fine = RandomRows(w, h, params, 6);
  const Image base = RandomImage(w, h, 3, 7);
  const auto image_at = [&](const std::vector<double>& p) {
    Image image = ApplyRows(fine, p);
    for (size_t i = 0; i < image.data.size(); ++i) image.data[i] += base.data[i];
    return image;
  };
  for (PyramidFilter filter : kFilters) {
    SCOPED_TRACE(PyramidFilterName(filter));
    const Image at = DownsampleMean(image_at(theta), filter);
    const Image after = DownsampleMean(image_at(moved), filter);
    const Image predicted = ApplyRows(DownsampleRows(fine, filter), delta);
    for (size_t i = 0; i < at.data.size(); ++i) {
      EXPECT_NEAR((after.data[i] - at.data[i]) / step, predicted.data[i], 1e-4) << i;
    }
  }
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

// The binomial mask rule: one active pixel at odd coordinates (3, 1) feeds two coarse pixels per
// axis (taps 1..3 of x = 1 and 3..4 of x = 2; taps 0..1 of y = 0 and 1..3 of y = 1), the box
// only its parent (1, 0).
TEST(PyramidTest, BinomialMaskPyramidFollowsTheTaps) {
  std::vector<uint8_t> mask(5 * 4, 0);
  mask[1 * 5 + 3] = 1;
  const auto box = MaskPyramid(mask, 5, 4, 2);
  const auto binomial = MaskPyramid(mask, 5, 4, 2, PyramidFilter::kBinomial);
  ASSERT_EQ(binomial[1].size(), 6u);  // 3x2.
  EXPECT_EQ(box[1], (std::vector<uint8_t>{0, 1, 0, 0, 0, 0}));
  EXPECT_EQ(binomial[1], (std::vector<uint8_t>{0, 1, 1, 0, 1, 1}));
}

// For random masks and both filters, a coarse pixel is active exactly when the filtered mask is
// positive there (all weights are positive): the mask follows the image levels.
TEST(PyramidTest, MaskPyramidMatchesTheFilteredMask) {
  std::mt19937 rng(8);
  std::bernoulli_distribution on(0.08);
  for (PyramidFilter filter : kFilters) {
    const int w = 11, h = 7;
    std::vector<uint8_t> mask(w * h);
    Image image(w, h, 1);
    for (int i = 0; i < w * h; ++i) image.data[i] = mask[i] = on(rng) ? 1 : 0;
    const auto masks = MaskPyramid(mask, w, h, 4, filter);
    const std::vector<Image> levels = BuildPyramid(image, 4, filter);
    ASSERT_EQ(masks.size(), levels.size());
    for (size_t l = 0; l < levels.size(); ++l) {
      for (size_t i = 0; i < masks[l].size(); ++i) {
        EXPECT_EQ(masks[l][i], levels[l].data[i] > 0.0f ? 1 : 0)
            << PyramidFilterName(filter) << " level " << l << " pixel " << i;
      }
    }
  }
}

}  // namespace
}  // namespace sft
