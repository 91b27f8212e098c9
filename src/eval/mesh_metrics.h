// Geometric accuracy of a reconstructed mesh against a reference mesh (`sft eval --reference`): F1
// at a distance tolerance, and the Chamfer distance.
//
// Units. Both meshes are first mapped by the same similarity, p ↦ (p − c)/D, where c is the centre
// and D the diagonal of the *reference*'s bounding box, so every distance and the tolerance are
// fractions of the reference's size (the report's "tolerance 0.01 of the object's size") and the
// numbers do not change when both meshes are scaled or moved together.
//
// Samples. Each surface is sampled with `samples` points, uniformly by area: sample k picks its
// face by inverting the cumulative face areas at (k + u_k)/N (stratified, so faces receive their
// area's share of samples up to ±1) and a uniform point inside it. The random numbers are pure
// functions of (seed, surface, k), so the numbers are deterministic for a seed. The two surfaces
// use different streams, so a mesh compared with itself is sampled at different points.
//
// Distances. The distance of a sample to the other surface is a point-to-triangle distance: the
// k = 8 nearest samples of the other surface are found with a kd-tree (nanoflann), and the distance
// is the minimum exact distance to their faces. It is the true point-to-surface distance whenever
// the nearest triangle owns one of those samples, and never larger than the point-to-sample
// distance otherwise; unlike a point-to-point (sample-to-sample) distance it has no bias of the
// order of the sample spacing, so identical surfaces give 0 up to rounding.
//
// Measures, with d(x, S) the distance of x to surface S, R the reference, M the mesh, τ the
// tolerance, and means over each surface's own samples:
//   precision = fraction of M's samples with d(x, R) < τ      (how much of M is correct)
//   recall    = fraction of R's samples with d(y, M) < τ      (how much of R is covered)
//   F1        = 2·precision·recall / (precision + recall)     (0 when both are 0)
//   mean_mesh_to_reference = mean d(x, R) over M,  mean_reference_to_mesh = mean d(y, M) over R
//   chamfer   = (mean_mesh_to_reference + mean_reference_to_mesh) / 2
// i.e. the Chamfer distance is the mean of the two directed mean (unsquared) distances.
#ifndef SFT_EVAL_MESH_METRICS_H_
#define SFT_EVAL_MESH_METRICS_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/mesh.h"

namespace sft {

struct MeshMetricsOptions {
  // F1 distance threshold, as a fraction of the reference's bounding-box diagonal; in (0, 1].
  double tolerance = 0.01;
  // Surface samples per mesh (the same number on both); in [kMinSamples, kMaxSamples]. With the
  // default, F1 at 0.01 varies by less than ±0.2 percentage points over seeds (docs/design-notes).
  int samples = 1000000;
  // Sampling seed: the same seed gives the same numbers.
  uint64_t seed = 0;

  static constexpr int kMinSamples = 100;
  static constexpr int kMaxSamples = 20000000;

  // False (with the offending field in *why, e.g. "tolerance: must be in (0, 1], got 0") when a
  // field is out of range.
  bool Check(std::string* why) const;
};

struct MeshMetrics {
  double tolerance = 0.0;  // as used, fraction of the reference diagonal.
  int samples = 0;         // samples per mesh.
  double precision = 0.0;  // in [0, 1].
  double recall = 0.0;     // in [0, 1].
  double f1 = 0.0;         // in [0, 1].
  double chamfer = 0.0;    // mean of the two directed means below; fraction of the diagonal.
  double mean_mesh_to_reference = 0.0;  // mean distance of the mesh's samples to the reference.
  double mean_reference_to_mesh = 0.0;  // mean distance of the reference's samples to the mesh.
  double reference_diagonal = 0.0;      // the reference's bounding-box diagonal, in file units.
};

// Computes the measures above. Errors (one line, starting with `reference_name` or `mesh_name`):
// a mesh without faces or whose faces all have zero area, non-finite vertex coordinates, a
// reference whose bounding box has zero diagonal; and invalid options (naming the field).
Status ComputeMeshMetrics(const TriMesh& reference, const TriMesh& mesh,
                          const MeshMetricsOptions& options, MeshMetrics* metrics,
                          const std::string& reference_name = "reference",
                          const std::string& mesh_name = "mesh");

// Points sampled uniformly by area on a triangle soup, with the face each one lies on.
struct SurfaceSamples {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> faces;
};

// Samples `count` points on the triangles `faces` of `positions` as described above; `stream`
// tells apart independent sample sets of the same seed. Faces of zero area get no samples.
// Requires a positive total area (CHECK).
SurfaceSamples SampleSurface(const std::vector<Eigen::Vector3d>& positions,
                             const std::vector<Eigen::Vector3i>& faces, int count, uint64_t seed,
                             uint64_t stream);

// Euclidean distance from `p` to the closed triangle (a, b, c); degenerate triangles (collinear
// or coincident corners) are handled as their edges.
double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace sft

#endif  // SFT_EVAL_MESH_METRICS_H_
