// Used texels and charts of a UV texture (src/geometry/uv_texel_charts.h): every texel a bilinear
// lookup inside a face reads is used (and nothing more than one texel beyond), UV seams split
// charts, and dilation fills exactly the unused texels.
#include "src/geometry/uv_texel_charts.h"

#include <gtest/gtest.h>

#include <set>

#include "src/core/rng.h"

namespace sft {
namespace {

double Uniform(uint64_t key) { return static_cast<double>(Mix64(key) >> 11) * 0x1.0p-53; }

// Two triangles of a quad (v0 v1 v2, v0 v2 v3) in one chart in the left half of a 16² texture,
// and a third, unconnected-in-UV triangle (the same v0 v2 edge, other UVs) in the right half.
struct Layout {
  std::vector<Eigen::Vector3i> faces = {{0, 1, 2}, {0, 2, 3}, {0, 2, 4}};
  std::vector<Eigen::Vector2d> uvs = {{0.1, 0.1}, {0.4, 0.1}, {0.4, 0.4},   // face 0
                                      {0.1, 0.1}, {0.4, 0.4}, {0.1, 0.4},   // face 1 (shares 0–2)
                                      {0.6, 0.6}, {0.9, 0.9}, {0.6, 0.9}};  // face 2 (a seam)
};

TEST(UvTexelChartsTest, ChartsFollowUvSeams) {
  const Layout l;
  const UvTexelCharts charts = ComputeUvTexelCharts(l.faces, l.uvs, 16, 16);
  EXPECT_EQ(charts.num_charts, 2);
  EXPECT_EQ(charts.chart_of_face[0], charts.chart_of_face[1]);
  EXPECT_NE(charts.chart_of_face[0], charts.chart_of_face[2]);
}

// Bilinear footprints of random points inside every face only read used texels of the face's
// chart; every used texel lies within one texel (Chebyshev, in pixel-centre coordinates) of its
// face's triangle's bounding box.
TEST(UvTexelChartsTest, UsedTexelsAreWhatLookupsRead) {
  const Layout l;
  const int n = 16;
  const UvTexelCharts charts = ComputeUvTexelCharts(l.faces, l.uvs, n, n);
  const UvTexture texture(n, n, 1);
  std::set<int> read;
  for (int f = 0; f < 3; ++f) {
    for (int k = 0; k < 4000; ++k) {
      double a = Uniform(3 * k + 100000 * f), b = Uniform(3 * k + 1 + 100000 * f);
      if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
      const Eigen::Vector2d uv =
          (1.0 - a - b) * l.uvs[3 * f] + a * l.uvs[3 * f + 1] + b * l.uvs[3 * f + 2];
      const BilinearFootprint fp = texture.Footprint(uv);
      for (int t = 0; t < 4; ++t) {
        if (fp.weight[t] <= 0.0) continue;
        ASSERT_TRUE(charts.used(fp.texel[t])) << "face " << f << " texel " << fp.texel[t];
        EXPECT_EQ(charts.chart_of_texel[fp.texel[t]], charts.chart_of_face[f]);
        read.insert(fp.texel[t]);
      }
    }
  }
  // Random samples reach nearly every used texel (the rest lie at a triangle's sliver corner).
  EXPECT_GE(static_cast<int>(read.size()), charts.used_texels * 9 / 10);
  EXPECT_LE(static_cast<int>(read.size()), charts.used_texels);
  EXPECT_LT(charts.used_texels, n * n / 2);
}

TEST(UvTexelChartsTest, DilationFillsOnlyUnusedTexels) {
  const Layout l;
  const int n = 16;
  const UvTexelCharts charts = ComputeUvTexelCharts(l.faces, l.uvs, n, n);
  std::vector<double> values(2 * n * n, -1.0);
  for (int k = 0; k < n * n; ++k) {
    if (charts.used(k)) values[2 * k] = values[2 * k + 1] = 0.25 + 0.5 * charts.chart_of_texel[k];
  }
  const std::vector<double> before = values;
  EXPECT_GT(DilateUnusedTexels(charts, 2, &values), 0);
  for (int k = 0; k < n * n; ++k) {
    if (charts.used(k)) {
      EXPECT_EQ(values[2 * k], before[2 * k]);
    } else {
      // Means of the two chart values: within their range, never the -1 fill.
      EXPECT_GE(values[2 * k], 0.25) << k;
      EXPECT_LE(values[2 * k], 0.75) << k;
    }
  }
}

}  // namespace
}  // namespace sft
