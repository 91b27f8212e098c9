// A worker rank's side of the render cache (src/optim/mpi_views.h, ServeViews): the RenderScene,
// the dataset's view setups and the fitted environment of the RenderStates rank 0 sends, brought
// to each new state as the render cache brings its own (RenderCache::UpdateScene), so that a job
// renders here exactly as it would on rank 0.
#ifndef SFT_OPTIM_STATE_RENDERER_H_
#define SFT_OPTIM_STATE_RENDERER_H_

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/optim/view_jobs.h"
#include "src/render/environment.h"
#include "src/render/scene.h"

namespace sft {

class StateRenderer {
 public:
  // `dataset`: this rank's copy of the fitted dataset, as read from rank 0's path (without the
  // fitted environment rank 0 adds to a dataset of unknown lighting).
  static Status Create(const Dataset& dataset, std::unique_ptr<StateRenderer>* renderer);

  // Brings the scene (rebuilt for a new scene id, then moved to the state's positions) and the
  // fitted environment to `state`. An error means the ranks disagree about the dataset.
  Status Update(const RenderState& state);
  // Renders `job` at `state`, the state of the last Update.
  void Render(const RenderState& state, const ViewJob& job, ViewResult* result) const;

 private:
  StateRenderer() = default;
  // The fitted environment of `state` (layout.num_environment_texels > 0): the first one adds
  // the light to the dataset as rank 0 did (AddFittedEnvironment), every new set of texels
  // rebuilds its map.
  Status UpdateEnvironment(const RenderState& state);

  Dataset dataset_;
  DatasetViews views_;
  std::unique_ptr<RenderScene> scene_;
  int64_t scene_id_ = -1;
  std::vector<Eigen::Vector3d> scene_positions_;
  FittedEnvironmentMaps fitted_environment_;     // the maps of the state's environment texels.
  RotatedEnvironmentMaps rotated_environments_;  // given probes turned by the state's rotations.
};

}  // namespace sft

#endif  // SFT_OPTIM_STATE_RENDERER_H_
