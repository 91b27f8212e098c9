// Turns a dataset's cameras, lights and views into the renderer's per-view setups: camera-attached
// point lights are moved to the world frame (world position = C + Rᵀ·offset, C the camera centre),
// environment probes are loaded once and shared by the views that use them (a camera-fixed
// environment gets one map per view, turned with the camera).
#ifndef SFT_IO_SCENE_SETUP_H_
#define SFT_IO_SCENE_SETUP_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/io/dataset.h"
#include "src/render/environment.h"
#include "src/render/render.h"

namespace sft {

struct DatasetViews {
  // World-fixed environment maps, owned; indexed like lights (null for other lights).
  std::vector<std::unique_ptr<EnvironmentMap>> environments;
  // Camera-fixed environment maps, owned; indexed like views (null when the view's environment,
  // if any, is world-fixed): one per view, turned with its camera.
  std::vector<std::unique_ptr<EnvironmentMap>> view_environments;
  std::vector<ViewSetup> views;  // point into `environments` and `view_environments`.
};

// The rotation that takes `light`'s env directions to the world frame in the view whose pose is
// `cam_from_world`: light.world_from_env for a world-fixed environment; for a camera-fixed one
// (light.frame kCamera), whose world_from_env takes env directions to the camera frame, the
// camera's world_from_cam rotation times it.
Eigen::Matrix3d ViewWorldFromEnv(const LightSpec& light, const Rigid3d& cam_from_world);

// What rendering one view holds at once, in RGBA float images of the camera's size: the render,
// the target read back for comparison, and the report's difference and thumbnails (about one
// more). Derivative rows come on top of this.
constexpr uint64_t kViewImageCopies = 3;

// Bytes that rendering one view of `camera` needs (kViewImageCopies RGBA float images).
uint64_t EstimateViewRenderBytes(const Camera& camera);

// Refuses datasets whose largest view cannot be rendered in the memory available
// (CheckMemoryBudget): the error names the camera, the estimate and the memory available.
Status CheckViewsFitInMemory(const Dataset& dataset);

// Checks that the views fit in memory (CheckViewsFitInMemory) before allocating anything. A view
// may use at most one environment light (more would need summed maps). Errors name the view and
// light, or the camera.
Status MakeDatasetViews(const Dataset& dataset, DatasetViews* out);

// The view indices to work on: `requested` when non-empty (each checked against [0, num_views);
// the error names the offending index), else all views.
Status SelectViews(const std::vector<int>& requested, int num_views, std::vector<int>* selected);

// The shading a dataset's images call for: ground_truth.shading when the dataset records it (a
// synthetic dataset says how it was rendered), else smooth (photographs of real surfaces).
Shading DatasetShading(const Dataset& dataset);
// A "shading" option's value: "auto" (DatasetShading), "flat" or "smooth". False for others.
bool ResolveShading(const std::string& name, const Dataset& dataset, Shading* shading);

}  // namespace sft

#endif  // SFT_IO_SCENE_SETUP_H_
