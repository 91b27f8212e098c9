#include "src/init/stereo_mesh.h"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>

#include "src/core/file_util.h"

namespace sft {

Status LoadStereoViews(const Dataset& dataset, const std::vector<int>& indices,
                       std::vector<StereoView>* views) {
  const int n = static_cast<int>(indices.size());
  for (int v : indices) {
    if (v < 0 || v >= static_cast<int>(dataset.views.size())) {
      return Status::Error(JoinPath(dataset.root, "scene.json") + ": no view " + std::to_string(v));
    }
  }
  std::vector<StereoView> result(n);
  std::vector<Status> statuses(n);
  tbb::parallel_for(0, n, [&](int i) {
    const int v = indices[i];
    const ViewSpec& spec = dataset.views[v];
    StereoView& view = result[i];
    view.name = "views[" + std::to_string(v) + "] (" + JoinPath(dataset.root, spec.image) + ")";
    view.camera = dataset.cameras[spec.camera];
    view.cam_from_world = spec.cam_from_world;
    statuses[i] = LoadViewImage(dataset, v, &view.image);
    if (statuses[i].ok() && !spec.mask.empty()) statuses[i] = LoadViewMask(dataset, v, &view.mask);
  });
  for (const Status& status : statuses) SFT_RETURN_IF_ERROR(status);
  *views = std::move(result);
  return Status::Ok();
}

Status MakeStereoMesh(const Dataset& dataset, const std::vector<int>& indices,
                      const std::vector<CarvingView>& hull_views, const TriMesh& hull_mesh,
                      const InitialMeshOptions& options, TriMesh* mesh, StereoMeshReport* report) {
  *report = StereoMeshReport();
  std::string why;
  if (!options.Check(&why)) return Status::Error("stereo mesh options: " + why);
  if (!options.stereo_options.Check(&why)) return Status::Error("stereo options: " + why);
  const auto start = std::chrono::steady_clock::now();
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(hull_mesh, &positions, &faces);
  if (faces.empty()) return Status::Error("stereo: the hull has no faces");
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : positions) box.extend(p);
  const double area = SurfaceArea(positions, faces);
  const double spacing = EquilateralEdgeLength(area, options.faces);

  std::vector<StereoView> views;
  SFT_RETURN_IF_ERROR(LoadStereoViews(dataset, indices, &views));
  report->load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<OrientedPoint> points;
  SFT_RETURN_IF_ERROR(
      ComputeStereoPoints(views, box, options.stereo_options, &points, &report->stereo));
  views.clear();
  if (points.empty()) {
    return Status::Error("stereo: no pixel kept a depth (" + std::to_string(report->stereo.pairs) +
                         " pairs matched); the views may "
                         "be too far apart (max_angle_deg) or the object without texture");
  }
  ResampleOptions surface;
  surface.faces = options.faces;
  surface.hull_min_view_fraction = options.hull.min_view_fraction;
  TriMesh result;
  SFT_RETURN_IF_ERROR(SurfaceFromSamples(std::move(points), spacing, &hull_views, surface, &result,
                                         &report->surface)
                          .Prefixed("stereo"));
  *mesh = std::move(result);
  report->total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace sft
