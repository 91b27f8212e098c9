// Seed-to-seed consistency of derivative images (src/eval/derivative_consistency.h): a
// derivative that is nearly deterministic measures as such, the noise of an edge-sampled vertex
// derivative falls like 1/√spp, and bad seed counts are refused.
#include "src/eval/derivative_consistency.h"

#include <gtest/gtest.h>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

class DerivativeConsistencyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string root = testing::DataDir() + "/cycles/bunny_point_ggx_gi";
    ASSERT_TRUE(ReadDataset(root, &dataset_).ok());
    ASSERT_TRUE(ReadMesh(root + "/gt/mesh.ply", &mesh_).ok());
  }
  ConsistencyResult Measure(const std::string& material_json, ParameterKind kind, int spp) {
    Material material;
    EXPECT_TRUE(LoadMaterial(material_json, mesh_, &material).ok());
    GradcheckOptions options;
    options.kind = kind;
    options.views = {2};
    options.render.spp = spp;
    options.render.bounces = 1;
    ConsistencyResult result;
    const Status status =
        MeasureDerivativeConsistency(dataset_, mesh_, material, options, 3, &result);
    EXPECT_TRUE(status.ok()) << status.message();
    return result;
  }
  Dataset dataset_;
  TriMesh mesh_;
};

// Albedo under direct light: the derivative is the render divided by the albedo, whose only noise
// is the pixel's sampling noise: alike across seeds.
TEST_F(DerivativeConsistencyTest, AlbedoDerivativeIsAlikeAcrossSeeds) {
  const ConsistencyResult r =
      Measure(R"({"albedo": [0.6, 0.5, 0.4], "roughness": 0.5, "resolution": 2})",
              ParameterKind::kAlbedo, 16);
  ASSERT_EQ(r.views.size(), 1u);
  EXPECT_EQ(r.seeds, 3);
  EXPECT_EQ(r.block, 1);
  EXPECT_GT(r.pixel_correlation, 0.9);
  EXPECT_LT(r.noise_to_signal, 0.4);
  EXPECT_GT(r.noise_to_signal, 0.0);  // different seeds: not the same image.
}

// Vertices: the seed-to-seed spread falls at least like 1/√spp (the scrambled Sobol sampler does
// better on smooth integrands: 0.08 was measured for 16× the samples here), so 16 times the
// samples leave at most a quarter-and-a-bit of the noise, and the images grow more alike.
TEST_F(DerivativeConsistencyTest, NoiseFallsAtLeastLikeOneOverRootSpp) {
  const char kGlossy[] = R"({"albedo": [0.6, 0.5, 0.4], "roughness": 0.3, "specular": 0.5})";
  const ConsistencyResult low = Measure(kGlossy, ParameterKind::kVertex, 2);
  const ConsistencyResult high = Measure(kGlossy, ParameterKind::kVertex, 32);
  EXPECT_EQ(low.block, 8);
  ASSERT_GT(low.noise_to_signal, 0.0);
  const double ratio = high.noise_to_signal / low.noise_to_signal;
  EXPECT_GT(ratio, 0.0);
  EXPECT_LT(ratio, 0.35) << low.noise_to_signal << " " << high.noise_to_signal;
  EXPECT_GT(high.pixel_correlation, low.pixel_correlation);
}

TEST_F(DerivativeConsistencyTest, SeedCountOutsideTheRangeIsRefused) {
  Material material;
  ASSERT_TRUE(LoadMaterial(R"({"albedo": [0.5, 0.5, 0.5]})", mesh_, &material).ok());
  GradcheckOptions options;
  options.views = {0};
  ConsistencyResult result;
  for (int seeds : {0, 1, 65}) {
    const Status status =
        MeasureDerivativeConsistency(dataset_, mesh_, material, options, seeds, &result);
    EXPECT_FALSE(status.ok());
    EXPECT_NE(status.message().find("seeds"), std::string::npos);
  }
}

}  // namespace
}  // namespace sft
