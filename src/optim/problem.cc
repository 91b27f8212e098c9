#include "src/optim/problem.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <set>

#include "src/core/memory.h"

namespace sft {
namespace {

// Block offsets touched by each active pixel of each level of one view.
using PixelBlocks = std::vector<std::vector<int>>;  // [pixel] -> sorted offsets.

// The blocks a touched parameter brings into a pixel's superset: its own block and, for a texel,
// every texel of the same face that surface points sample (i + j < r). Texels are often smaller
// than pixels, so a few renders' samples miss most of the texels a pixel covers; their face is
// the better predictor. A UV texel brings only its own block (a bilinear lookup already touches
// four, and texels of a UV texture belong to no single face).
void ExpandBlock(const SceneParameters& params, const Material& material, int param,
                 std::vector<int>* out) {
  const BlockSpan span = params.BlockOf(param);
  const ParameterLayout& layout = params.layout();
  const bool albedo = !span.exposure && span.kind == ParameterKind::kAlbedo;
  if (material.has_uv_textures() ||
      (!albedo && (span.exposure || span.kind != ParameterKind::kRoughness))) {
    out->push_back(span.offset);
    return;
  }
  const int r = (albedo ? material.albedo : material.roughness).resolution();
  const int per_face = MeshColors::TexelsPerFace(r);
  const int base = albedo ? layout.AlbedoOffset() : layout.RoughnessOffset();
  const int size = albedo ? 3 : 1;
  const int face = (span.offset - base) / size / per_face;
  for (int i = 0; i < r || (r == 0 && i == 0); ++i) {
    for (int j = 0; i + j < std::max(r, 1); ++j) {
      out->push_back(base + size * (face * per_face + MeshColors::LocalIndex(r, i, j)));
    }
  }
}

void AddTouchedBlocks(const SceneParameters& params, const Material& material,
                      const LevelRows& rows, const std::vector<uint8_t>& active,
                      PixelBlocks* blocks) {
  std::vector<int> merged, fresh;
  for (size_t p = 0; p + 1 < rows.offsets.size(); ++p) {
    if (!active[p]) continue;
    fresh.clear();
    int last_block = -1;
    for (uint64_t i = rows.offsets[p]; i < rows.offsets[p + 1]; ++i) {
      const int block = params.BlockOf(rows.entries[i].param).offset;
      if (block != last_block) ExpandBlock(params, material, rows.entries[i].param, &fresh);
      last_block = block;
    }
    std::sort(fresh.begin(), fresh.end());
    fresh.erase(std::unique(fresh.begin(), fresh.end()), fresh.end());
    std::vector<int>& have = (*blocks)[p];
    merged.clear();
    std::set_union(have.begin(), have.end(), fresh.begin(), fresh.end(),
                   std::back_inserter(merged));
    have.swap(merged);
  }
}

// Supersets [view][level][pixel] -> block offsets: the union over `renders` derivative renders
// with seeds derived from the cache's seed, which is left as it was.
void CollectSupersets(RenderCache* cache, const SceneParameters& params, int renders,
                      std::vector<std::vector<PixelBlocks>>* supersets) {
  supersets->assign(cache->num_views(), {});
  for (int v = 0; v < cache->num_views(); ++v) {
    for (int l = 0; l < cache->num_levels(v); ++l) {
      const Image& image = cache->level(v, l).target;
      (*supersets)[v].emplace_back(static_cast<size_t>(image.width) * image.height);
    }
  }
  const uint64_t seed = cache->seed();
  for (int k = 0; k < renders; ++k) {
    cache->SetSeed(seed * 1000003ull + 7919ull * (k + 1));
    cache->Render(/*rows=*/true);
    for (int v = 0; v < cache->num_views(); ++v) {
      for (int l = 0; l < cache->num_levels(v); ++l) {
        AddTouchedBlocks(params, cache->material(), cache->level(v, l).rows,
                         cache->targets(v).active[l], &(*supersets)[v][l]);
      }
    }
  }
  cache->SetSeed(seed);
}

// Refuses a problem whose Jacobian Ceres cannot index (its block-sparse matrix counts entries in
// an int) or that does not fit into the available memory, with one line that says what to
// change. Bytes: 8 per Jacobian value, and about 32 per (residual block, parameter block) cell for
// Ceres' block structure, the residual blocks' parameter lists and the costs' offsets.
Status CheckJacobianSize(const std::vector<std::vector<PixelBlocks>>& supersets,
                         const SceneParameters& params, int64_t max_values) {
  int64_t cells = 0, values = 0;
  for (const std::vector<PixelBlocks>& view : supersets) {
    for (const PixelBlocks& level : view) {
      for (const std::vector<int>& offsets : level) {
        cells += static_cast<int64_t>(offsets.size());
        for (int offset : offsets) values += kPixelResiduals * params.BlockOf(offset).size;
      }
    }
  }
  const std::string hint =
      "; lower this stage's image_scale or texel_resolution, or fit it with \"solver\": "
      "\"adam\"";
  if (values > max_values) {
    return Status::Error("the Levenberg-Marquardt problem's Jacobian would hold " +
                         std::to_string(values) + " values, more than the " +
                         std::to_string(max_values) + " allowed (Ceres indexes them with an int)" +
                         hint);
  }
  std::string why;
  const uint64_t bytes = 8 * static_cast<uint64_t>(values) + 32 * static_cast<uint64_t>(cells);
  if (!CheckMemoryBudget(bytes, "the Levenberg-Marquardt problem's Jacobian", &why)) {
    return Status::Error(why + hint);
  }
  return Status::Ok();
}

}  // namespace

bool ProblemOptions::Check(std::string* why) const {
  if (superset_renders < 1 || superset_renders > 8) {
    *why = "superset_renders: must be in [1, 8]";
    return false;
  }
  if (max_jacobian_values < 1 || max_jacobian_values > std::numeric_limits<int>::max()) {
    *why = "max_jacobian_values: must be in [1, 2147483647]";
    return false;
  }
  return bounds.Check(why);
}

Status ReconstructionProblem::Build(RenderCache* cache, SceneParameters* params,
                                    const ProblemOptions& options,
                                    std::unique_ptr<ReconstructionProblem>* out) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  const auto start = std::chrono::steady_clock::now();
  auto result = std::unique_ptr<ReconstructionProblem>(new ReconstructionProblem());
  // Without an image term (regularizers only) there are no pixel blocks to build.
  const bool image_term = cache->level(0, 0).sqrt_weight > 0.0;
  std::vector<std::vector<PixelBlocks>> supersets;
  if (image_term) {
    CollectSupersets(cache, *params, options.superset_renders, &supersets);
    SFT_RETURN_IF_ERROR(CheckJacobianSize(supersets, *params, options.max_jacobian_values));
  }

  // The problem owns every cost function: the pixel costs below and the regularizers that
  // SolverHooks::add_regularizers adds later.
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = cache;
  result->problem_ = std::make_unique<ceres::Problem>(problem_options);
  ceres::Problem* problem = result->problem_.get();
  std::vector<bool> added(params->size(), false);
  ProblemStats& stats = result->stats_;
  std::vector<double*> blocks;
  std::vector<int> sizes;
  for (int v = 0; v < cache->num_views(); ++v) {
    for (int l = 0; l < cache->num_levels(v); ++l) {
      const std::vector<uint8_t>& active = cache->targets(v).active[l];
      for (size_t p = 0; p < active.size(); ++p) {
        if (!image_term || !active[p]) continue;
        std::vector<int>& offsets = supersets[v][l][p];
        if (offsets.empty()) {
          ++stats.pixels_without_parameters;
          continue;
        }
        blocks.clear();
        sizes.clear();
        for (int offset : offsets) {
          const BlockSpan span = params->BlockOf(offset);
          blocks.push_back(params->data() + offset);
          sizes.push_back(span.size);
          stats.superset_entries += span.size;
          if (!added[offset]) {
            added[offset] = true;
            problem->AddParameterBlock(params->data() + offset, span.size);
            ++stats.parameter_blocks;
            for (int i = 0; i < span.size; ++i) {
              const double lo = params->Lower(offset + i, options.bounds);
              const double hi = params->Upper(offset + i, options.bounds);
              if (std::isfinite(lo)) problem->SetParameterLowerBound(blocks.back(), i, lo);
              if (std::isfinite(hi)) problem->SetParameterUpperBound(blocks.back(), i, hi);
            }
          }
        }
        auto* cost = new PyramidPixelCost(&cache->level(v, l), cache->finite(), static_cast<int>(p),
                                          offsets, sizes);
        problem->AddResidualBlock(cost, nullptr, blocks);
        result->residuals_.push_back({v, l, static_cast<int>(p), cost});
        std::vector<int>().swap(offsets);
      }
    }
  }
  stats.residual_blocks = static_cast<int64_t>(result->residuals_.size());
  stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  *out = std::move(result);
  return Status::Ok();
}

double ReconstructionProblem::DroppedJacobianFraction(const RenderCache& cache) const {
  double dropped = 0.0, total = 0.0;
  for (const Residual& r : residuals_) {
    const LevelRows& rows = cache.level(r.view, r.level).rows;
    if (rows.offsets.empty()) continue;
    const std::vector<int>& offsets = r.cost->block_offsets();
    const std::vector<int32_t>& sizes = r.cost->parameter_block_sizes();
    size_t b = 0;
    for (uint64_t i = rows.offsets[r.pixel]; i < rows.offsets[r.pixel + 1]; ++i) {
      const RowEntry& e = rows.entries[i];
      const double mass = e.d[0] * e.d[0] + e.d[1] * e.d[1] + e.d[2] * e.d[2];
      total += mass;
      while (b < offsets.size() && offsets[b] + sizes[b] <= e.param) ++b;
      if (b == offsets.size() || e.param < offsets[b]) dropped += mass;
    }
  }
  return total > 0.0 ? dropped / total : 0.0;
}

void FillUnsampledTexels(MeshColors* colors) {
  const int r = colors->resolution();
  if (r < 1) return;
  const int per_face = MeshColors::TexelsPerFace(r);
  for (int f = 0; f < colors->num_faces(); ++f) {
    for (int i = 0; i <= r; ++i) {
      const int j = r - i;
      const int source =
          j > 0 ? MeshColors::LocalIndex(r, i, j - 1) : MeshColors::LocalIndex(r, i - 1, j);
      const double* from = colors->texel(f * per_face + source);
      double* to = colors->texel(f * per_face + MeshColors::LocalIndex(r, i, j));
      std::copy(from, from + colors->channels(), to);
    }
  }
}

}  // namespace sft
