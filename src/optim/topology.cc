#include "src/optim/topology.h"

#include <algorithm>
#include <cmath>

#include "src/geometry/mesh_colors_resample.h"
#include "src/init/initial_mesh.h"
#include "src/init/remesh.h"
#include "src/init/resample.h"
#include "src/init/texel_transfer.h"

namespace sft {
namespace {

using json = nlohmann::json;

Eigen::Vector3d Centroid(const TriMesh& mesh) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (auto vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    sum += Eigen::Vector3d(p[0], p[1], p[2]);
  }
  return mesh.n_vertices() > 0 ? Eigen::Vector3d(sum / mesh.n_vertices()) : sum;
}

Status Remesh(const TopologyOptions& options, double edge_length, TriMesh* mesh, json* record) {
  RemeshOptions remesh;
  if (!RemeshMethodFromName(options.remesh, &remesh.method)) {
    return Status::Error("remesh: unknown method " + options.remesh);
  }
  remesh.target_edge_length = edge_length;
  remesh.max_faces = options.max_faces;
  TriMesh out;
  RemeshReport report;
  SFT_RETURN_IF_ERROR(Remesh(*mesh, remesh, &out, &report));
  *mesh = std::move(out);
  *record = {{"kind", "remesh"},
             {"method", options.remesh},
             {"target_edge_length", edge_length},
             {"faces_before", report.faces_before},
             {"faces_after", report.faces_after},
             {"mean_edge_length_after", report.mean_edge_length_after},
             {"non_manifold_vertices_split", report.non_manifold_vertices_split}};
  return Status::Ok();
}

Status Resample(const TopologyOptions& options, const Dataset& dataset,
                const std::vector<int>& view_indices, const std::vector<int>& held_out,
                int image_scale_log2, TriMesh* mesh, json* record) {
  DatasetViews views;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &views));
  std::vector<ViewSetup> setups;
  for (int v : view_indices) {
    setups.push_back(views.views[v]);
    setups.back().camera = DownscaledCamera(setups.back().camera, image_scale_log2);
  }
  // The visual hull of every view but the held-out ones bounds the Poisson surface when each of
  // them has a mask.
  std::vector<int> hull_views;
  bool all_masks = true;
  for (int v = 0; v < static_cast<int>(dataset.views.size()); ++v) {
    if (std::find(held_out.begin(), held_out.end(), v) != held_out.end()) continue;
    hull_views.push_back(v);
    all_masks = all_masks && !dataset.views[v].mask.empty();
  }
  std::vector<CarvingView> hull;
  if (all_masks) SFT_RETURN_IF_ERROR(LoadCarvingViews(dataset, hull_views, &hull));
  ResampleOptions resample;
  resample.faces = std::min<int>(options.max_faces, static_cast<int>(mesh->n_faces()));
  TriMesh out;
  ResampleReport report;
  SFT_RETURN_IF_ERROR(
      ResampleSurface(*mesh, setups, all_masks ? &hull : nullptr, resample, &out, &report));
  *record = {{"kind", "resample"},
             {"faces_before", mesh->n_faces()},
             {"faces_after", out.n_faces()},
             {"points", report.points},
             {"trimmed_to_hull", all_masks}};
  *mesh = std::move(out);
  return Status::Ok();
}

}  // namespace

bool TopologyOptions::Check(std::string* why) const {
  RemeshMethod method;
  if (remesh != "none" && !RemeshMethodFromName(remesh, &method)) {
    *why = "remesh: expected none, adaptive or isotropic";
    return false;
  }
  if (!(remesh_edge_pixels > 0.0 && remesh_edge_pixels <= 64.0)) {
    *why = "remesh_edge_pixels: must be in (0, 64]";
    return false;
  }
  if (!(resample_fold_fraction >= 0.0 && resample_fold_fraction <= 1.0)) {
    *why = "resample_fold_fraction: must be in [0, 1]";
    return false;
  }
  if (max_faces < 100 || max_faces > 5000000) {
    *why = "max_faces: must be in [100, 5000000]";
    return false;
  }
  return true;
}

double PixelFootprint(const TriMesh& mesh, const Dataset& dataset,
                      const std::vector<int>& view_indices, int image_scale_log2) {
  const Eigen::Vector3d centroid = Centroid(mesh);
  double sum = 0.0;
  int count = 0;
  for (int v : view_indices) {
    const ViewSpec& view = dataset.views[v];
    const Camera camera = DownscaledCamera(dataset.cameras[view.camera], image_scale_log2);
    const Eigen::Vector3d centre = view.cam_from_world.Inverse().translation;
    const Eigen::Vector2d focal = camera.Focal();
    sum += (centroid - centre).norm() * 2.0 / (focal.x() + focal.y());
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

int ResolveTexelResolution(int requested, int current, const TriMesh& mesh, const Dataset& dataset,
                           const std::vector<int>& view_indices, int image_scale_log2) {
  if (requested > 0) return requested;
  if (requested != kTexelResolutionAuto) return current;
  double sum = 0.0;
  int64_t count = 0;
  for (const auto& edge : mesh.edges()) {
    sum += mesh.calc_edge_length(edge);
    ++count;
  }
  const double footprint = PixelFootprint(mesh, dataset, view_indices, image_scale_log2);
  if (count == 0 || !(footprint > 0.0)) return 1;
  const double r = std::round(sum / count / footprint);
  return static_cast<int>(std::clamp(r, 1.0, static_cast<double>(kMaxAutoTexelResolution)));
}

Status ApplyTopologyChange(TopologyChange change, const TopologyOptions& options,
                           const Dataset& dataset, const std::vector<int>& view_indices,
                           int image_scale_log2, int texel_resolution, TriMesh* mesh,
                           Material* material, json* record, const std::vector<int>& held_out) {
  const TriMesh old_mesh = *mesh;
  if (change == TopologyChange::kRemesh) {
    const double edge =
        options.remesh_edge_pixels * PixelFootprint(*mesh, dataset, view_indices, image_scale_log2);
    SFT_RETURN_IF_ERROR(Remesh(options, edge, mesh, record));
  } else {
    SFT_RETURN_IF_ERROR(
        Resample(options, dataset, view_indices, held_out, image_scale_log2, mesh, record));
  }
  const int resolution = ResolveTexelResolution(texel_resolution, material->albedo.resolution(),
                                                *mesh, dataset, view_indices, image_scale_log2);
  Material transferred;
  SFT_RETURN_IF_ERROR(TransferMaterial(old_mesh, *material, *mesh, resolution, &transferred));
  *material = std::move(transferred);
  (*record)["texel_resolution"] = resolution;
  return Status::Ok();
}

Material ResampleMaterial(const Material& material, int texel_resolution) {
  Material out = material;
  out.albedo = ResampleMeshColors(material.albedo, texel_resolution);
  out.roughness = ResampleMeshColors(material.roughness, texel_resolution);
  return out;
}

}  // namespace sft
