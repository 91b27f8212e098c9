// Smoothness between neighbouring mesh-colors texels (albedo: 3 channels; roughness: 1).
//
// Residual (C residuals, C = channels), for a pair (a, b) of neighbouring texels:
//
//   r = w · (t_a − t_b)
//
// Parameter blocks: [t_a, t_b], each C doubles (the texel's channel values).
// Jacobians: ∂r/∂t_a = w·I_C, ∂r/∂t_b = −w·I_C (exact: the residual is linear).
// Evaluate never returns false. Derivative terms it does not have: none.
//
// The log-ratio form (TexelSmoothnessOptions::log_ratio; TexelLogRatioCost):
//
//   r = w · kLogRatioReference · (log(t_a + kLogRatioEpsilon) − log(t_b + kLogRatioEpsilon))
//
// with ∂r/∂t_a = w·kLogRatioReference / (t_a + ε)·I_C and ∂r/∂t_b the negative at t_b (exact).
// It is invariant when every texel is scaled by one factor (up to ε), so a fit that can trade the
// albedo's scale against another parameter's (a fitted light's scale: the images see only the
// product) is not pulled towards a dark albedo by the prior. The linear form shrinks with the
// scale squared and drives that trade without bound (docs/design-notes.md, "The video road's
// albedo on the true mesh"). At t = kLogRatioReference both forms have the same Jacobian; darker
// texels are tied more strongly, brighter ones less (differences are relative). Bounds keep t ≥ 0,
// so the log stays finite. Evaluate never returns false.
//
// Which texels are neighbours (TexelNeighbourPairs), in the layout of src/geometry/mesh_colors.h
// (texel (i, j) of a face, i + j ≤ r, owns the points with (floor(rα), floor(rβ)) = (i, j)):
//   * within a face, the three grid neighbours (i, j)–(i+1, j), (i, j)–(i, j+1) and
//     (i+1, j)–(i, j+1), whenever both texels exist: 3·r(r+1)/2 pairs per face;
//   * across each edge shared by two faces, the texels that cover the same stretch of the edge:
//     the edge is cut into r equal intervals (one for r = 0), and the texel of each face that the
//     mesh-colors lookup assigns to the interval's midpoint is paired with the other face's:
//     r pairs per interior edge (1 for r = 0). Faces sharing only a vertex are linked through the
//     faces between them.
// The duplicated edge and vertex texels of the layout are therefore *smoothed* towards each other
// with the same weight as in-face neighbours, not tied by a hard or strong constraint: the term is
// one uniform smoothness over the texel adjacency graph (`cross_face_weight` can change the
// balance). Pairing by the lookup, not by duplicated lattice points, matters: a lattice-point texel
// covers the interval *after* its point along its own face's grid, so when the two faces' grids
// run along the shared edge in opposite directions the duplicates of a lattice point cover
// intervals on opposite sides of it (off by one), and the far-corner duplicates have no area.
//
// The r + 1 texels with i + j = r of each face cover no area (only lattice points on the edge
// α + β = 1 map to them), so no rendering residual depends on them. This term ties them to their
// in-face neighbours (i−1, r−i) and (i, r−i−1), so the solver sets them to a smooth continuation
// of the texels around them instead of leaving them at their initial values (and the normal
// equations stay non-singular for them).
#ifndef SFT_COST_FUNCTIONS_TEXEL_SMOOTHNESS_H_
#define SFT_COST_FUNCTIONS_TEXEL_SMOOTHNESS_H_

#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>

#include <cmath>
#include <string>
#include <vector>

#include "src/geometry/mesh.h"

namespace sft {

// The cost function of one pair (see the top comment); kChannels = 3 (albedo) or 1 (roughness).
template <int kChannels>
class TexelDifferenceCost : public ceres::SizedCostFunction<kChannels, kChannels, kChannels> {
 public:
  explicit TexelDifferenceCost(double weight) : weight_(weight) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int c = 0; c < kChannels; ++c) {
      residuals[c] = weight_ * (parameters[0][c] - parameters[1][c]);
    }
    if (jacobians == nullptr) return true;
    for (int block = 0; block < 2; ++block) {
      if (jacobians[block] == nullptr) continue;
      const double scale = block == 0 ? weight_ : -weight_;
      for (int e = 0; e < kChannels * kChannels; ++e) {
        jacobians[block][e] = (e % (kChannels + 1) == 0) ? scale : 0.0;
      }
    }
    return true;
  }

 private:
  double weight_;
};

// The log-ratio form's reference value (where it matches the linear form) and offset.
constexpr double kLogRatioReference = 0.5;
constexpr double kLogRatioEpsilon = 1e-3;

// The cost function of one pair in the log-ratio form (see the top comment).
template <int kChannels>
class TexelLogRatioCost : public ceres::SizedCostFunction<kChannels, kChannels, kChannels> {
 public:
  explicit TexelLogRatioCost(double weight) : scale_(weight * kLogRatioReference) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int c = 0; c < kChannels; ++c) {
      residuals[c] = scale_ * (std::log(parameters[0][c] + kLogRatioEpsilon) -
                               std::log(parameters[1][c] + kLogRatioEpsilon));
    }
    if (jacobians == nullptr) return true;
    for (int block = 0; block < 2; ++block) {
      if (jacobians[block] == nullptr) continue;
      const double sign = block == 0 ? 1.0 : -1.0;
      for (int e = 0; e < kChannels * kChannels; ++e) jacobians[block][e] = 0.0;
      for (int c = 0; c < kChannels; ++c) {
        jacobians[block][c * (kChannels + 1)] =
            sign * scale_ / (parameters[block][c] + kLogRatioEpsilon);
      }
    }
    return true;
  }

 private:
  double scale_;  // w · kLogRatioReference.
};

// Two neighbouring texels, as global mesh-colors texel indices.
struct TexelPair {
  int a = -1;
  int b = -1;
  bool cross_face = false;  // true when a and b belong to different faces.
};

// Every neighbouring pair of `mesh`'s texels at mesh-colors resolution `resolution` (≥ 0), as
// described above: first the in-face pairs face by face, then the cross-edge pairs edge by edge.
std::vector<TexelPair> TexelNeighbourPairs(const TriMesh& mesh, int resolution);

struct TexelSmoothnessOptions {
  // w of in-face pairs; finite, ≥ 0. Residuals have the units of the texel values.
  double weight = 1.0;
  // Multiplies w for cross-face pairs; finite, ≥ 0 (1 = the same smoothness across edges).
  double cross_face_weight = 1.0;
  // The log-ratio form instead of the difference (top comment): for values whose overall scale
  // another fitted parameter can take over.
  bool log_ratio = false;

  bool Check(std::string* why) const;
};

// Adds one TexelDifferenceCost<channels> (TexelLogRatioCost<channels> with log_ratio) block per
// pair to `problem` (which takes ownership). `texel_blocks[k]` is texel k's parameter block of
// `channels` doubles; channels is 1 or 3 and pairs index into texel_blocks (CHECK). Pairs with zero
// weight are skipped. Returns the number of blocks added.
int AddTexelSmoothness(const std::vector<TexelPair>& pairs, int channels,
                       const TexelSmoothnessOptions& options,
                       const std::vector<double*>& texel_blocks, ceres::Problem* problem);

}  // namespace sft

#endif  // SFT_COST_FUNCTIONS_TEXEL_SMOOTHNESS_H_
