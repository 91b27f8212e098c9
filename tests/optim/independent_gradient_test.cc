// The adjoint gradient at the true material of a glossy object: drawn from the residual's own
// paths it is biased by ½∂Var R̂ (it descends the render's variance, which grows with the specular
// weight); drawn from independent paths (RenderCacheOptions::independent_gradient) it is an
// unbiased estimate of the noise-free loss's gradient, which is zero at the truth up to the
// target's own noise.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/parameters.h"
#include "src/optim/render_cache.h"
#include "tests/testing/render_cache_fixture.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

struct GradientStats {
  double mean = 0.0;
  double standard_error = 0.0;
};

// The specular weight's adjoint gradient over `seeds` seeds at the true material.
GradientStats SpecularGradient(const Dataset& dataset, const TriMesh& mesh, const Material& truth,
                               bool independent, int seeds) {
  RenderCacheOptions options;
  options.render.spp = 1;  // few samples: a large variance, so its gradient is clear.
  options.render.bounces = 1;
  options.pyramid_levels = 1;
  options.independent_gradient = independent;
  testing::CacheFixture f;
  EXPECT_EQ(testing::MakeCacheFixture(dataset, mesh, truth, options, &f), "");
  RenderCache* cache = f.cache.get();
  ActiveParameters active;
  active.albedo = false;
  active.roughness = false;
  active.specular = true;
  cache->SetActive(active);
  const int index = f.params->layout().SpecularIndex();
  std::vector<double> samples;
  for (int s = 0; s < seeds; ++s) {
    cache->SetSeed(1000 + s);
    cache->Render(/*rows=*/false);
    samples.push_back(testing::AdjointGradient(cache, *f.params)[index]);
  }
  GradientStats stats;
  for (double g : samples) stats.mean += g / seeds;
  double variance = 0.0;
  for (double g : samples) variance += (g - stats.mean) * (g - stats.mean) / (seeds - 1);
  stats.standard_error = std::sqrt(variance / seeds);
  return stats;
}

TEST(IndependentGradientTest, UnbiasedAtTheTruthWhereTheSamePathsAreNot) {
  testing::TempDir dir;
  // A glossy icosphere under the camera flash; the target has 1024 spp, 1024× the fit's 1.
  ASSERT_EQ(testing::SynthIcosphere(
                dir.Join("ds"),
                "--cameras 2 --zooms 1 --res 20 --spp 1024 --bounces 1 --shading flat --material "
                "'{\"albedo\": [0.4, 0.4, 0.4], \"roughness\": 0.3, \"specular\": 0.5}'"),
            "");
  Dataset dataset;
  TriMesh mesh;
  Material truth;
  ASSERT_TRUE(ReadDataset(dir.Join("ds"), &dataset).ok());
  ASSERT_TRUE(ReadMesh(dir.Join("ds/gt/mesh.ply"), &mesh).ok());
  ASSERT_TRUE(LoadMaterial(dir.Join("ds/gt/material.json"), mesh, &truth).ok());
  const int kSeeds = 64;
  const GradientStats same = SpecularGradient(dataset, mesh, truth, false, kSeeds);
  const GradientStats independent = SpecularGradient(dataset, mesh, truth, true, kSeeds);
  // Same paths: a positive mean (descent lowers the specular weight, which lowers the variance),
  // far outside its standard error (6 SE).
  EXPECT_GT(same.mean, 6.0 * same.standard_error)
      << "mean " << same.mean << " SE " << same.standard_error;
  // Independent paths: zero within 4 standard errors (plus the target's noise, 1/1024 of the fit's
  // variance, which the bias's size bounds).
  EXPECT_LT(std::abs(independent.mean), 4.0 * independent.standard_error + same.mean / 64.0)
      << "mean " << independent.mean << " SE " << independent.standard_error;
  // The bias is the larger effect by far.
  EXPECT_GT(same.mean, 5.0 * std::abs(independent.mean))
      << "same " << same.mean << " independent " << independent.mean;
}

}  // namespace
}  // namespace sft
