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
  // Sample for each of u[0 … n), with each draw's inverse probability: the interface
  // DrawSegmentCandidates' proposals share.
  void SampleBatch(const double* u, int n, int* out, double* inverse_probability) const {
    for (int k = 0; k < n; ++k) {
      out[k] = Sample(u[k]);
      inverse_probability[k] = InverseProbability(out[k]);
    }
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

// (Segment, point) pairs drawn by resampled importance sampling (Talbot et al. 2005):
// `num_candidates` segments drawn from `proposal` (any type with `SampleBatch(u, n, out,
// inverse_probability)`, an index −1 for an empty draw, e.g. DiscreteDistribution, or
// NearEdgeMixture), each with a point uniform in
// the angle it subtends at x, weighted w_k = p̂_k·Θ_k/p_k with p̂ = `target`(ω_k); Pick keeps one
// ∝ w_k. `ends(c, &a, &b)` gives candidate c's endpoints, or false where it cannot be a jump seen
// from x (p̂ = 0). The first candidate uses (u_index, u_point), the rest `sampler`.
struct ResampledPoint {
  int index = -1;        // the kept candidate; −1 when none had a positive weight.
  double s = 0.0;        // its point a + s(b − a).
  double inv_pdf = 0.0;  // Θ/(p·p̂) replaced by (1/K)Σ_k w_k/p̂: the estimate's weight/jump.
};

// At most this many candidates per draw.
constexpr int kMaxResampleCandidates = 32;

// The weighed candidates of one draw (those of positive weight, in draw order).
struct SegmentCandidates {
  int num_drawn = 0;     // K, zero-weight candidates included.
  int num_weighted = 0;  // entries below.
  int index[kMaxResampleCandidates];
  double s[kMaxResampleCandidates];
  double target[kMaxResampleCandidates];
  double cumulative[kMaxResampleCandidates];  // Σ_{j≤k} w_j.

  double weight_sum() const { return num_weighted > 0 ? cumulative[num_weighted - 1] : 0.0; }

  // The entry whose cumulative-weight interval holds u·Σw (u ∈ [0, 1)): candidate k with
  // probability w_k/Σw. Picks at u_j = (j + u)/M, j < M (systematic resampling), are each
  // candidate k w_k/Σw·M times in expectation, so the mean of their estimates is unbiased too;
  // equal picks are adjacent in j. Entry −1 when no candidate has a positive weight.
  int PickEntry(double u) const {
    if (num_weighted == 0) return -1;
    const double level = u * weight_sum();
    int k = 0;
    while (k + 1 < num_weighted && !(level < cumulative[k])) ++k;
    return k;
  }
  ResampledPoint Point(int entry) const {
    ResampledPoint out;
    if (entry < 0) return out;
    out.index = index[entry];
    out.s = s[entry];
    out.inv_pdf = weight_sum() / (target[entry] * num_drawn);
    return out;
  }
};

template <typename Proposal, typename Ends, typename Target>
SegmentCandidates DrawSegmentCandidates(const Proposal& proposal, int num_candidates,
                                        const Eigen::Vector3d& x, double u_index, double u_point,
                                        Sampler* sampler, const Ends& ends, const Target& target) {
  // All candidates are drawn (and their data prefetched) before any is weighed, so that their
  // memory loads overlap.
  SegmentCandidates out;
  out.num_drawn = std::min(num_candidates, kMaxResampleCandidates);
  int index[kMaxResampleCandidates];
  double index_u[kMaxResampleCandidates], point_u[kMaxResampleCandidates];
  double inverse_probability[kMaxResampleCandidates];
  for (int k = 0; k < out.num_drawn; ++k) {
    index_u[k] = k == 0 ? u_index : sampler->Next1D();
    point_u[k] = k == 0 ? u_point : sampler->Next1D();
  }
  proposal.SampleBatch(index_u, out.num_drawn, index, inverse_probability);
  double w_sum = 0.0;
  for (int k = 0; k < out.num_drawn; ++k) {
    const int c = index[k];
    Eigen::Vector3d a, b;
    if (c < 0 || !ends(c, &a, &b)) continue;
    double s_k = 0.0, subtended = 0.0;
    if (!AngleUniformEdgePoint(a, b, x, point_u[k], &s_k, &subtended)) continue;
    const double p_hat = target((a + s_k * (b - a) - x).normalized());
    const double w = p_hat * subtended * inverse_probability[k];
    if (!(w > 0.0) || !std::isfinite(w)) continue;
    w_sum += w;
    const int e = out.num_weighted++;
    out.index[e] = c;
    out.s[e] = s_k;
    out.target[e] = p_hat;
    out.cumulative[e] = w_sum;
  }
  return out;
}

// One kept pair: DrawSegmentCandidates, then a pick with the sampler's next number.
template <typename Proposal, typename Ends, typename Target>
ResampledPoint ResampleSegmentPoint(const Proposal& proposal, int num_candidates,
                                    const Eigen::Vector3d& x, double u_index, double u_point,
                                    Sampler* sampler, const Ends& ends, const Target& target) {
  const SegmentCandidates candidates =
      DrawSegmentCandidates(proposal, num_candidates, x, u_index, u_point, sampler, ends, target);
  return candidates.Point(candidates.PickEntry(sampler->Next1D()));
}

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_SAMPLING_H_
