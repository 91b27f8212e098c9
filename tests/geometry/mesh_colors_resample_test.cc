// Resolution changes of mesh colours on an unchanged mesh: exact round trips, and each new texel
// reading the old texel under its centre.
#include "src/geometry/mesh_colors_resample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace sft {
namespace {

MeshColors RandomColors(int num_faces, int resolution, int channels, unsigned seed) {
  MeshColors colors(num_faces, resolution, channels);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (double& v : colors.values()) v = uniform(rng);
  return colors;
}

TEST(ResampleMeshColorsTest, SameResolutionIsTheIdentity) {
  for (int r = 0; r <= 8; ++r) {
    SCOPED_TRACE(r);
    const MeshColors colors = RandomColors(5, r, 3, 10 + r);
    const MeshColors same = ResampleMeshColors(colors, r);
    EXPECT_EQ(same.num_faces(), 5);
    EXPECT_EQ(same.resolution(), r);
    EXPECT_EQ(same.channels(), 3);
    EXPECT_EQ(same.values(), colors.values());
  }
}

TEST(ResampleMeshColorsTest, UpAndBackDownIsExact) {
  for (int r = 0; r <= 8; ++r) {
    for (int factor : {2, 3}) {
      SCOPED_TRACE(::testing::Message() << "r " << r << " factor " << factor);
      const MeshColors colors = RandomColors(4, r, 2, 100 + r);
      const MeshColors fine = ResampleMeshColors(colors, factor * r);
      ASSERT_EQ(fine.resolution(), factor * r);
      EXPECT_EQ(ResampleMeshColors(fine, r).values(), colors.values());
    }
  }
}

// Every texel at the new resolution holds the value of the old texel that contains its centre,
// written out from the layout (grid coordinates r·α, r·β floored, on the same face).
TEST(ResampleMeshColorsTest, EachTexelReadsTheOldTexelUnderItsCentre) {
  const int old_r = 3;
  MeshColors colors(2, old_r, 1);
  for (int k = 0; k < colors.num_texels(); ++k) colors.texel(k)[0] = k;  // value = old index.
  for (int new_r : {1, 2, 4, 5, 7}) {
    SCOPED_TRACE(new_r);
    const MeshColors resampled = ResampleMeshColors(colors, new_r);
    for (int f = 0; f < 2; ++f) {
      for (int i = 0; i <= new_r; ++i) {
        for (int j = 0; j <= new_r - i; ++j) {
          const Eigen::Vector2d c = MeshColors::TexelCenter(new_r, i, j);
          const int old_i = std::min(old_r, static_cast<int>(std::floor(old_r * c.x() + 1e-9)));
          const int old_j =
              std::min(old_r - old_i, static_cast<int>(std::floor(old_r * c.y() + 1e-9)));
          const int expected =
              f * MeshColors::TexelsPerFace(old_r) + MeshColors::LocalIndex(old_r, old_i, old_j);
          const int k = f * MeshColors::TexelsPerFace(new_r) + MeshColors::LocalIndex(new_r, i, j);
          EXPECT_EQ(resampled.texel(k)[0], expected) << "face " << f << " texel " << i << "," << j;
        }
      }
    }
  }
}

TEST(ResampleMeshColorsTest, EmptyStaysEmpty) {
  EXPECT_EQ(ResampleMeshColors(MeshColors(), 4).num_texels(), 0);
  const MeshColors none = ResampleMeshColors(MeshColors(0, 2, 3), 5);
  EXPECT_EQ(none.num_faces(), 0);
  EXPECT_EQ(none.resolution(), 5);
  EXPECT_EQ(none.channels(), 3);
}

}  // namespace
}  // namespace sft
