// The vertex step of a glossy object at its true shape and material. With the lobe off in both
// passes (the geometry stages' `pin: {specular: false}`), the residual is the missing highlight,
// and the step moves the true shape to explain it. With the lobe in the residual and out of the
// gradient (RenderCacheOptions::gradient_specular = false), the residual at the truth is noise
// only, so the mean step over seeds is zero within its standard error: the truth stays a
// stationary point while the step still leaves out the lobe's vertex derivative.
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

struct StepStats {
  double mean_squared_norm = 0.0;  // ‖mean gradient over seeds‖².
  double noise = 0.0;  // Σ over entries of the mean's variance (its expected ‖·‖²).
  double specular_gradient = 0.0;  // the specular weight's entry, summed over seeds.
};

// The vertex gradient's mean over `seeds` seeds at the true shape and material.
StepStats VertexStep(const Dataset& dataset, const TriMesh& mesh, const Material& truth,
                     bool specular, bool gradient_specular, int seeds) {
  RenderCacheOptions options;
  options.render.spp = 4;
  options.render.bounces = 1;
  options.render.shading = Shading::kSmooth;
  options.render.effects.specular = specular;
  options.pyramid_levels = 1;
  options.independent_gradient = true;  // no variance term: only the residual's mean matters.
  options.gradient_specular = gradient_specular;
  testing::CacheFixture f;
  EXPECT_EQ(testing::MakeCacheFixture(dataset, mesh, truth, options, &f), "");
  RenderCache* cache = f.cache.get();
  ActiveParameters active;
  active.vertices = true;
  active.albedo = false;
  active.roughness = false;
  active.specular = true;  // its entry shows whether the adjoint pass rendered the lobe.
  cache->SetActive(active);
  const int n = 3 * static_cast<int>(f.positions.size());
  std::vector<std::vector<double>> samples;
  double specular_gradient = 0.0;
  for (int s = 0; s < seeds; ++s) {
    cache->SetSeed(500 + s);
    cache->Render(/*rows=*/false);
    const std::vector<double> gradient = testing::AdjointGradient(cache, *f.params);
    samples.emplace_back(gradient.begin(), gradient.begin() + n);
    specular_gradient += std::abs(gradient[f.params->layout().SpecularIndex()]);
  }
  StepStats stats;
  stats.specular_gradient = specular_gradient;
  for (int i = 0; i < n; ++i) {
    double mean = 0.0, variance = 0.0;
    for (const auto& g : samples) mean += g[i] / seeds;
    for (const auto& g : samples) variance += (g[i] - mean) * (g[i] - mean) / (seeds - 1);
    stats.mean_squared_norm += mean * mean;
    stats.noise += variance / seeds;
  }
  return stats;
}

TEST(GradientSpecularTest, TheTruthStaysStationaryWithTheLobeInTheResidualOnly) {
  testing::TempDir dir;
  // A glossy icosphere under the camera flash, smooth-shaded; the target has 1024 spp.
  ASSERT_EQ(
      testing::SynthIcosphere(
          dir.Join("ds"),
          "--cameras 3 --zooms 1 --res 24 --spp 1024 --bounces 1 --shading smooth "
          "--material '{\"albedo\": [0.4, 0.4, 0.4], \"roughness\": 0.3, \"specular\": 0.5}'"),
      "");
  Dataset dataset;
  TriMesh mesh;
  Material truth;
  ASSERT_TRUE(ReadDataset(dir.Join("ds"), &dataset).ok());
  ASSERT_TRUE(ReadMesh(dir.Join("ds/gt/mesh.ply"), &mesh).ok());
  ASSERT_TRUE(LoadMaterial(dir.Join("ds/gt/material.json"), mesh, &truth).ok());
  const int kSeeds = 16;
  const StepStats pinned = VertexStep(dataset, mesh, truth, /*specular=*/false, true, kSeeds);
  const StepStats residual_only =
      VertexStep(dataset, mesh, truth, /*specular=*/true, false, kSeeds);
  // The lobe off in both passes: a mean step far above its noise (the missing highlights).
  EXPECT_GT(pinned.mean_squared_norm, 10.0 * pinned.noise)
      << "mean² " << pinned.mean_squared_norm << " noise " << pinned.noise;
  // The lobe in the residual only: the mean step is noise (‖mean‖² has expectation `noise`; 2.5×
  // leaves room for the target's own noise and the spread of a sum of squares over the entries).
  EXPECT_LT(residual_only.mean_squared_norm, 2.5 * residual_only.noise)
      << "mean² " << residual_only.mean_squared_norm << " noise " << residual_only.noise;
  // And the bias it removes is the larger effect by far.
  EXPECT_GT(pinned.mean_squared_norm, 10.0 * residual_only.mean_squared_norm);
  // The step has no lobe: the specular weight, which only the lobe renders, gets no gradient
  // (exactly), while with the lobe in both passes it does.
  EXPECT_EQ(residual_only.specular_gradient, 0.0);
  const StepStats both = VertexStep(dataset, mesh, truth, /*specular=*/true, true, 2);
  EXPECT_GT(both.specular_gradient, 0.0);
}

}  // namespace
}  // namespace sft
