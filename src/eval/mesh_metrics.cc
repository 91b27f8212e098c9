#include "src/eval/mesh_metrics.h"

#include <glog/logging.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <nanoflann.hpp>

#include "src/core/rng.h"

namespace sft {
namespace {

// Nearest samples whose faces are tested exactly for each query point.
constexpr int kCandidates = 8;

// A uniform double in [0, 1) that is a pure function of its key.
double HashUniform(uint64_t key) { return static_cast<double>(Mix64(key) >> 11) * 0x1.0p-53; }

// nanoflann's dataset interface over a vector of points.
struct PointCloudAdaptor {
  const std::vector<Eigen::Vector3d>* points;
  size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(size_t index, size_t dim) const { return (*points)[index][dim]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox&) const {
    return false;  // let nanoflann compute it.
  }
};

using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloudAdaptor>,
                                        PointCloudAdaptor, 3, uint32_t>;

double SegmentDistanceSquared(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length_squared = ab.squaredNorm();
  double t = length_squared > 0.0 ? (p - a).dot(ab) / length_squared : 0.0;
  t = std::min(1.0, std::max(0.0, t));
  return (p - (a + t * ab)).squaredNorm();
}

// Distances from every sample of `from` to the surface (positions, faces) sampled by `to`.
std::vector<double> DirectedDistances(const SurfaceSamples& from, const SurfaceSamples& to,
                                      const std::vector<Eigen::Vector3d>& positions,
                                      const std::vector<Eigen::Vector3i>& faces) {
  PointCloudAdaptor adaptor{&to.points};
  KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  std::vector<double> distances(from.points.size());
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, from.points.size(), 4096),
      [&](const tbb::blocked_range<size_t>& range) {
        uint32_t indices[kCandidates];
        double squared[kCandidates];
        for (size_t s = range.begin(); s != range.end(); ++s) {
          const Eigen::Vector3d& p = from.points[s];
          const size_t found = tree.knnSearch(p.data(), kCandidates, indices, squared);
          double best = found > 0 ? std::sqrt(squared[0]) : HUGE_VAL;
          for (size_t k = 0; k < found; ++k) {
            const Eigen::Vector3i& f = faces[to.faces[indices[k]]];
            best = std::min(
                best, PointTriangleDistance(p, positions[f[0]], positions[f[1]], positions[f[2]]));
          }
          distances[s] = best;
        }
      });
  return distances;
}

// Normalised copy of a mesh: positions mapped by p ↦ (p − centre)/diagonal. Errors name `name`.
Status NormalisedArrays(const TriMesh& mesh, const Eigen::Vector3d& centre, double diagonal,
                        const std::string& name, std::vector<Eigen::Vector3d>* positions,
                        std::vector<Eigen::Vector3i>* faces) {
  MeshToArrays(mesh, positions, faces);
  if (faces->empty()) return Status::Error(name + ": mesh has no faces");
  double area = 0.0;
  for (Eigen::Vector3d& p : *positions) {
    if (!p.allFinite()) return Status::Error(name + ": non-finite vertex coordinates");
    p = (p - centre) / diagonal;
  }
  for (const Eigen::Vector3i& f : *faces) {
    const Eigen::Vector3d& a = (*positions)[f[0]];
    area += 0.5 * ((*positions)[f[1]] - a).cross((*positions)[f[2]] - a).norm();
  }
  if (!(area > 0.0) || !std::isfinite(area)) {
    return Status::Error(name + ": every face has zero area (no surface to sample)");
  }
  return Status::Ok();
}

}  // namespace

bool MeshMetricsOptions::Check(std::string* why) const {
  if (!(tolerance > 0.0 && tolerance <= 1.0)) {
    *why =
        "tolerance: must be in (0, 1] (a fraction of the reference's bounding-box diagonal), "
        "got " +
        std::to_string(tolerance);
    return false;
  }
  if (samples < kMinSamples || samples > kMaxSamples) {
    *why = "samples: must be in [" + std::to_string(kMinSamples) + ", " +
           std::to_string(kMaxSamples) + "], got " + std::to_string(samples);
    return false;
  }
  return true;
}

double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n_squared = n.squaredNorm();
  if (n_squared > 0.0) {
    // Barycentric weights of p's projection onto the plane, from signed sub-triangle areas.
    const double wa = (c - b).cross(p - b).dot(n) / n_squared;
    const double wb = (a - c).cross(p - c).dot(n) / n_squared;
    const double wc = 1.0 - wa - wb;
    if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) return std::abs((p - a).dot(n)) / std::sqrt(n_squared);
  }
  // The nearest point lies on the boundary (or the triangle is degenerate).
  return std::sqrt(std::min({SegmentDistanceSquared(p, a, b), SegmentDistanceSquared(p, b, c),
                             SegmentDistanceSquared(p, c, a)}));
}

SurfaceSamples SampleSurface(const std::vector<Eigen::Vector3d>& positions,
                             const std::vector<Eigen::Vector3i>& faces, int count, uint64_t seed,
                             uint64_t stream) {
  std::vector<double> cumulative(faces.size());
  double total = 0.0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const Eigen::Vector3d& a = positions[faces[f][0]];
    total += 0.5 * (positions[faces[f][1]] - a).cross(positions[faces[f][2]] - a).norm();
    cumulative[f] = total;
  }
  CHECK(total > 0.0) << "SampleSurface: zero total area";
  SurfaceSamples samples;
  samples.points.resize(count);
  samples.faces.resize(count);
  const uint64_t key = Mix64(Mix64(seed) ^ Mix64(stream + 0x632BE59BD9B4E019ull));
  tbb::parallel_for(0, count, [&](int k) {
    const uint64_t sample_key = key + 3 * static_cast<uint64_t>(k);
    // Stratified over the cumulative area; upper_bound skips zero-area faces.
    const double target = (k + HashUniform(sample_key)) / count * total;
    size_t f = std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin();
    f = std::min(f, faces.size() - 1);
    while (f > 0 && cumulative[f] == cumulative[f - 1]) --f;  // rounding at the very end.
    // Uniform in the triangle: (1 − √u, √u(1 − v), √u·v).
    const double su = std::sqrt(HashUniform(sample_key + 1));
    const double v = HashUniform(sample_key + 2);
    const Eigen::Vector3i& tri = faces[f];
    samples.points[k] = (1.0 - su) * positions[tri[0]] + su * (1.0 - v) * positions[tri[1]] +
                        su * v * positions[tri[2]];
    samples.faces[k] = static_cast<int>(f);
  });
  return samples;
}

Status ComputeMeshMetrics(const TriMesh& reference, const TriMesh& mesh,
                          const MeshMetricsOptions& options, MeshMetrics* metrics,
                          const std::string& reference_name, const std::string& mesh_name) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (reference.n_vertices() == 0) return Status::Error(reference_name + ": mesh is empty");
  Eigen::Vector3d lo, hi;
  MeshBounds(reference, &lo, &hi);
  const double diagonal = (hi - lo).norm();
  if (!std::isfinite(diagonal)) {
    return Status::Error(reference_name + ": non-finite vertex coordinates");
  }
  if (!(diagonal > 0.0)) {
    return Status::Error(reference_name + ": bounding box has zero diagonal");
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  std::vector<Eigen::Vector3d> ref_positions, mesh_positions;
  std::vector<Eigen::Vector3i> ref_faces, mesh_faces;
  SFT_RETURN_IF_ERROR(
      NormalisedArrays(reference, centre, diagonal, reference_name, &ref_positions, &ref_faces));
  SFT_RETURN_IF_ERROR(
      NormalisedArrays(mesh, centre, diagonal, mesh_name, &mesh_positions, &mesh_faces));

  const SurfaceSamples ref_samples =
      SampleSurface(ref_positions, ref_faces, options.samples, options.seed, 0);
  const SurfaceSamples mesh_samples =
      SampleSurface(mesh_positions, mesh_faces, options.samples, options.seed, 1);
  const std::vector<double> mesh_to_ref =
      DirectedDistances(mesh_samples, ref_samples, ref_positions, ref_faces);
  const std::vector<double> ref_to_mesh =
      DirectedDistances(ref_samples, mesh_samples, mesh_positions, mesh_faces);

  // Sequential sums: deterministic for any thread count.
  const auto summarise = [&](const std::vector<double>& d, double* mean, double* within) {
    double sum = 0.0;
    size_t inside = 0;
    for (double x : d) {
      sum += x;
      inside += x < options.tolerance;
    }
    *mean = sum / d.size();
    *within = static_cast<double>(inside) / d.size();
  };
  MeshMetrics result;
  result.tolerance = options.tolerance;
  result.samples = options.samples;
  result.reference_diagonal = diagonal;
  summarise(mesh_to_ref, &result.mean_mesh_to_reference, &result.precision);
  summarise(ref_to_mesh, &result.mean_reference_to_mesh, &result.recall);
  const double sum = result.precision + result.recall;
  result.f1 = sum > 0.0 ? 2.0 * result.precision * result.recall / sum : 0.0;
  result.chamfer = 0.5 * (result.mean_mesh_to_reference + result.mean_reference_to_mesh);
  *metrics = result;
  return Status::Ok();
}

}  // namespace sft
