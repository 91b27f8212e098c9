// Adam's tail averaging (AdamOptions::average_tail): the run ends at the mean of its last
// iterates, and on a noisy material fit started at the truth that mean is closer to the truth than
// the last iterate (constant-step Adam keeps wandering by about one step size per parameter).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/parameters.h"
#include "src/optim/problem.h"
#include "src/optim/render_cache.h"
#include "src/optim/solvers.h"
#include "tests/testing/render_cache_fixture.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// Squared distance of the material parameters (albedo, roughness, specular) from the truth's.
double MaterialError(const std::vector<double>& values, const std::vector<double>& truth,
                     const ParameterLayout& layout) {
  double error = 0.0;
  for (int i = layout.AlbedoOffset(); i <= layout.SpecularIndex(); ++i) {
    error += (values[i] - truth[i]) * (values[i] - truth[i]);
  }
  return error;
}

TEST(AdamAverageTest, EndsAtTheTailMeanWhichIsCloserToTheTruth) {
  testing::TempDir dir;
  ASSERT_EQ(testing::SynthIcosphere(
                dir.Join("ds"),
                "--cameras 6 --zooms 1 --res 20 --spp 256 --bounces 1 --shading flat --material "
                "'{\"albedo\": [0.5, 0.3, 0.2], \"roughness\": 0.4, \"specular\": 0.3}'"),
            "");
  Dataset dataset;
  TriMesh mesh;
  Material truth;
  ASSERT_TRUE(ReadDataset(dir.Join("ds"), &dataset).ok());
  ASSERT_TRUE(ReadMesh(dir.Join("ds/gt/mesh.ply"), &mesh).ok());
  ASSERT_TRUE(LoadMaterial(dir.Join("ds/gt/material.json"), mesh, &truth).ok());
  RenderCacheOptions cache_options;
  cache_options.render.spp = 4;  // a noisy gradient, so the last iterate wanders.
  cache_options.render.bounces = 1;
  cache_options.pyramid_levels = 1;
  cache_options.independent_gradient = true;
  testing::CacheFixture f;
  ASSERT_EQ(testing::MakeCacheFixture(dataset, mesh, truth, cache_options, &f), "");
  SceneParameters& params = *f.params;
  RenderCache* cache = f.cache.get();
  const std::vector<double> truth_values = params.values();
  ActiveParameters active;
  active.albedo = true;
  active.roughness = true;
  active.specular = true;
  cache->SetActive(active);
  cache->SetSeed(7);

  SolverOptions solver;
  solver.kind = SolverKind::kAdam;
  solver.steps = 60;
  solver.adam.resample = true;
  solver.adam.average_tail = 0.5;
  ProblemOptions problem;
  // The iterates as the solver stores them (the parameters after each step).
  std::vector<std::vector<double>> iterates;
  std::vector<double> full_costs;
  SolverHooks hooks;
  hooks.on_iteration = [&](const IterationInfo& info) {
    if (info.full) {
      full_costs.push_back(info.cost);
    } else {
      iterates.push_back(params.values());
    }
    return true;
  };
  AdamState state;
  SolverRunStats stats;
  ASSERT_TRUE(RunAdam(solver, problem, cache, &params, hooks, {}, &state, &stats).ok());
  ASSERT_EQ(iterates.size(), 60u);
  // One closing evaluation of all views, at the end point.
  ASSERT_EQ(full_costs.size(), 1u);
  EXPECT_GT(full_costs[0], 0.0);

  // The final state is the mean of iterates 31..60, to rounding.
  const ParameterLayout& layout = params.layout();
  for (int i = layout.AlbedoOffset(); i <= layout.SpecularIndex(); ++i) {
    double mean = 0.0;
    for (size_t s = 30; s < iterates.size(); ++s) mean += iterates[s][i] / 30.0;
    ASSERT_NEAR(params.values()[i], mean, 1e-12) << layout.Describe(i);
  }
  // The mean is closer to the truth than the last iterate. Texels whose gradient is mostly noise
  // random-walk (Adam moves each by about its step size whatever the gradient's size); the mean
  // of a random walk's second half has 2/3 of the endpoint's variance, and texels held near the
  // truth by their signal gain more. Summed over hundreds of texels the ratio concentrates.
  const double last = MaterialError(iterates.back(), truth_values, layout);
  const double averaged = MaterialError(params.values(), truth_values, layout);
  EXPECT_LT(1.25 * averaged, last) << "averaged " << averaged << " last " << last;
}

}  // namespace
}  // namespace sft
