// A RenderCache over every view of a dataset at a given mesh and material, with the scene
// parameters it reads and writes: the scaffolding of the tests that look at one stage's gradient
// or solver directly (tests/optim/adam_average_test.cc, gradient_specular_test.cc,
// independent_gradient_test.cc).
#ifndef SFT_TESTS_TESTING_RENDER_CACHE_FIXTURE_H_
#define SFT_TESTS_TESTING_RENDER_CACHE_FIXTURE_H_

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/optim/parameters.h"
#include "src/optim/render_cache.h"

namespace sft {
namespace testing {

struct CacheFixture {
  DatasetViews views;  // the cache points at these and at *params: members live together.
  std::vector<Eigen::Vector3d> positions;  // the mesh's vertices, as the parameters start.
  std::vector<Eigen::Vector3i> faces;
  std::unique_ptr<SceneParameters> params;
  std::unique_ptr<RenderCache> cache;
};

// Builds *fixture for `dataset` (every view) at `mesh` and `material`; "" on success, else the
// error.
std::string MakeCacheFixture(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                             const RenderCacheOptions& options, CacheFixture* fixture);

// The adjoint gradient (every view's AddAdjointGradient at its AdjointWeights) at the cache's
// current render, over the whole parameter layout; entries of inactive parameters are 0.
std::vector<double> AdjointGradient(RenderCache* cache, const SceneParameters& params);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_RENDER_CACHE_FIXTURE_H_
