// Turns a dataset's cameras, lights and views into the renderer's per-view setups: camera-attached
// point lights are moved to the world frame (world position = C + Rᵀ·offset, C the camera centre),
// environment probes are loaded once and shared by the views that use them.
#ifndef SFT_IO_SCENE_SETUP_H_
#define SFT_IO_SCENE_SETUP_H_

#include <memory>
#include <vector>

#include "src/core/status.h"
#include "src/io/dataset.h"
#include "src/render/environment.h"
#include "src/render/render.h"

namespace sft {

struct DatasetViews {
  std::vector<std::unique_ptr<EnvironmentMap>> environments;  // owned; indexed like lights.
  std::vector<ViewSetup> views;                               // point into `environments`.
};

// A view may use at most one environment light (more would need summed maps). Errors name the
// view and light.
Status MakeDatasetViews(const Dataset& dataset, DatasetViews* out);

// The view indices to work on: `requested` when non-empty (each checked against [0, num_views);
// the error names the offending index), else all views.
Status SelectViews(const std::vector<int>& requested, int num_views, std::vector<int>* selected);

}  // namespace sft

#endif  // SFT_IO_SCENE_SETUP_H_
