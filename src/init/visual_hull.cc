#include "src/init/visual_hull.h"

#include <glog/logging.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <opencv2/imgproc.hpp>

namespace sft {
namespace {

// Bilinear value of a row-major map at image coordinates (pixel centres at +0.5), clamped to the
// map's edge pixels.
float SampleMap(const std::vector<float>& map, int width, int height, const Eigen::Vector2d& px) {
  const double x = std::clamp(px.x() - 0.5, 0.0, width - 1.0);
  const double y = std::clamp(px.y() - 0.5, 0.0, height - 1.0);
  const int x0 = std::min(static_cast<int>(x), width - 1);
  const int y0 = std::min(static_cast<int>(y), height - 1);
  const int x1 = std::min(x0 + 1, width - 1);
  const int y1 = std::min(y0 + 1, height - 1);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const float* row0 = map.data() + static_cast<size_t>(y0) * width;
  const float* row1 = map.data() + static_cast<size_t>(y1) * width;
  const float top = row0[x0] + fx * (row0[x1] - row0[x0]);
  const float bottom = row1[x0] + fx * (row1[x1] - row1[x0]);
  return top + fy * (bottom - top);
}

// The field value at `p` (see the header): the (outliers+1)-th largest over the views that see p
// of the scaled distance (the maximum when outliers is 0), clamped to [-band, band]; +band when
// fewer than `min_views` views see p. Stops early once that value reaches +band (it cannot come
// down again).
float FieldAt(const std::vector<CarvingView>& views, const Eigen::Vector3d& p, double band,
              int min_views, int outliers) {
  // top[0] >= top[1] >= … >= top[outliers]: the largest values so far.
  std::array<double, VisualHullOptions::kMaxOutlierViews + 1> top;
  top.fill(-band);
  int seen = 0;
  for (const CarvingView& view : views) {
    const Eigen::Vector3d p_in_cam = view.cam_from_world * p;
    if (!(p_in_cam.z() > 1e-9)) continue;
    const Eigen::Vector2d normalized = p_in_cam.head<2>() / p_in_cam.z();
    if (normalized.norm() > view.max_radius) continue;
    const Eigen::Vector2d px = view.camera.ImageFromCam(p_in_cam);
    const Camera& camera = view.camera;
    if (!(px.x() >= 0 && px.y() >= 0 && px.x() <= camera.width && px.y() <= camera.height)) {
      continue;
    }
    ++seen;
    double d = SampleMap(view.distance, camera.width, camera.height, px) * p_in_cam.z() *
               view.world_per_pixel_at_unit_depth;
    for (int i = 0; i <= outliers && d > top[outliers]; ++i) {
      if (d > top[i]) std::swap(d, top[i]);
    }
    if (top[outliers] >= band) return static_cast<float>(band);
  }
  if (seen < min_views) return static_cast<float>(band);
  return static_cast<float>(std::clamp(top[outliers], -band, band));
}

// FieldAt with the support (see the header): the union with the contact band's extrusion, then
// the intersection with the half-space above the plane, clamped to [-band, band].
float SupportedFieldAt(const std::vector<CarvingView>& views, const Eigen::Vector3d& p, double band,
                       int min_views, const VisualHullOptions& options) {
  const int outliers = options.outlier_views;
  float value = FieldAt(views, p, band, min_views, outliers);
  if (!options.has_support) return value;
  const double height = options.support_normal.dot(p - options.support_point);
  if (height >= 0 && height < options.support_contact) {
    const Eigen::Vector3d top = p + (options.support_contact - height) * options.support_normal;
    value = std::min(value, FieldAt(views, top, band, min_views, outliers));
  }
  return static_cast<float>(std::clamp(std::max<double>(value, -height), -band, band));
}

// Evaluates the field over `box` in parallel over z slices, advancing `progress` once per slice.
std::vector<float> EvaluateField(const std::vector<CarvingView>& views, const VoxelBox& box,
                                 double band, int min_views, const VisualHullOptions& options,
                                 Progress* progress) {
  const int nx = box.dims.x(), ny = box.dims.y(), nz = box.dims.z();
  std::vector<float> field(static_cast<size_t>(box.NumVoxels()));
  tbb::parallel_for(tbb::blocked_range<int>(0, nz, 1), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      for (int j = 0; j < ny; ++j) {
        float* row = field.data() + (static_cast<size_t>(k) * ny + j) * nx;
        for (int i = 0; i < nx; ++i)
          row[i] = SupportedFieldAt(views, box.Centre(i, j, k), band, min_views, options);
      }
      if (progress != nullptr) progress->Advance();
    }
  });
  return field;
}

// The carving box from the coarse pass (see the header); false when no coarse voxel may touch
// the hull.
bool FindCarvingBox(const std::vector<CarvingView>& views, const VisualHullOptions& options,
                    int min_views, Progress* progress, VoxelBox* box) {
  VoxelBox coarse;
  coarse.voxel_size = 2.0 * options.bounds / kCoarseResolution;
  coarse.lo = Eigen::Vector3d::Constant(-options.bounds);
  coarse.dims = Eigen::Vector3i::Constant(kCoarseResolution);
  const double band = kBandVoxels * coarse.voxel_size;
  const std::vector<float> field = EvaluateField(views, coarse, band, min_views, options, progress);
  const double touch = 0.5 * std::sqrt(3.0) * coarse.voxel_size;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  size_t index = 0;
  for (int k = 0; k < kCoarseResolution; ++k) {
    for (int j = 0; j < kCoarseResolution; ++j) {
      for (int i = 0; i < kCoarseResolution; ++i, ++index) {
        if (field[index] >= touch) continue;
        const Eigen::Vector3d c = coarse.Centre(i, j, k);
        lo = lo.cwiseMin(c);
        hi = hi.cwiseMax(c);
      }
    }
  }
  if (!(lo.x() <= hi.x())) return false;
  const double grow = 1.5 * coarse.voxel_size;  // half a voxel to its faces, plus one voxel.
  lo = (lo.array() - grow).max(-options.bounds).matrix();
  hi = (hi.array() + grow).min(options.bounds).matrix();
  const Eigen::Vector3d extent = hi - lo;
  box->voxel_size = extent.maxCoeff() / options.resolution;
  for (int a = 0; a < 3; ++a) {
    box->dims[a] = std::clamp(static_cast<int>(std::ceil(extent[a] / box->voxel_size - 1e-9)), 1,
                              options.resolution);
  }
  // Centre the grid on the box (its last voxel may stick out by less than one voxel).
  box->lo = 0.5 * (lo + hi) - 0.5 * box->voxel_size * box->dims.cast<double>();
  return true;
}

}  // namespace

bool VisualHullOptions::Check(std::string* why) const {
  if (resolution < kMinResolution || resolution > kMaxResolution) {
    *why = "resolution: must be in [" + std::to_string(kMinResolution) + ", " +
           std::to_string(kMaxResolution) + "], got " + std::to_string(resolution);
    return false;
  }
  if (!(min_view_fraction > 0 && min_view_fraction <= 1)) {
    *why = "min_view_fraction: must be in (0, 1]";
    return false;
  }
  if (!(bounds > 0 && bounds < 1e6)) {
    *why = "bounds: must be in (0, 1e6)";
    return false;
  }
  if (outlier_views < 0 || outlier_views > kMaxOutlierViews) {
    *why = "outlier_views: must be in [0, " + std::to_string(kMaxOutlierViews) + "], got " +
           std::to_string(outlier_views);
    return false;
  }
  if (has_support && !(std::abs(support_normal.norm() - 1) < 1e-6 && support_point.allFinite())) {
    *why = "support: the normal must be a unit vector and the point finite";
    return false;
  }
  if (!(support_contact >= 0 && support_contact <= bounds)) {
    *why = "support_contact: must be in [0, " + std::to_string(bounds) + "] (the carved box's " +
           "half side), got " + std::to_string(support_contact);
    return false;
  }
  return true;
}

Status MakeCarvingView(const std::string& name, const Camera& camera, const Rigid3d& cam_from_world,
                       const Image& mask, CarvingView* view) {
  CHECK_EQ(mask.channels, 1);
  CHECK_EQ(mask.width, camera.width);
  CHECK_EQ(mask.height, camera.height);
  cv::Mat inside(mask.height, mask.width, CV_8U);
  int count = 0;
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      const bool in = mask.at(x, y) > 0.5f;
      inside.at<uint8_t>(y, x) = in ? 255 : 0;
      count += in;
    }
  }
  if (count == 0) {
    return Status::Error(name +
                         ": the mask is empty (no object pixel); a view that does not see "
                         "the object cannot be carved with (remove the view or fix its "
                         "mask)");
  }
  // distanceTransform: each non-zero pixel's distance to the nearest zero pixel (centre to
  // centre). Outside pixels measure to the nearest object pixel and vice versa; the silhouette
  // lies half a pixel from either centre. An image without background pixels leaves the inside
  // distances at OpenCV's large sentinel, which never carves.
  cv::Mat outside;
  cv::bitwise_not(inside, outside);
  cv::Mat to_inside, to_outside;
  cv::distanceTransform(outside, to_inside, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  cv::distanceTransform(inside, to_outside, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  view->name = name;
  view->camera = camera;
  view->cam_from_world = cam_from_world;
  view->distance.resize(static_cast<size_t>(mask.width) * mask.height);
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      const bool in = inside.at<uint8_t>(y, x) != 0;
      view->distance[static_cast<size_t>(y) * mask.width + x] =
          in ? -(to_outside.at<float>(y, x) - 0.5f) : to_inside.at<float>(y, x) - 0.5f;
    }
  }
  view->world_per_pixel_at_unit_depth = 2.0 / (camera.Focal().x() + camera.Focal().y());
  view->max_radius = camera.MaxUndistortedRadius();
  return Status::Ok();
}

uint64_t EstimateCarvingBytes(int64_t view_pixels, int resolution) {
  const uint64_t voxels = static_cast<uint64_t>(resolution) * resolution * resolution;
  // Per voxel: the dense field (4 bytes) and its OpenVDB copy (~4.2 bytes per stored voxel with
  // leaf masks). Per pixel: the 0/1 mask while loading (4), the distance map (4) and OpenCV's
  // temporaries (~10). Plus the coarse pass.
  const uint64_t coarse = uint64_t{kCoarseResolution} * kCoarseResolution * kCoarseResolution * 4;
  return voxels * 9 + static_cast<uint64_t>(std::max<int64_t>(view_pixels, 0)) * 18 + coarse;
}

Status CarveVisualHull(const std::vector<CarvingView>& views, const VisualHullOptions& options,
                       Progress* progress, VisualHull* hull) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (views.empty()) return Status::Error("no views to carve with");
  const int num_views = static_cast<int>(views.size());
  // Overruling t views leaves a point to the others, so at least t + 2 must see it.
  const int min_views =
      std::clamp(std::max(static_cast<int>(std::ceil(options.min_view_fraction * num_views - 1e-9)),
                          options.outlier_views + 2),
                 2, num_views);
  VoxelBox box;
  if (!FindCarvingBox(views, options, min_views, progress, &box)) {
    return Status::Error("the visual hull is empty: no point of [-" +
                         std::to_string(options.bounds) + ", " + std::to_string(options.bounds) +
                         "]^3 projects inside the masks of "
                         "all views that see it (seen by at least " +
                         std::to_string(min_views) + " views); check the cameras and masks");
  }
  hull->box = box;
  hull->band = kBandVoxels * box.voxel_size;
  hull->min_views = min_views;
  hull->field = EvaluateField(views, box, hull->band, min_views, options, progress);
  // The progress total counts `resolution` fine slices; the box may have fewer along z.
  if (progress != nullptr) progress->Advance(options.resolution - box.dims.z());
  hull->inside_voxels = static_cast<int>(
      std::count_if(hull->field.begin(), hull->field.end(), [](float v) { return v < 0; }));
  if (hull->inside_voxels == 0) {
    return Status::Error("the visual hull is empty at resolution " +
                         std::to_string(options.resolution) + " (no voxel centre inside it)");
  }
  return Status::Ok();
}

double SampleHull(const VisualHull& hull, const Eigen::Vector3d& p) {
  const VoxelBox& box = hull.box;
  const Eigen::Vector3d u = (p - box.lo) / box.voxel_size - Eigen::Vector3d::Constant(0.5);
  Eigen::Vector3i i0;
  Eigen::Vector3d f;
  for (int a = 0; a < 3; ++a) {
    if (!(u[a] >= -0.5 && u[a] <= box.dims[a] - 0.5)) return hull.band;
    const double c = std::clamp(u[a], 0.0, box.dims[a] - 1.0);
    i0[a] = std::min(static_cast<int>(c), box.dims[a] - 1);
    f[a] = c - i0[a];
  }
  auto at = [&](int di, int dj, int dk) {
    const int i = std::min(i0.x() + di, box.dims.x() - 1);
    const int j = std::min(i0.y() + dj, box.dims.y() - 1);
    const int k = std::min(i0.z() + dk, box.dims.z() - 1);
    return static_cast<double>(
        hull.field[(static_cast<size_t>(k) * box.dims.y() + j) * box.dims.x() + i]);
  };
  double value = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    const double w = (di ? f.x() : 1 - f.x()) * (dj ? f.y() : 1 - f.y()) * (dk ? f.z() : 1 - f.z());
    value += w * at(di, dj, dk);
  }
  return value;
}

Status ExtractHullSurface(const VisualHull& hull, std::vector<Eigen::Vector3d>* points,
                          std::vector<Eigen::Vector3i>* triangles) {
  static std::once_flag init_once;
  std::call_once(init_once, [] { openvdb::initialize(); });
  const VoxelBox& box = hull.box;
  try {
    // The field as a sparse OpenVDB grid: background +band (outside), values within 1e-6 of it
    // not stored, interior tiles pruned to -band. Index (i, j, k) is voxel (i, j, k) of the box,
    // so the transform maps it to its centre in scene units; everything outside the box is
    // background, which closes the surface where the hull reaches the box.
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(static_cast<float>(hull.band));
    openvdb::math::Transform::Ptr transform =
        openvdb::math::Transform::createLinearTransform(box.voxel_size);
    const Eigen::Vector3d origin = box.Centre(0, 0, 0);
    transform->postTranslate(openvdb::Vec3d(origin.x(), origin.y(), origin.z()));
    grid->setTransform(transform);
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    const openvdb::CoordBBox bbox(
        openvdb::Coord(0, 0, 0),
        openvdb::Coord(box.dims.x() - 1, box.dims.y() - 1, box.dims.z() - 1));
    // Dense only reads through this pointer (copyFromDense).
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(
        bbox, const_cast<float*>(hull.field.data()));
    openvdb::tools::copyFromDense(dense, *grid, 1e-6f);
    openvdb::tools::pruneLevelSet(grid->tree());

    std::vector<openvdb::Vec3s> vdb_points;
    std::vector<openvdb::Vec3I> vdb_triangles;
    std::vector<openvdb::Vec4I> vdb_quads;
    openvdb::tools::volumeToMesh(*grid, vdb_points, vdb_triangles, vdb_quads, 0.0, 0.0);
    points->resize(vdb_points.size());
    for (size_t n = 0; n < vdb_points.size(); ++n) {
      (*points)[n] = Eigen::Vector3d(vdb_points[n].x(), vdb_points[n].y(), vdb_points[n].z());
    }
    triangles->clear();
    triangles->reserve(vdb_triangles.size() + 2 * vdb_quads.size());
    for (const openvdb::Vec3I& t : vdb_triangles) triangles->emplace_back(t[0], t[1], t[2]);
    for (const openvdb::Vec4I& q : vdb_quads) {
      const Eigen::Vector3d& a = (*points)[q[0]];
      const Eigen::Vector3d& b = (*points)[q[1]];
      const Eigen::Vector3d& c = (*points)[q[2]];
      const Eigen::Vector3d& d = (*points)[q[3]];
      if ((a - c).squaredNorm() <= (b - d).squaredNorm()) {
        triangles->emplace_back(q[0], q[1], q[2]);
        triangles->emplace_back(q[0], q[2], q[3]);
      } else {
        triangles->emplace_back(q[0], q[1], q[3]);
        triangles->emplace_back(q[1], q[2], q[3]);
      }
    }
  } catch (const std::exception& e) {
    return Status::Error(std::string("surface extraction (OpenVDB) failed: ") + e.what());
  }
  if (triangles->empty()) return Status::Error("surface extraction gave no triangles");
  return Status::Ok();
}

}  // namespace sft
