#include "src/optim/start_mesh.h"

#include <algorithm>
#include <vector>

#include "src/core/file_util.h"

namespace sft {

std::string StartChoice::Describe() const {
  switch (kind) {
    case StartKind::kGiven:
      return "init";
    case StartKind::kDatasetInitialMesh:
      return "dataset initial_mesh";
    case StartKind::kCarved:
      return "carved hull";
  }
  return "?";
}

Status ChooseStart(const Dataset& dataset, const std::string& init_path, StartChoice* choice) {
  if (!init_path.empty()) {
    *choice = {StartKind::kGiven, init_path};
    return Status::Ok();
  }
  if (!dataset.initial_mesh.empty()) {
    *choice = {StartKind::kDatasetInitialMesh, JoinPath(dataset.root, dataset.initial_mesh)};
    return Status::Ok();
  }
  for (size_t v = 0; v < dataset.views.size(); ++v) {
    if (dataset.views[v].mask.empty()) {
      return Status::Error(dataset.root + ": views[" + std::to_string(v) +
                           "] has no mask, the dataset names no initial_mesh, and no --init was " +
                           "given: give --init MESH, or masks to carve a hull from");
    }
  }
  *choice = {StartKind::kCarved, ""};
  return Status::Ok();
}

Status LoadStartMesh(const Dataset& dataset, const StartChoice& choice,
                     const InitialMeshOptions& carve, TriMesh* mesh,
                     const std::vector<int>& excluded_views) {
  if (choice.kind != StartKind::kCarved) return ReadMesh(choice.path, mesh);
  std::vector<CarvingView> all;
  SFT_RETURN_IF_ERROR(LoadCarvingViews(dataset, &all));
  std::vector<CarvingView> views;  // LoadCarvingViews gives one per dataset view, in order.
  for (size_t v = 0; v < all.size(); ++v) {
    if (std::find(excluded_views.begin(), excluded_views.end(), static_cast<int>(v)) ==
        excluded_views.end()) {
      views.push_back(std::move(all[v]));
    }
  }
  InitialMeshReport report;
  return MakeInitialMesh(views, carve, /*sparse_points=*/{}, mesh, &report);
}

}  // namespace sft
