#include "tests/testing/render_cache_fixture.h"

#include <gtest/gtest.h>

namespace sft {
namespace testing {

std::string MakeCacheFixture(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                             const RenderCacheOptions& options, CacheFixture* fixture) {
  Status status = MakeDatasetViews(dataset, &fixture->views);
  if (!status.ok()) return status.message();
  MeshToArrays(mesh, &fixture->positions, &fixture->faces);
  fixture->params = std::make_unique<SceneParameters>(fixture->positions, material,
                                                      static_cast<int>(dataset.lights.size()));
  std::vector<int> all(dataset.views.size());
  for (size_t v = 0; v < all.size(); ++v) all[v] = static_cast<int>(v);
  status = RenderCache::Create(dataset, &fixture->views, all, fixture->faces, material,
                               fixture->params.get(), options, &fixture->cache);
  return status.ok() ? "" : status.message();
}

std::vector<double> AdjointGradient(RenderCache* cache, const SceneParameters& params) {
  std::vector<double> gradient(params.layout().size(), 0.0);
  for (int v = 0; v < cache->num_views(); ++v) {
    EXPECT_TRUE(cache->AddAdjointGradient(v, cache->AdjointWeights(v), &gradient));
  }
  return gradient;
}

}  // namespace testing
}  // namespace sft
