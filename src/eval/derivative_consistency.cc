#include "src/eval/derivative_consistency.h"

#include <cmath>

#include "src/render/scene.h"

namespace sft {
namespace {

double Correlation(const std::vector<double>& a, const std::vector<double>& b) {
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    ab += a[i] * b[i];
    aa += a[i] * a[i];
    bb += b[i] * b[i];
  }
  return aa > 0.0 && bb > 0.0 ? ab / std::sqrt(aa * bb) : 0.0;
}

double MeanPairCorrelation(const std::vector<std::vector<double>>& images) {
  double sum = 0.0;
  int pairs = 0;
  for (size_t i = 0; i < images.size(); ++i) {
    for (size_t j = i + 1; j < images.size(); ++j, ++pairs)
      sum += Correlation(images[i], images[j]);
  }
  return pairs > 0 ? sum / pairs : 0.0;
}

// √(Σ_i var_s) / √(Σ_i mean_s²), the variance unbiased over the seeds.
double NoiseToSignal(const std::vector<std::vector<double>>& images) {
  const double k = static_cast<double>(images.size());
  double var = 0.0, signal = 0.0;
  for (size_t i = 0; i < images[0].size(); ++i) {
    double mean = 0.0;
    for (const auto& image : images) mean += image[i] / k;
    double v = 0.0;
    for (const auto& image : images) v += (image[i] - mean) * (image[i] - mean);
    var += v / (k - 1.0);
    signal += mean * mean;
  }
  return signal > 0.0 ? std::sqrt(var / signal) : (var > 0.0 ? INFINITY : 0.0);
}

}  // namespace

Status MeasureDerivativeConsistency(const Dataset& dataset, const TriMesh& mesh,
                                    const Material& material, const GradcheckOptions& options,
                                    int seeds, ConsistencyResult* result) {
  if (seeds < 2 || seeds > 64) return Status::Error("consistency seeds: must be in [2, 64]");
  GradcheckSetup setup;
  SFT_RETURN_IF_ERROR(PrepareGradcheck(dataset, options, &setup));
  const RenderScene scene(mesh);
  const int num_lights = static_cast<int>(dataset.lights.size());
  const ParameterLayout layout = MakeParameterLayout(scene, material, num_lights);
  const std::vector<double> delta =
      GradcheckDirection(scene, layout, options.kind, options.direction_seed);
  *result = ConsistencyResult();
  result->seeds = seeds;
  result->block = setup.block;
  for (int v : setup.selected) {
    const ViewSetup& view = setup.views.views[v];
    std::vector<std::vector<double>> pixels, blocks;
    for (int s = 0; s < seeds; ++s) {
      RenderOptions render = options.render;
      render.seed = options.render.seed + static_cast<uint64_t>(s);
      render.sampling_material = &material;
      Image image;
      DerivativeOutput out;
      RenderStats stats;
      RenderViewWithDerivatives(scene, material, view, render, setup.request, num_lights, &image,
                                &out, &stats);
      pixels.push_back(DirectionalDerivativeImage(out.rows, delta));
      blocks.push_back(
          BlockSums(pixels.back(), view.camera.width, view.camera.height, setup.block));
    }
    ConsistencyViewResult r;
    r.view = v;
    r.pixel_correlation = MeanPairCorrelation(pixels);
    r.block_correlation = MeanPairCorrelation(blocks);
    r.noise_to_signal = NoiseToSignal(pixels);
    result->views.push_back(r);
    const double n = static_cast<double>(setup.selected.size());
    result->pixel_correlation += r.pixel_correlation / n;
    result->block_correlation += r.block_correlation / n;
    result->noise_to_signal += r.noise_to_signal / n;
  }
  return Status::Ok();
}

}  // namespace sft
