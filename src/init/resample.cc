#include "src/init/resample.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>

#include "src/init/poisson_grid.h"
#include "src/init/view_samples.h"
#include "src/render/scene.h"

namespace sft {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The grid over the samples' bounding box grown by the margin; *h grows when the longest side
// would exceed kMaxGridSide voxels.
VoxelBox MakeGridBox(const std::vector<OrientedPoint>& samples, double* h) {
  Eigen::Vector3d lo = samples[0].position, hi = samples[0].position;
  for (const OrientedPoint& s : samples) {
    lo = lo.cwiseMin(s.position);
    hi = hi.cwiseMax(s.position);
  }
  const double margin_fraction = kGridMarginFraction * (hi - lo).norm();
  const auto side = [&](double voxel) {
    return (hi - lo).maxCoeff() + 2.0 * std::max(margin_fraction, kGridMarginVoxels * voxel);
  };
  if (side(*h) > kMaxGridSide * *h) {
    // extent + 2·margin_fraction + 2·kGridMarginVoxels·h <= kMaxGridSide·h suffices.
    *h = ((hi - lo).maxCoeff() + 2.0 * margin_fraction) / (kMaxGridSide - 2 * kGridMarginVoxels);
  }
  const double margin = std::max(margin_fraction, kGridMarginVoxels * *h);
  VoxelBox box;
  box.voxel_size = *h;
  for (int a = 0; a < 3; ++a) {
    box.dims[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo[a] + 2 * margin) / *h)));
    // Centre the grid on the samples' box.
    box.lo[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * box.dims[a] * *h;
  }
  return box;
}

// Carves the hull of `views` over about `box` and replaces the field by max(field, hull).
Status TrimToHull(const std::vector<CarvingView>& views, const ResampleOptions& options,
                  const VoxelBox& box, std::vector<float>* field, ResampleReport* report) {
  VisualHullOptions hull_options;
  hull_options.resolution = std::clamp(box.dims.maxCoeff(), VisualHullOptions::kMinResolution,
                                       VisualHullOptions::kMaxResolution);
  hull_options.min_view_fraction = options.hull_min_view_fraction;
  const Eigen::Vector3d hi = box.lo + box.voxel_size * box.dims.cast<double>();
  hull_options.bounds = box.lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).maxCoeff();
  std::string why;
  if (!hull_options.Check(&why)) return Status::Error("visual hull: " + why);
  VisualHull hull;
  SFT_RETURN_IF_ERROR(CarveVisualHull(views, hull_options, nullptr, &hull).Prefixed("visual hull"));
  std::atomic<int64_t> trimmed{0};
  const Eigen::Vector3i& dims = box.dims;
  tbb::parallel_for(0, dims.z(), [&](int k) {
    int64_t slice_trimmed = 0;
    for (int j = 0; j < dims.y(); ++j) {
      for (int i = 0; i < dims.x(); ++i) {
        float& value = (*field)[(static_cast<size_t>(k) * dims.y() + j) * dims.x() + i];
        const float outside = static_cast<float>(SampleHull(hull, box.Centre(i, j, k)));
        if (value < 0 && outside >= 0) ++slice_trimmed;
        value = std::max(value, outside);
      }
    }
    trimmed += slice_trimmed;
  });
  report->hull_views = static_cast<int>(views.size());
  report->trimmed_voxels = trimmed;
  return Status::Ok();
}

// Extraction of the field's zero level set and clean-up to one closed manifold.
Status ExtractSurface(const VoxelBox& box, double band, std::vector<float> field, TriMesh* mesh,
                      ResampleReport* report) {
  VisualHull level_set;
  level_set.box = box;
  level_set.band = band;
  level_set.field = std::move(field);
  if (std::none_of(level_set.field.begin(), level_set.field.end(), [](float v) { return v < 0; })) {
    return Status::Error("the reconstructed solid is empty (no voxel inside it" +
                         std::string(report->hull_views > 0 ? " and the visual hull)" : ")"));
  }
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> triangles;
  SFT_RETURN_IF_ERROR(ExtractHullSurface(level_set, &points, &triangles));
  report->poisson_vertices = static_cast<int>(points.size());
  report->poisson_faces = static_cast<int>(triangles.size());
  SFT_RETURN_IF_ERROR(BuildClosedSurface(points, triangles, mesh, &report->cleanup));
  report->components_removed = std::max(0, report->cleanup.components - 1);
  return Status::Ok();
}

// Steps 2-5 of resample.h on given samples.
Status PoissonFromSamples(std::vector<OrientedPoint> samples, double h, int target_faces,
                          const std::vector<CarvingView>* hull, const ResampleOptions& options,
                          TriMesh* out, ResampleReport* report) {
  auto stage = std::chrono::steady_clock::now();
  // The grid first: it may coarsen h, which the thinning then uses.
  const VoxelBox box = MakeGridBox(samples, &h);
  samples = ThinSamples(samples, h);
  report->points = static_cast<int>(samples.size());
  report->spacing = h;
  report->grid = box.dims;
  report->cast_seconds += SecondsSince(stage);

  stage = std::chrono::steady_clock::now();
  const double band = kBandVoxels * h;
  std::vector<float> field;
  PoissonGridReport poisson;
  SFT_RETURN_IF_ERROR(
      EvaluatePoissonGrid(samples, box, band, &field, &poisson).Prefixed("Poisson reconstruction"));
  report->triangulation_vertices = poisson.triangulation_vertices;
  report->solve_seconds = poisson.solve_seconds;
  report->poisson_seconds = SecondsSince(stage);

  stage = std::chrono::steady_clock::now();
  if (options.trim_to_hull && hull != nullptr && !hull->empty()) {
    SFT_RETURN_IF_ERROR(TrimToHull(*hull, options, box, &field, report));
  }
  report->trim_seconds = SecondsSince(stage);

  stage = std::chrono::steady_clock::now();
  TriMesh result;
  SFT_RETURN_IF_ERROR(ExtractSurface(box, band, std::move(field), &result, report));
  report->extract_seconds = SecondsSince(stage);

  stage = std::chrono::steady_clock::now();
  DecimateMesh(target_faces, &result);
  report->decimate_seconds = SecondsSince(stage);
  report->vertices_after = static_cast<int>(result.n_vertices());
  report->faces_after = static_cast<int>(result.n_faces());
  *out = std::move(result);
  return Status::Ok();
}

Status Resample(const TriMesh& mesh, const std::vector<ViewSetup>& views,
                const std::vector<CarvingView>* hull, const ResampleOptions& options, TriMesh* out,
                ResampleReport* report) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  if (faces.empty()) return Status::Error("the mesh has no faces");
  if (views.empty()) return Status::Error("no views to cast rays from");
  for (size_t v = 0; v < views.size(); ++v) {
    std::string why;
    if (!views[v].camera.Check(&why)) {
      return Status::Error("views[" + std::to_string(v) + "]: camera: " + why);
    }
  }
  const int target_faces = options.faces > 0 ? options.faces : static_cast<int>(faces.size());
  const double area = SurfaceArea(positions, faces);
  double h = options.spacing_factor * EquilateralEdgeLength(area, target_faces);
  if (!(h > 0) || !std::isfinite(h)) return Status::Error("the mesh has no area");

  auto stage = std::chrono::steady_clock::now();
  std::vector<OrientedPoint> samples;
  {
    const RenderScene scene(positions, faces);
    ViewSamplesReport cast;
    CastViewSamples(scene, views, options.pixel_stride, &samples, &cast);
    report->rays = cast.rays;
    report->hits = cast.hits;
    report->back_face_hits = cast.back_face_hits;
    report->views_with_hits = cast.views_with_hits;
  }
  if (samples.empty()) {
    return Status::Error("no view sees the mesh: none of the " + std::to_string(report->rays) +
                         " rays from " + std::to_string(views.size()) +
                         " views hits it (check the cameras and the mesh's position)");
  }
  report->cast_seconds = SecondsSince(stage);
  SFT_RETURN_IF_ERROR(
      PoissonFromSamples(std::move(samples), h, target_faces, hull, options, out, report));
  report->total_seconds = SecondsSince(start);
  return Status::Ok();
}

}  // namespace

double EquilateralEdgeLength(double area, int faces) {
  return std::sqrt(4.0 * area / (std::sqrt(3.0) * faces));
}

bool ResampleOptions::Check(std::string* why) const {
  if (pixel_stride < 1 || pixel_stride > kMaxPixelStride) {
    *why = "pixel_stride: must be in [1, " + std::to_string(kMaxPixelStride) + "], got " +
           std::to_string(pixel_stride);
    return false;
  }
  if (faces != 0 && (faces < kMinFaces || faces > kMaxFaces)) {
    *why = "faces: must be 0 (keep the input's count) or in [" + std::to_string(kMinFaces) + ", " +
           std::to_string(kMaxFaces) + "], got " + std::to_string(faces);
    return false;
  }
  if (!(spacing_factor >= kMinSpacingFactor && spacing_factor <= kMaxSpacingFactor)) {
    *why = "spacing_factor: must be in [" + std::to_string(kMinSpacingFactor) + ", " +
           std::to_string(kMaxSpacingFactor) + "], got " + std::to_string(spacing_factor);
    return false;
  }
  if (!(hull_min_view_fraction > 0 && hull_min_view_fraction <= 1)) {
    *why =
        "hull_min_view_fraction: must be in (0, 1], got " + std::to_string(hull_min_view_fraction);
    return false;
  }
  return true;
}

Status ResampleSurface(const TriMesh& mesh, const std::vector<ViewSetup>& views,
                       const std::vector<CarvingView>* hull, const ResampleOptions& options,
                       TriMesh* out, ResampleReport* report) {
  *report = ResampleReport();
  std::string why;
  if (!options.Check(&why)) return Status::Error("resample options: " + why);
  try {
    return Resample(mesh, views, hull, options, out, report).Prefixed("resampling");
  } catch (const std::exception& e) {
    return Status::Error(std::string("resampling failed: ") + e.what());
  }
}

Status SurfaceFromSamples(std::vector<OrientedPoint> samples, double spacing,
                          const std::vector<CarvingView>* hull, const ResampleOptions& options,
                          TriMesh* out, ResampleReport* report) {
  *report = ResampleReport();
  std::string why;
  if (!options.Check(&why)) return Status::Error("resample options: " + why);
  if (options.faces <= 0) return Status::Error("resample options: faces: must be set (> 0)");
  if (!(spacing > 0) || !std::isfinite(spacing)) {
    return Status::Error("the sample spacing must be positive, got " + std::to_string(spacing));
  }
  if (samples.size() < 4) {
    return Status::Error("too few surface samples (" + std::to_string(samples.size()) + ")");
  }
  const auto start = std::chrono::steady_clock::now();
  try {
    SFT_RETURN_IF_ERROR(
        PoissonFromSamples(std::move(samples), spacing, options.faces, hull, options, out, report)
            .Prefixed("surface from samples"));
  } catch (const std::exception& e) {
    return Status::Error(std::string("surface from samples failed: ") + e.what());
  }
  report->total_seconds = SecondsSince(start);
  return Status::Ok();
}

}  // namespace sft
