#include "src/capture/object_box.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "src/core/progress.h"
#include "src/init/visual_hull.h"

namespace sft {
namespace {

// The smallest eigenvalue of the mean of (I − d·dᵀ) over the optical axes d below which the axes
// count as parallel (1e-3: all axes within about 2° of one direction).
constexpr double kMinAxisSpread = 1e-3;

double Median(std::vector<double> values) {
  const size_t k = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

// Step 1: the point nearest to every optical axis and the median camera distance from it.
Status SearchFrame(const std::vector<BoxView>& views, Eigen::Vector3d* centre, double* unit) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> origins, axes;
  for (const BoxView& view : views) {
    const Rigid3d world_from_cam = view.cam_from_world.Inverse();
    const Eigen::Vector3d origin = world_from_cam.translation;
    const Eigen::Vector3d axis = world_from_cam.rotation * Eigen::Vector3d::UnitZ();
    const Eigen::Matrix3d project = Eigen::Matrix3d::Identity() - axis * axis.transpose();
    a += project;
    b += project * origin;
    origins.push_back(origin);
    axes.push_back(axis);
  }
  const double n = static_cast<double>(views.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(a / n);
  if (!(eigen.eigenvalues().minCoeff() > kMinAxisSpread)) {
    return Status::Error(
        "the cameras' optical axes are (nearly) parallel, so they do not converge on an "
        "object; sft imports object captures with views around the object");
  }
  *centre = a.ldlt().solve(b);
  std::vector<double> distances;
  int in_front = 0;
  for (size_t i = 0; i < origins.size(); ++i) {
    distances.push_back((*centre - origins[i]).norm());
    in_front += axes[i].dot(*centre - origins[i]) > 0;
  }
  *unit = Median(distances);
  if (!(2 * in_front > static_cast<int>(views.size())) || !(*unit > 0) || !centre->allFinite()) {
    return Status::Error("the point nearest to the cameras' optical axes lies behind " +
                         std::to_string(views.size() - in_front) + " of " +
                         std::to_string(views.size()) +
                         " cameras; the views do not look at one object");
  }
  return Status::Ok();
}

// The bounds of the voxel centres of the largest 6-connected component of the hull's inside
// voxels. Where views lose the object past their frame's edge, points that few views see can
// survive carving away from the object (a narrow field of view leaves such regions beside the
// object); they are separate components and must not stretch the box.
void LargestComponentBounds(const VisualHull& hull, Eigen::Vector3d* lo, Eigen::Vector3d* hi) {
  const Eigen::Vector3i& d = hull.box.dims;
  const int64_t n = hull.box.NumVoxels();
  std::vector<int> component(n, -1);
  std::vector<int64_t> stack;
  int best = -1;
  int64_t best_size = 0;
  for (int64_t seed = 0; seed < n; ++seed) {
    if (!(hull.field[seed] < 0) || component[seed] >= 0) continue;
    const int label = static_cast<int>(seed);
    int64_t size = 0;
    stack.assign(1, seed);
    component[seed] = label;
    while (!stack.empty()) {
      const int64_t v = stack.back();
      stack.pop_back();
      ++size;
      const int i = static_cast<int>(v % d.x()), j = static_cast<int>((v / d.x()) % d.y()),
                k = static_cast<int>(v / (int64_t{d.x()} * d.y()));
      const int64_t steps[6][2] = {{i > 0, -1},
                                   {i + 1 < d.x(), 1},
                                   {j > 0, -d.x()},
                                   {j + 1 < d.y(), d.x()},
                                   {k > 0, -int64_t{d.x()} * d.y()},
                                   {k + 1 < d.z(), int64_t{d.x()} * d.y()}};
      for (const auto& step : steps) {
        const int64_t w = v + step[1];
        if (step[0] && hull.field[w] < 0 && component[w] < 0) {
          component[w] = label;
          stack.push_back(w);
        }
      }
    }
    if (size > best_size) {
      best_size = size;
      best = label;
    }
  }
  *lo = Eigen::Vector3d::Constant(1e300);
  *hi = -*lo;
  for (int64_t v = 0; v < n; ++v) {
    if (component[v] != best) continue;
    const Eigen::Vector3d c =
        hull.box.Centre(static_cast<int>(v % d.x()), static_cast<int>((v / d.x()) % d.y()),
                        static_cast<int>(v / (int64_t{d.x()} * d.y())));
    *lo = lo->cwiseMin(c);
    *hi = hi->cwiseMax(c);
  }
}

// Step 2: the hull's box in the search frame (p_search = (p − centre) / unit).
Status CarvedBox(const std::vector<BoxView>& views, const ObjectBoxOptions& options,
                 ObjectBox* box) {
  std::vector<CarvingView> carving(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    const BoxView& view = views[i];
    Rigid3d pose = view.cam_from_world;  // p_cam ∝ R·(unit·q + centre) + t for a search point q.
    pose.translation = (pose.translation + pose.rotation * box->search_centre) / box->search_unit;
    SFT_RETURN_IF_ERROR(MakeCarvingView(view.name, view.camera, pose, view.mask, &carving[i]));
  }
  VisualHullOptions hull_options;
  hull_options.resolution = options.resolution;
  hull_options.bounds = 1.0;
  VisualHull hull;
  {
    Progress progress("import (carving)", kCoarseResolution + options.resolution, !options.quiet);
    const Status status = CarveVisualHull(carving, hull_options, &progress, &hull);
    progress.Finish();
    if (!status.ok()) return status.Prefixed("finding the object with the masks");
  }
  const VoxelBox& grid = hull.box;
  Eigen::Vector3d lo, hi;
  LargestComponentBounds(hull, &lo, &hi);
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5 * grid.voxel_size);
  lo -= half;
  hi += half;
  box->touches_search_border =
      (lo.array() <= -1.0 + grid.voxel_size).any() || (hi.array() >= 1.0 - grid.voxel_size).any();
  box->lo = box->search_centre + box->search_unit * lo;
  box->hi = box->search_centre + box->search_unit * hi;
  box->method = "visual hull of the masks";
  return Status::Ok();
}

// Step 3 without a sphere: the object fills the central axis_cone of the images.
ObjectSphere AssumedSphere(const std::vector<BoxView>& views, const ObjectBoxOptions& options,
                           const Eigen::Vector3d& centre) {
  std::vector<double> radii;
  for (const BoxView& view : views) {
    const Eigen::Vector2d focal = view.camera.Focal();
    const double half_tan =
        std::min(0.5 * view.camera.width / focal.x(), 0.5 * view.camera.height / focal.y());
    const double distance = (view.cam_from_world * centre).norm();
    radii.push_back(distance * options.axis_cone * half_tan);
  }
  return {centre, Median(radii)};
}

}  // namespace

bool ObjectBoxOptions::Check(std::string* why) const {
  if (resolution < 16 || resolution > 256) {
    *why = "resolution: must be in [16, 256], got " + std::to_string(resolution);
    return false;
  }
  if (!(axis_cone > 0 && axis_cone <= 1)) {
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "--axis-cone: must be in (0, 1], got %g", axis_cone);
    *why = buffer;
    return false;
  }
  return true;
}

Status FindObjectBox(const std::vector<BoxView>& views, const std::optional<ObjectSphere>& sphere,
                     const ObjectBoxOptions& options, ObjectBox* box) {
  *box = ObjectBox();
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (views.empty()) return Status::Error("no views");
  SFT_RETURN_IF_ERROR(SearchFrame(views, &box->search_centre, &box->search_unit));
  const bool masks = std::all_of(views.begin(), views.end(),
                                 [](const BoxView& view) { return !view.mask.empty(); });
  if (masks) return CarvedBox(views, options, box);
  ObjectSphere s;
  if (sphere) {
    s = *sphere;
    box->method = "sphere of the camera file";
  } else {
    s = AssumedSphere(views, options, box->search_centre);
    char method[96];
    std::snprintf(method, sizeof(method),
                  "optical axes (object assumed to fill the central %g of the images)",
                  options.axis_cone);
    box->method = method;
  }
  if (!(s.radius > 0) || !s.centre.allFinite()) {
    return Status::Error("the object's bounding sphere is empty");
  }
  box->lo = s.centre - Eigen::Vector3d::Constant(s.radius);
  box->hi = s.centre + Eigen::Vector3d::Constant(s.radius);
  return Status::Ok();
}

}  // namespace sft
