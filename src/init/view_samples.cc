#include "src/init/view_samples.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace sft {
namespace {

// The samples and counts of one row of pixel blocks of one view.
struct RowSamples {
  std::vector<OrientedPoint> samples;
  int64_t rays = 0;
  int64_t back_face_hits = 0;
};

// Casts the blocks of block row `row` of `view` in packets of up to 8 rays (one origin).
void CastRow(const RenderScene& scene, const ViewSetup& view, int stride, int row,
             RowSamples* out) {
  const Camera& camera = view.camera;
  const Rigid3d world_from_cam = view.cam_from_world.Inverse();
  const Eigen::Vector3d origin = world_from_cam.translation;
  const int y0 = row * stride;
  const double y = 0.5 * (y0 + std::min(y0 + stride, camera.height));
  const int blocks = (camera.width + stride - 1) / stride;
  Eigen::Vector3d dirs[8];
  RayHit hits[8];
  for (int first = 0; first < blocks; first += 8) {
    int count = 0;
    for (int b = first; b < std::min(first + 8, blocks); ++b) {
      const int x0 = b * stride;
      const double x = 0.5 * (x0 + std::min(x0 + stride, camera.width));
      const Eigen::Vector3d ray = camera.CamFromImage(Eigen::Vector2d(x, y));
      if (ray.isZero()) continue;  // no ray through this pixel (past a distortion's fold).
      dirs[count++] = (world_from_cam.rotation * ray).normalized();
    }
    if (count == 0) continue;
    out->rays += count;
    scene.Intersect8(origin, dirs, count, hits);
    for (int i = 0; i < count; ++i) {
      if (!hits[i].hit) continue;
      Eigen::Vector3d normal = scene.FaceNormal(hits[i].face);
      if (normal.isZero()) continue;
      if (normal.dot(dirs[i]) > 0) {
        normal = -normal;
        ++out->back_face_hits;
      }
      out->samples.push_back({scene.Point(hits[i].face, hits[i].u, hits[i].v), normal});
    }
  }
}

// 0..5 for the dominant direction of n: +x, −x, +y, −y, +z, −z.
int NormalBucket(const Eigen::Vector3d& n) {
  int axis = 0;
  n.cwiseAbs().maxCoeff(&axis);
  return 2 * axis + (n[axis] < 0 ? 1 : 0);
}

}  // namespace

void CastViewSamples(const RenderScene& scene, const std::vector<ViewSetup>& views,
                     int pixel_stride, std::vector<OrientedPoint>* samples,
                     ViewSamplesReport* report) {
  *report = ViewSamplesReport();
  samples->clear();
  // One task per (view, block row); rows of all views are numbered consecutively.
  std::vector<int> first_row(views.size() + 1, 0);
  for (size_t v = 0; v < views.size(); ++v) {
    const int height = std::max(views[v].camera.height, 0);
    first_row[v + 1] = first_row[v] + (height + pixel_stride - 1) / pixel_stride;
  }
  std::vector<RowSamples> rows(first_row.back());
  tbb::parallel_for(0, first_row.back(), [&](int task) {
    const int v = static_cast<int>(std::upper_bound(first_row.begin(), first_row.end(), task) -
                                   first_row.begin() - 1);
    CastRow(scene, views[v], pixel_stride, task - first_row[v], &rows[task]);
  });
  for (size_t v = 0; v < views.size(); ++v) {
    bool seen = false;
    for (int r = first_row[v]; r < first_row[v + 1]; ++r) {
      RowSamples& row = rows[r];
      report->rays += row.rays;
      report->back_face_hits += row.back_face_hits;
      seen = seen || !row.samples.empty();
      samples->insert(samples->end(), row.samples.begin(), row.samples.end());
      row = RowSamples();
    }
    report->views_with_hits += seen;
  }
  report->hits = static_cast<int64_t>(samples->size());
}

std::vector<OrientedPoint> ThinSamples(const std::vector<OrientedPoint>& samples, double cell) {
  if (samples.empty()) return {};
  Eigen::Vector3d lo = samples[0].position;
  for (const OrientedPoint& s : samples) lo = lo.cwiseMin(s.position);
  // Cell (i, j, k) covers lo + [i, i+1)·cell etc.; 20 bits per index (a million cells per side,
  // far beyond any grid resampling builds) and 3 for the normal's direction.
  auto key_of = [&](const OrientedPoint& s, Eigen::Vector3d* centre) {
    const Eigen::Vector3d u = (s.position - lo) / cell;
    uint64_t key = static_cast<uint64_t>(NormalBucket(s.normal));
    for (int a = 0; a < 3; ++a) {
      const uint64_t i = std::min<uint64_t>(static_cast<uint64_t>(u[a]), (1u << 20) - 1);
      (*centre)[a] = lo[a] + (static_cast<double>(i) + 0.5) * cell;
      key = (key << 20) | i;
    }
    return key;
  };
  std::unordered_map<uint64_t, int> best;  // key -> index of the kept sample.
  best.reserve(samples.size());
  std::vector<int> order;  // keys in order of first occurrence (as indices of their first sample).
  for (int n = 0; n < static_cast<int>(samples.size()); ++n) {
    Eigen::Vector3d centre;
    const uint64_t key = key_of(samples[n], &centre);
    auto [it, inserted] = best.emplace(key, n);
    if (inserted) {
      order.push_back(n);
    } else if ((samples[n].position - centre).squaredNorm() <
               (samples[it->second].position - centre).squaredNorm()) {
      it->second = n;
    }
  }
  std::vector<OrientedPoint> kept;
  kept.reserve(order.size());
  for (int first : order) {
    Eigen::Vector3d centre;
    kept.push_back(samples[best.at(key_of(samples[first], &centre))]);
  }
  return kept;
}

}  // namespace sft
