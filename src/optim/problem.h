// The Ceres problem of one outer iteration (docs/reconstruct.md): parameter blocks into the flat
// state (src/optim/parameters.h) with the bounds of the feasible set, and one 3-residual block per
// active pyramid pixel of every view (cost_functions/pyramid_pixel.h) whose parameter blocks are a
// fixed superset: the union of the blocks the pixel's samples touched in `superset_renders` renders
// with different seeds (coarse pixels: the union of their children). Parameter kinds that the phase
// does not vary are not in the problem at all (constant). Texels that no surface point samples (the
// i + j = r texels of each face in the report's layout) never appear in a row, so they are not in
// the problem either; FillUnsampledTexels gives them their in-face neighbour's value for output.
#ifndef SFT_OPTIM_PROBLEM_H_
#define SFT_OPTIM_PROBLEM_H_

#include <ceres/problem.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cost_functions/pyramid_pixel.h"
#include "src/optim/parameters.h"
#include "src/optim/render_cache.h"

namespace sft {

struct ProblemOptions {
  int superset_renders = 2;  // renders whose touched blocks form each pixel's superset, [1, 8].
  ParameterBounds bounds;    // the feasible set.
  // The most Jacobian values (residuals × parameters over all cells) a build accepts, [1, 2^31 −
  // 1]: Ceres' block-sparse matrix indexes its values with an int. A larger problem, or one whose
  // Jacobian does not fit into the available memory, is an error that names what to change.
  int64_t max_jacobian_values = std::numeric_limits<int>::max();

  bool Check(std::string* why) const;
};

// Measures of a built problem, for reports.
struct ProblemStats {
  int64_t residual_blocks = 0;
  int64_t pixels_without_parameters = 0;  // active pixels whose superset was empty (left out).
  int64_t parameter_blocks = 0;
  int64_t superset_entries = 0;  // Σ over residual blocks of the parameters in their superset.
  double build_seconds = 0.0;    // including the superset renders.
};

class ReconstructionProblem {
 public:
  // Renders the supersets with seeds derived from cache->seed(), builds the problem and leaves
  // the cache's seed as it was.
  static Status Build(RenderCache* cache, SceneParameters* params, const ProblemOptions& options,
                      std::unique_ptr<ReconstructionProblem>* out);

  ceres::Problem* problem() { return problem_.get(); }
  const ProblemStats& stats() const { return stats_; }
  // Σ of squared Jacobian entries (over the cache's current rows) that fall outside the
  // supersets, over the Σ of all squared entries: the Jacobian mass the frozen pattern drops.
  double DroppedJacobianFraction(const RenderCache& cache) const;

 private:
  struct Residual {
    int view, level, pixel;
    const PyramidPixelCost* cost;  // owned by problem_.
  };
  std::unique_ptr<ceres::Problem> problem_;
  std::vector<Residual> residuals_;
  ProblemStats stats_;
};

// Copies into every texel with i + j = r (which no surface point samples) the value of its
// in-face neighbour (i, j − 1), or (i − 1, j) when j = 0.
void FillUnsampledTexels(MeshColors* colors);

}  // namespace sft

#endif  // SFT_OPTIM_PROBLEM_H_
