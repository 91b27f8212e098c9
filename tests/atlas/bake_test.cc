// Baking: the atlas textures give back the mesh-colors material at every mesh-colors texel's
// representative point, and dilation leaves no texel empty.
#include "src/atlas/bake.h"

#include <gtest/gtest.h>

#include <random>

#include "src/geometry/material.h"
#include "tests/testing/meshes.h"

namespace sft {
namespace {

// A material with a random value in every mesh-colors texel.
Material RandomMaterial(int num_faces, int resolution, unsigned seed) {
  Material m = ConstantMaterial(num_faces, Eigen::Vector3d::Constant(0.5), 0.5, 0.0, resolution);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(0.1, 0.9);
  for (double& v : m.albedo.values()) v = value(rng);
  for (double& v : m.roughness.values()) v = value(rng);
  return m;
}

struct RoundTrip {
  int samples = 0;
  int exact = 0;
};

// Looks every mesh-colors texel's representative point up in the baked textures (nearest texel).
// Texels with i + j = r are left out: their part of the triangle is a single point (a corner of
// the barycentric grid on the face's far edge), which the renderer meets only on that edge.
RoundTrip SampleBack(const UvAtlas& atlas, const Material& m, const BakedMaterial& baked) {
  RoundTrip result;
  const int r = m.albedo.resolution();
  for (size_t f = 0; f < atlas.chart_of_face.size(); ++f) {
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; i + j < r; ++j) {
        const Eigen::Vector2d ab = MeshColors::TexelCenter(r, i, j);
        const Eigen::Vector2d uv = (1.0 - ab.x() - ab.y()) * atlas.corner_uv[3 * f] +
                                   ab.x() * atlas.corner_uv[3 * f + 1] +
                                   ab.y() * atlas.corner_uv[3 * f + 2];
        const Eigen::Vector2d t = UvToTexel(uv, atlas.texture_size);
        const int x = static_cast<int>(t.x()), y = static_cast<int>(t.y());
        const int k =
            static_cast<int>(f) * MeshColors::TexelsPerFace(r) + MeshColors::LocalIndex(r, i, j);
        bool same = std::abs(baked.roughness.at(x, y) - m.roughness.texel(k)[0]) < 1e-6;
        for (int c = 0; c < 3; ++c) {
          same = same && std::abs(baked.albedo.at(x, y, c) - m.albedo.texel(k)[c]) < 1e-6;
        }
        ++result.samples;
        result.exact += same ? 1 : 0;
      }
    }
  }
  return result;
}

TEST(BakeTest, RoundTripThroughTheAtlas) {
  const testing::Triangles bunny = testing::ReadTestMesh("bunny_watertight_5k.obj");
  UvAtlasOptions options;
  options.texture_size = 1024;
  UvAtlas atlas;
  UvAtlasReport atlas_report;
  ASSERT_TRUE(BuildUvAtlas(bunny.positions, bunny.faces, options, &atlas, &atlas_report).ok());
  for (int resolution : {1, 3}) {
    const Material m = RandomMaterial(static_cast<int>(bunny.faces.size()), resolution, 7);
    BakedMaterial baked;
    BakeReport report;
    ASSERT_TRUE(BakeMaterial(atlas, m, &baked, &report).ok());
    const RoundTrip trip = SampleBack(atlas, m, baked);
    // Resolution 1 is one value per face: the texel under a face's centroid is that face's unless
    // the face is thinner than a texel. At resolution 3 a mesh-colors texel is a few atlas texels
    // wide, and the nearest atlas texel's centre can fall into the neighbouring mesh-colors texel
    // (measured: 0.7% of the samples).
    const double fraction = static_cast<double>(trip.exact) / trip.samples;
    EXPECT_GT(fraction, resolution == 1 ? 0.999 : 0.98) << resolution;
    printf("resolution %d: %d of %d samples exact (%.4f); %d covered, %d edge, %d dilated texels\n",
           resolution, trip.exact, trip.samples, fraction, report.covered_texels,
           report.edge_texels, report.dilated_texels);
    // Dilation fills every texel: no black left for mip-mapping to pull in.
    EXPECT_EQ(report.covered_texels + report.edge_texels + report.dilated_texels,
              options.texture_size * options.texture_size);
    float darkest = 1.0f;
    for (float v : baked.albedo.data) darkest = std::min(darkest, v);
    EXPECT_GE(darkest, 0.1f - 1e-6f);
    EXPECT_NEAR(report.covered_texels,
                atlas_report.utilization * options.texture_size * options.texture_size,
                0.02 * options.texture_size * options.texture_size);
  }
}

TEST(BakeTest, FaceCountMismatchIsAnError) {
  const testing::Triangles sphere = testing::ReadTestMesh("icosphere_r1_320f.obj");
  UvAtlas atlas;
  UvAtlasReport report;
  UvAtlasOptions options;
  options.texture_size = 128;
  ASSERT_TRUE(BuildUvAtlas(sphere.positions, sphere.faces, options, &atlas, &report).ok());
  BakedMaterial baked;
  BakeReport bake_report;
  const Status status = BakeMaterial(atlas, ConstantMaterial(10, Eigen::Vector3d::Ones(), 0.5, 0.0),
                                     &baked, &bake_report);
  EXPECT_NE(status.message().find("10 faces"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace sft
