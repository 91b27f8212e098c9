// Google Benchmark: how the coarse levels of the residual pyramid get their Jacobian rows (issue 11
// item 1, docs/reconstruct.md). The bunny (5k faces) at 128², 1 path segment, vertex derivatives
// with edge sampling (reconstruction's geometry phase), 4 levels:
//   BM_PyramidChildRows        one level-0 render with rows; coarse rows are means of child rows.
//   BM_PyramidPerLevelRenders  each coarse level l rendered on its own with a camera of 2^-l the
//                              resolution (a coarse pixel's box filter = its children's union),
//                              at the same spp per pixel (arg 0) or at spp·4^l, the same samples
//                              per coarse pixel (arg 1); level 0 is rendered in both.
// Counters: entries_l = Jacobian entries at level l; noise_img_l and noise_row_l = the
// seed-to-seed noise over 4 seeds relative to the signal, √(Σ_p var_p / Σ_p mean_p²), of level
// l's pixel values (RGB sum) and of its rows' derivative along a fixed random-sign direction.
//   ./sft_benchmarks --benchmark_filter=Pyramid
#include <benchmark/benchmark.h>
#include <glog/logging.h>

#include <cmath>
#include <memory>
#include <vector>

#include "benchmarks/bunny_scene.h"
#include "src/core/rng.h"
#include "src/eval/throughput.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/optim/pyramid.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {
namespace {

constexpr int kResolution = 128;
constexpr int kSpp = 16;
constexpr int kLevels = 4;
constexpr int kNoiseSeeds = 4;

const BunnyScene& Fixture() {
  static const BunnyScene* fixture = [] {
    auto* f = new BunnyScene;
    MakeBunnyScene(kResolution, f);
    return f;
  }();
  return *fixture;
}

// `view` with a camera of 2^-level the resolution (pinhole: focal and principal point scale).
ViewSetup CoarseView(const ViewSetup& view, int level) {
  ViewSetup coarse = view;
  const double s = std::ldexp(1.0, -level);
  coarse.camera.width = view.camera.width >> level;
  coarse.camera.height = view.camera.height >> level;
  for (int k = 0; k < 4; ++k) coarse.camera.params[k] *= s;
  return coarse;
}

// Level-0 image and rows of `view` at `spp`.
void RenderRows(const ViewSetup& view, int spp, uint64_t seed, Image* image, LevelRows* rows) {
  const BunnyScene& f = Fixture();
  RenderOptions options;
  options.spp = spp;
  options.bounces = 1;
  options.seed = seed;
  DerivativeRequest request;
  request.params = ParameterSelection::Only(ParameterKind::kVertex);
  request.jacobian_rows = true;
  DerivativeOutput output;
  RenderViewWithDerivatives(*f.scene, f.material, view, options, request, /*num_lights=*/0, image,
                            &output);
  *rows = RowsFromRenderer(output.rows);
}

// Every level's image and rows by the method (`per_level` < 0: child rows; else per-level renders
// with spp·4^l when `per_level` = 1).
void Levels(int per_level, uint64_t seed, std::vector<Image>* images,
            std::vector<LevelRows>* rows) {
  const BunnyScene& f = Fixture();
  images->assign(kLevels, Image());
  rows->assign(kLevels, LevelRows());
  Image image;
  RenderRows(f.view, kSpp, seed, &image, &(*rows)[0]);
  if (per_level < 0) {
    *images = BuildPyramid(image, kLevels);
    for (int l = 1; l < kLevels; ++l) (*rows)[l] = DownsampleRows((*rows)[l - 1]);
    return;
  }
  (*images)[0] = image;
  for (int l = 1; l < kLevels; ++l) {
    const int spp = per_level == 1 ? kSpp << (2 * l) : kSpp;
    RenderRows(CoarseView(f.view, l), spp, seed, &(*images)[l], &(*rows)[l]);
  }
}

// A fixed random sign per parameter: the direction along which rows are compared.
double Sign(int param) { return (Mix64(static_cast<uint64_t>(param)) & 1) ? 1.0 : -1.0; }

// The derivative of the pixel's RGB sum along the random-sign direction.
double RowDot(const LevelRows& rows, size_t pixel) {
  double sum = 0.0;
  for (uint64_t e = rows.offsets[pixel]; e < rows.offsets[pixel + 1]; ++e) {
    const RowEntry& entry = rows.entries[e];
    sum += Sign(entry.param) * (entry.d[0] + entry.d[1] + entry.d[2]);
  }
  return sum;
}

// √(Σ_p var_p / Σ_p mean_p²) over the pixels of level l: the seed-to-seed noise relative to the
// signal, for pixel values and for the rows' directional derivative.
void Noise(int per_level, benchmark::State& state) {
  std::vector<std::vector<Image>> images(kNoiseSeeds);
  std::vector<std::vector<LevelRows>> rows(kNoiseSeeds);
  for (int s = 0; s < kNoiseSeeds; ++s) Levels(per_level, 100 + s, &images[s], &rows[s]);
  for (int l = 0; l < kLevels; ++l) {
    const Image& first = images[0][l];
    const size_t pixels = static_cast<size_t>(first.width) * first.height;
    double img_var = 0.0, img_signal = 0.0, row_var = 0.0, row_signal = 0.0;
    for (size_t p = 0; p < pixels; ++p) {
      double m = 0, m2 = 0, r = 0, r2 = 0;
      for (int s = 0; s < kNoiseSeeds; ++s) {
        const Image& im = images[s][l];
        const double value =
            im.data[p * im.channels] + im.data[p * im.channels + 1] + im.data[p * im.channels + 2];
        const double row = RowDot(rows[s][l], p);
        m += value, m2 += value * value, r += row, r2 += row * row;
      }
      m /= kNoiseSeeds, m2 /= kNoiseSeeds, r /= kNoiseSeeds, r2 /= kNoiseSeeds;
      img_var += std::max(0.0, m2 - m * m), img_signal += m * m;
      row_var += std::max(0.0, r2 - r * r), row_signal += r * r;
    }
    const std::string suffix = "_" + std::to_string(l);
    state.counters["noise_img" + suffix] = std::sqrt(img_var / std::max(1e-30, img_signal));
    state.counters["noise_row" + suffix] = std::sqrt(row_var / std::max(1e-30, row_signal));
    state.counters["entries" + suffix] = static_cast<double>(rows[0][l].entries.size());
  }
}

void BM_PyramidChildRows(benchmark::State& state) {
  std::vector<Image> images;
  std::vector<LevelRows> rows;
  for (auto _ : state) {
    Levels(-1, 1, &images, &rows);
    benchmark::DoNotOptimize(rows.data());
  }
  Noise(-1, state);
}
BENCHMARK(BM_PyramidChildRows)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

void BM_PyramidPerLevelRenders(benchmark::State& state) {
  const int same_samples = static_cast<int>(state.range(0));
  std::vector<Image> images;
  std::vector<LevelRows> rows;
  for (auto _ : state) {
    Levels(same_samples, 1, &images, &rows);
    benchmark::DoNotOptimize(rows.data());
  }
  Noise(same_samples, state);
}
BENCHMARK(BM_PyramidPerLevelRenders)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
}  // namespace sft
