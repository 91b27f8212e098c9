// Where a reconstruction starts (docs/reconstruct.md, "Start points"): the mesh given with
// --init; else the dataset's own `initial_mesh` (scene.json, relative to the dataset); else a
// visual hull carved from the views' masks with `sft init`'s code (src/init/initial_mesh.h).
// The choice is recorded in state.json and metrics.json ("start").
#ifndef SFT_OPTIM_START_MESH_H_
#define SFT_OPTIM_START_MESH_H_

#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/mesh.h"
#include "src/init/initial_mesh.h"
#include "src/io/dataset.h"

namespace sft {

// The material a run starts from when none is given (grey albedo 0.5, roughness 0.5, constant).
inline constexpr char kInitialMaterial[] = R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5})";

enum class StartKind { kGiven, kDatasetInitialMesh, kCarved };

struct StartChoice {
  StartKind kind = StartKind::kGiven;
  std::string path;  // the mesh file (kGiven, kDatasetInitialMesh); empty when carved.
  // "init", "dataset initial_mesh" or "carved hull", for the record.
  std::string Describe() const;
};

// Decides the start without loading anything: `init_path` when non-empty, else the dataset's
// initial mesh, else carving. Carving needs a mask for every view; without one the error says
// which view lacks it and what to pass instead.
Status ChooseStart(const Dataset& dataset, const std::string& init_path, StartChoice* choice);

// Loads (or carves, with `carve` options) the start mesh. Carving neither reads nor uses the masks
// of `excluded_views` (held-out views, src/optim/holdout.h). *summary (when given) gets one line
// for the console: the start's source, how a carved start was made (views, stereo points and
// pairs) and its face count.
Status LoadStartMesh(const Dataset& dataset, const StartChoice& choice,
                     const InitialMeshOptions& carve, TriMesh* mesh,
                     const std::vector<int>& excluded_views = {}, std::string* summary = nullptr);

}  // namespace sft

#endif  // SFT_OPTIM_START_MESH_H_
