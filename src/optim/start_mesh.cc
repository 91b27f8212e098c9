#include "src/optim/start_mesh.h"

#include <algorithm>
#include <vector>

#include "src/core/file_util.h"
#include "src/init/stereo_mesh.h"

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
                     const std::vector<int>& excluded_views, std::string* summary) {
  if (choice.kind != StartKind::kCarved) {
    SFT_RETURN_IF_ERROR(ReadMesh(choice.path, mesh));
    if (summary != nullptr) {
      *summary = "start: " + choice.path + " (" + choice.Describe() + ", " +
                 std::to_string(mesh->n_faces()) + " faces)";
    }
    return Status::Ok();
  }
  // Held-out masks are not even read: neither their content nor their absence may change the
  // start.
  std::vector<int> carved;
  for (int v = 0; v < static_cast<int>(dataset.views.size()); ++v) {
    if (std::find(excluded_views.begin(), excluded_views.end(), v) == excluded_views.end()) {
      carved.push_back(v);
    }
  }
  std::vector<CarvingView> views;
  SFT_RETURN_IF_ERROR(LoadCarvingViews(dataset, carved, &views));
  InitialMeshOptions options = carve;
  UseDatasetSupport(dataset, &options.hull);
  InitialMeshReport report;
  SFT_RETURN_IF_ERROR(MakeInitialMesh(views, options, /*sparse_points=*/{}, mesh, &report));
  std::string how = "the hull carved from " + std::to_string(carved.size()) + " views' masks";
  if (options.stereo) {
    StereoMeshReport stereo;
    SFT_RETURN_IF_ERROR(MakeStereoMesh(dataset, carved, views, *mesh, options, mesh, &stereo));
    how += ", rebuilt from stereo (" + std::to_string(stereo.stereo.points) + " points from " +
           std::to_string(stereo.stereo.pairs) + " view pairs)";
  }
  if (summary != nullptr) {
    *summary = "start: " + how + ", " + std::to_string(mesh->n_faces()) + " faces";
  }
  return Status::Ok();
}

}  // namespace sft
