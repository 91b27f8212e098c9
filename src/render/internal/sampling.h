// Internal to src/render: sampling utilities of the edge terms — a discrete distribution over
// weighted candidates (inverse CDF for stratified draws, alias method for O(1) draws), frustum
// clipping of segments, points uniform in the angle a segment subtends, and resampled importance
// sampling of (segment, point) pairs. Unit tests: tests/render/sampling_test.cc.
#ifndef SFT_RENDER_INTERNAL_SAMPLING_H_
#define SFT_RENDER_INTERNAL_SAMPLING_H_

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "src/core/rng.h"
#include "src/render/camera.h"

namespace sft {
namespace render_internal {

// Draws index i with probability w_i/Σw. Two ways: SampleInverse inverts the cumulative
// distribution (monotone in u, so stratified u give stratified indices; a binary search) and
// Sample uses Walker's alias table (Vose's construction; O(1), where the binary search costs a
// cache miss per level — secondary edge candidates are drawn 16 times per path vertex).
class DiscreteDistribution {
 public:
  DiscreteDistribution() = default;
  // Weights should be finite and ≥ 0; empty() is true unless their sum is positive and finite.
  explicit DiscreteDistribution(const std::vector<double>& weights);

  bool empty() const { return cells_.empty(); }
  int size() const { return static_cast<int>(cumulative_.size()); }
  double total() const { return total_; }
  double weight(int i) const { return weights_[i]; }
  // Sample for each of u[0 … n): the interface ResampleSegmentPoint's proposals share.
  void SampleBatch(const double* u, int n, int* out) const {
    for (int k = 0; k < n; ++k) out[k] = Sample(u[k]);
  }
  // Σw / w_i: the inverse of index i's probability.
  double InverseProbability(int i) const { return total_ / weights_[i]; }
  // Σ_{j<i} w_j.
  double CumulativeBefore(int i) const { return i > 0 ? cumulative_[i - 1] : 0.0; }
  // The index i with Σ_{j<i} w_j ≤ u·Σw < Σ_{j≤i} w_j (the last index for u·Σw at the end).
  int SampleInverse(double u) const;
  // The alias-table draw for u ∈ [0, 1).
  int Sample(double u) const;
  // Cell i of the alias table (Sample keeps i with `probability`, else takes `alias`), for
  // tables that pack it next to their own data.
  struct Cell {
    double probability = 1.0;  // of keeping index i in cell i.
    int alias = 0;
  };
  const Cell& cell(int i) const { return cells_[i]; }

 private:
  std::vector<double> weights_;
  std::vector<double> cumulative_;
  std::vector<Cell> cells_;
  double total_ = 0.0;
};

// Normalized image-plane bounds (x/z, y/z) of a view, with a margin, for clipping edges.
struct FrustumBounds {
  double u_min, u_max, v_min, v_max;
  double z_min;
};

// The bounds of `camera`'s image with a 5% margin; z_min = 1e-7·scene_extent.
FrustumBounds ViewFrustum(const Camera& camera, double scene_extent);

// Clips the camera-frame segment a + s(b − a), s ∈ [0, 1], to the frustum; false when empty.
bool ClipSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const FrustumBounds& f,
                 double* s0, double* s1);

// The point a + s(b − a) whose direction from x is at angle ξ·Θ from (a − x) in the plane of x
// and the segment, Θ the angle the segment subtends at x. False when degenerate (x on the
// segment's line, zero angle).
bool AngleUniformEdgePoint(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& x, double xi, double* s, double* subtended);

// One (segment, point) pair drawn by resampled importance sampling (Talbot et al. 2005):
// `num_candidates` segments drawn from `proposal` (any type with `SampleBatch(u, n, out)` and
// `double InverseProbability(int c)`, e.g. DiscreteDistribution), each with a point uniform in
// the angle it subtends at x, weighted w_k = p̂_k·Θ_k/p_k with p̂ = `target`(ω_k), one kept ∝ w_k.
// `ends(c, &a, &b)` gives candidate c's endpoints, or false where it cannot be a jump seen from
// x (p̂ = 0). The first candidate uses (u_index, u_point), the rest `sampler`.
struct ResampledPoint {
  int index = -1;        // the kept candidate; −1 when none had a positive weight.
  double s = 0.0;        // its point a + s(b − a).
  double inv_pdf = 0.0;  // Θ/(p·p̂) replaced by (1/K)Σ_k w_k/p̂: the estimate's weight/jump.
};

// At most this many candidates per draw.
constexpr int kMaxResampleCandidates = 32;

template <typename Proposal, typename Ends, typename Target>
ResampledPoint ResampleSegmentPoint(const Proposal& proposal, int num_candidates,
                                    const Eigen::Vector3d& x, double u_index, double u_point,
                                    Sampler* sampler, const Ends& ends, const Target& target) {
  // All candidates are drawn (and their data prefetched) before any is weighed, so that their
  // memory loads overlap; the random numbers are consumed in the same order either way.
  int index[kMaxResampleCandidates];
  double point_u[kMaxResampleCandidates], pick_u[kMaxResampleCandidates];
  num_candidates = std::min(num_candidates, kMaxResampleCandidates);
  double index_u[kMaxResampleCandidates];
  for (int k = 0; k < num_candidates; ++k) {
    index_u[k] = k == 0 ? u_index : sampler->Next1D();
    point_u[k] = k == 0 ? u_point : sampler->Next1D();
    pick_u[k] = sampler->Next1D();
  }
  proposal.SampleBatch(index_u, num_candidates, index);
  ResampledPoint out;
  double w_sum = 0.0, kept_target = 0.0;
  for (int k = 0; k < num_candidates; ++k) {
    const int c = index[k];
    Eigen::Vector3d a, b;
    if (!ends(c, &a, &b)) continue;
    double s_k = 0.0, subtended = 0.0;
    if (!AngleUniformEdgePoint(a, b, x, point_u[k], &s_k, &subtended)) continue;
    const double p_hat = target((a + s_k * (b - a) - x).normalized());
    const double w = p_hat * subtended * proposal.InverseProbability(c);
    if (!(w > 0.0) || !std::isfinite(w)) continue;
    w_sum += w;
    if (pick_u[k] * w_sum < w) {
      out.index = c;
      out.s = s_k;
      kept_target = p_hat;
    }
  }
  if (out.index >= 0) out.inv_pdf = w_sum / (kept_target * num_candidates);
  return out;
}

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_SAMPLING_H_
