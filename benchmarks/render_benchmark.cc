// Google Benchmark: raw Embree vs the renderer on the bunny (5k faces), 256² pixels, 4 spp, all
// cores, on the renderer's own BVH and ray set (src/eval/throughput.h). items_per_second = rays
// per wall-clock second (real time: the work is multithreaded).
//   ./sft_benchmarks --benchmark_filter=Embree
// BM_RenderJacobianRows and BM_RenderAdjoint render the same view as BM_RenderTwoBounces (2
// bounces, same material) with derivatives (albedo, roughness, specular, light scale; no vertex
// derivatives yet): their times over BM_RenderTwoBounces' are the derivative passes' cost ratios
// (issue 3 item 6; `sft bench gradient` measures them over 64 views).
#include <benchmark/benchmark.h>
#include <glog/logging.h>

#include <memory>
#include <utility>
#include <vector>

#include "benchmarks/bunny_scene.h"
#include "src/core/rng.h"
#include "src/eval/throughput.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {
namespace {

constexpr int kResolution = 256;
constexpr int kSpp = 4;
constexpr uint64_t kSeed = 0;

// The bunny scene, view, material and ray sets, built once.
struct BunnyFixture {
  std::unique_ptr<RenderScene> scene;
  Material material;
  ViewSetup view;
  std::vector<BenchRay> camera_rays;
  std::vector<BenchRay> shadow_rays;
  ViewSetup derivative_view;  // `view` with its light as dataset light 0 (a scale parameter).
  Image weights;              // adjoint weights: uniform in [−1, 1], fixed.
};

const BunnyFixture& Bunny() {
  static const BunnyFixture* fixture = [] {
    auto* f = new BunnyFixture;
    BunnyScene bunny;
    MakeBunnyScene(kResolution, &bunny);
    f->scene = std::move(bunny.scene);
    f->material = std::move(bunny.material);
    f->view = bunny.view;
    f->camera_rays = CameraRays(f->view, kSpp, kSeed);
    f->shadow_rays = ShadowRays(*f->scene, f->view, kSpp, kSeed, /*threads=*/0);
    f->derivative_view = f->view;
    for (PointLight& light : f->derivative_view.point_lights) light.light_index = 0;
    f->weights = Image(kResolution, kResolution, 3);
    for (size_t i = 0; i < f->weights.data.size(); ++i) {
      f->weights.data[i] = static_cast<float>(2.0 * (Mix64(i) >> 11) * 0x1.0p-53 - 1.0);
    }
    return f;
  }();
  return *fixture;
}

void RunEmbree(benchmark::State& state, EmbreeQuery query) {
  const BunnyFixture& bunny = Bunny();
  const std::vector<BenchRay>& rays =
      query == EmbreeQuery::kOccluded1 ? bunny.shadow_rays : bunny.camera_rays;
  int64_t rays_traced = 0;
  for (auto _ : state) {
    const RayRate rate = TraceEmbree(bunny.scene->embree_scene(), rays, query, /*threads=*/0);
    benchmark::DoNotOptimize(rate.hits);
    rays_traced += rate.rays;
  }
  state.SetItemsProcessed(rays_traced);
}

void RunRender(benchmark::State& state, int bounces) {
  const BunnyFixture& bunny = Bunny();
  RenderOptions options;
  options.spp = kSpp;
  options.bounces = bounces;
  options.seed = kSeed;
  int64_t rays_traced = 0;
  for (auto _ : state) {
    Image image;
    RenderStats stats;
    RenderView(*bunny.scene, bunny.material, bunny.view, options, &image, &stats);
    rays_traced += stats.TotalRays();
  }
  state.SetItemsProcessed(rays_traced);
}

// RenderViewWithDerivatives at 2 bounces: Jacobian rows, or the adjoint gradient only.
void RunDerivatives(benchmark::State& state, bool rows) {
  const BunnyFixture& bunny = Bunny();
  RenderOptions options;
  options.spp = kSpp;
  options.bounces = 2;
  options.seed = kSeed;
  DerivativeRequest request;
  request.jacobian_rows = rows;
  request.adjoint_weights = rows ? nullptr : &bunny.weights;
  int64_t rays_traced = 0;
  int64_t entries = 0;
  for (auto _ : state) {
    Image image;
    DerivativeOutput output;
    RenderStats stats;
    RenderViewWithDerivatives(*bunny.scene, bunny.material, bunny.derivative_view, options, request,
                              /*num_lights=*/1, &image, &output, &stats);
    rays_traced += stats.TotalRays();
    entries = static_cast<int64_t>(output.rows.entries.size());
    benchmark::DoNotOptimize(output.gradient.data());
  }
  state.SetItemsProcessed(rays_traced);
  if (rows) state.counters["entries"] = static_cast<double>(entries);
}

void BM_EmbreeIntersect1(benchmark::State& state) { RunEmbree(state, EmbreeQuery::kIntersect1); }
void BM_EmbreeIntersect8(benchmark::State& state) { RunEmbree(state, EmbreeQuery::kIntersect8); }
void BM_EmbreeOccluded1(benchmark::State& state) { RunEmbree(state, EmbreeQuery::kOccluded1); }
void BM_RenderDirect(benchmark::State& state) { RunRender(state, 1); }
void BM_RenderTwoBounces(benchmark::State& state) { RunRender(state, 2); }
void BM_RenderJacobianRows(benchmark::State& state) { RunDerivatives(state, /*rows=*/true); }
void BM_RenderAdjoint(benchmark::State& state) { RunDerivatives(state, /*rows=*/false); }

BENCHMARK(BM_EmbreeIntersect1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EmbreeIntersect8)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EmbreeOccluded1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderDirect)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderTwoBounces)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderJacobianRows)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderAdjoint)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sft

BENCHMARK_MAIN();
