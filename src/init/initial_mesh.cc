#include "src/init/initial_mesh.h"

#include <tbb/parallel_for.h>

#include <chrono>

#include "src/core/file_util.h"
#include "src/core/progress.h"

namespace sft {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void CheckSparsePoints(const VisualHull& hull, const std::vector<Eigen::Vector3d>& points,
                       InitialMeshReport* report) {
  const double h = hull.box.voxel_size;
  const Eigen::Vector3d lo = hull.box.lo;
  const Eigen::Vector3d hi = lo + h * hull.box.dims.cast<double>();
  report->points = static_cast<int>(points.size());
  for (const Eigen::Vector3d& p : points) {
    const bool in_box = (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
    if (!in_box) {
      ++report->points_outside;
      ++report->points_outside_box;
      continue;
    }
    const double value = SampleHull(hull, p);
    if (value > h) ++report->points_outside;
    if (value < -kInsidePointVoxels * h) ++report->points_inside;
  }
}

}  // namespace

bool InitialMeshOptions::Check(std::string* why) const {
  if (!hull.Check(why)) return false;
  if (faces < kMinFaces || faces > kMaxFaces) {
    *why = "faces: must be in [" + std::to_string(kMinFaces) + ", " + std::to_string(kMaxFaces) +
           "], got " + std::to_string(faces);
    return false;
  }
  if (stereo && !stereo_options.Check(why)) {
    *why = "stereo." + *why;
    return false;
  }
  return true;
}

Status LoadCarvingViews(const Dataset& dataset, std::vector<CarvingView>* views) {
  std::vector<int> all(dataset.views.size());
  for (size_t v = 0; v < all.size(); ++v) all[v] = static_cast<int>(v);
  return LoadCarvingViews(dataset, all, views);
}

Status LoadCarvingViews(const Dataset& dataset, const std::vector<int>& indices,
                        std::vector<CarvingView>* views) {
  const std::string scene = JoinPath(dataset.root, "scene.json");
  if (dataset.views.empty()) return Status::Error(scene + ": the dataset has no views");
  const int n = static_cast<int>(indices.size());
  if (n == 0) return Status::Error(scene + ": no views to carve from");
  for (int v : indices) {
    if (v < 0 || v >= static_cast<int>(dataset.views.size())) {
      return Status::Error(scene + ": no view " + std::to_string(v) + " to carve from");
    }
    if (dataset.views[v].mask.empty()) {
      return Status::Error(scene + ": views[" + std::to_string(v) +
                           "] has no mask; sft init needs a mask for every view (8-bit PNG, > 127 "
                           "= object), and carving without them is not possible");
    }
  }
  std::vector<CarvingView> result(n);
  std::vector<Status> statuses(n);
  tbb::parallel_for(0, n, [&](int i) {
    const int v = indices[i];
    Image mask;
    statuses[i] = LoadViewMask(dataset, v, &mask);
    if (!statuses[i].ok()) return;
    const ViewSpec& spec = dataset.views[v];
    statuses[i] = MakeCarvingView(
        "views[" + std::to_string(v) + "] (" + JoinPath(dataset.root, spec.mask) + ")",
        dataset.cameras[spec.camera], spec.cam_from_world, mask, &result[i]);
  });
  for (const Status& status : statuses) SFT_RETURN_IF_ERROR(status);
  *views = std::move(result);
  return Status::Ok();
}

void UseDatasetSupport(const Dataset& dataset, VisualHullOptions* hull) {
  hull->has_support = dataset.has_support_plane;
  hull->support_normal = dataset.support_normal;
  hull->support_point = dataset.support_point;
}

Status MakeInitialMesh(const std::vector<CarvingView>& views, const InitialMeshOptions& options,
                       const std::vector<Eigen::Vector3d>& sparse_points, TriMesh* mesh,
                       InitialMeshReport* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  const auto start = std::chrono::steady_clock::now();
  *report = InitialMeshReport();
  VisualHull hull;
  {
    Progress progress("init", kCoarseResolution + options.hull.resolution, options.progress);
    const Status status = CarveVisualHull(views, options.hull, &progress, &hull);
    progress.Finish();
    SFT_RETURN_IF_ERROR(status);
  }
  report->carve_seconds = SecondsSince(start);
  report->box = hull.box;
  report->min_views = hull.min_views;
  report->outlier_views = options.hull.outlier_views;
  report->support = options.hull.has_support;
  report->support_contact = options.hull.has_support ? options.hull.support_contact : 0.0;
  report->inside_voxels = hull.inside_voxels;
  CheckSparsePoints(hull, sparse_points, report);

  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> triangles;
  SFT_RETURN_IF_ERROR(ExtractHullSurface(hull, &points, &triangles));
  report->extracted_triangles = static_cast<int>(triangles.size());
  hull = VisualHull();  // the field is no longer needed; free it before decimation.
  TriMesh result;
  SFT_RETURN_IF_ERROR(BuildClosedSurface(points, triangles, &result, &report->cleanup));
  report->extract_seconds = SecondsSince(start) - report->carve_seconds;
  DecimateMesh(options.faces, &result);
  report->decimate_seconds = SecondsSince(start) - report->carve_seconds - report->extract_seconds;
  if (!IsClosedManifold(result, &why)) return Status::Error("after decimation: " + why);
  report->faces = static_cast<int>(result.n_faces());
  report->vertices = static_cast<int>(result.n_vertices());
  report->total_seconds = SecondsSince(start);
  *mesh = std::move(result);
  return Status::Ok();
}

}  // namespace sft
