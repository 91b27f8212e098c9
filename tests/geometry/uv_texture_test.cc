// UV textures: bilinear lookup with exact values at texel centres, between them and across the
// wrapped border, the footprint's texels and weights, and conversion from an image.
#include "src/geometry/uv_texture.h"

#include <gtest/gtest.h>

namespace sft {
namespace {

// 2×2 grey texture, texel (x, y) (row 0 = top) = 1 + x + 2y: top row 1 2, bottom row 3 4.
UvTexture Grey2x2() {
  UvTexture t(2, 2, 1);
  for (int k = 0; k < 4; ++k) t.texel(k)[0] = 1.0 + k;
  return t;
}

double At(const UvTexture& t, double u, double v) {
  double value = 0.0;
  t.Sample(Eigen::Vector2d(u, v), &value);
  return value;
}

TEST(UvTextureTest, TexelCentresAreExact) {
  const UvTexture t = Grey2x2();
  // Texel (x, y) is centred at uv = ((x + ½)/W, 1 − (y + ½)/H).
  EXPECT_EQ(At(t, 0.25, 0.75), 1.0);
  EXPECT_EQ(At(t, 0.75, 0.75), 2.0);
  EXPECT_EQ(At(t, 0.25, 0.25), 3.0);
  EXPECT_EQ(At(t, 0.75, 0.25), 4.0);
}

TEST(UvTextureTest, BilinearBetweenCentres) {
  const UvTexture t = Grey2x2();
  EXPECT_EQ(At(t, 0.5, 0.75), 1.5);     // halfway along the top row.
  EXPECT_EQ(At(t, 0.25, 0.5), 2.0);     // halfway down the left column.
  EXPECT_EQ(At(t, 0.5, 0.5), 2.5);      // the centre: the mean.
  EXPECT_EQ(At(t, 0.375, 0.75), 1.25);  // a quarter of the way.
  // (px, py) = (0.25, 0.25): weights 9/16, 3/16, 3/16, 1/16.
  EXPECT_EQ(At(t, 0.375, 0.625), 1.75);
  const BilinearFootprint f = t.Footprint(Eigen::Vector2d(0.375, 0.625));
  const int texels[4] = {0, 1, 2, 3};
  const double weights[4] = {9.0 / 16, 3.0 / 16, 3.0 / 16, 1.0 / 16};
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(f.texel[k], texels[k]);
    EXPECT_EQ(f.weight[k], weights[k]);
  }
}

TEST(UvTextureTest, WrapsAtTheBorders) {
  const UvTexture t = Grey2x2();
  // u = 0 is halfway between the right column (wrapped) and the left one.
  EXPECT_EQ(At(t, 0.0, 0.75), 1.5);
  EXPECT_EQ(At(t, 1.0, 0.75), 1.5);
  // v = 1 (top edge) is halfway between the top row and the bottom one (wrapped).
  EXPECT_EQ(At(t, 0.25, 1.0), 2.0);
  // Whole periods repeat, negative ones too.
  EXPECT_EQ(At(t, 1.25, 0.75), 1.0);
  EXPECT_EQ(At(t, -0.25, -1.25), 2.0);
  const BilinearFootprint f = t.Footprint(Eigen::Vector2d(0.0, 0.75));
  EXPECT_EQ(f.texel[0], 1);  // x0 = −1 wraps to column 1.
  EXPECT_EQ(f.texel[1], 0);
  EXPECT_EQ(f.weight[0] + f.weight[1], 1.0);
}

TEST(UvTextureTest, NonSquareAndRgb) {
  // 4×1 RGB: column x has (x, 10x, 100x).
  UvTexture t(4, 1, 3);
  for (int x = 0; x < 4; ++x) {
    for (int c = 0; c < 3; ++c) t.texel(x)[c] = x * (c == 0 ? 1 : c == 1 ? 10 : 100);
  }
  double rgb[3];
  t.Sample(Eigen::Vector2d(0.25, 0.3), rgb);  // between columns 0 and 1; one row: any v.
  EXPECT_EQ(rgb[0], 0.5);
  EXPECT_EQ(rgb[1], 5.0);
  EXPECT_EQ(rgb[2], 50.0);
}

TEST(UvTextureTest, FromImageKeepsTheFirstChannels) {
  Image image(2, 1, 4);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = 0.125f * i;
  const UvTexture t = UvTexture::FromImage(image, 3);
  ASSERT_EQ(t.channels(), 3);
  ASSERT_EQ(t.num_texels(), 2);
  EXPECT_EQ(t.texel(1)[0], 0.5);  // image value 4 (pixel 1, channel 0).
  EXPECT_EQ(t.texel(1)[2], 0.75);
}

}  // namespace
}  // namespace sft
