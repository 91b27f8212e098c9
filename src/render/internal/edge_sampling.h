// Internal to src/render: what the boundary (edge) terms of vertex derivatives share (Li et al.
// 2018, "Differentiable Monte Carlo ray tracing through edge sampling", §3–4). The pixel integral
// I = ∫_pixel L(q) dq has, besides the interior term, a boundary term wherever L jumps along a
// curve in the image that moves with the vertices:
//   ∂I/∂θ += ∫_curve (L(q⁻) − L(q⁺)) · (m·∂q/∂θ) dl,
// m the curve's unit normal, q± the sides q ± εm. The curves (see the table in derivatives.h):
// primary edges (primary_edges.cc), point-light shadow edges (shadow_edges.cc) and texel
// boundaries (texel_edges.cc) seen directly by the camera; the same kinds of curves seen from
// path vertices are secondary edges (secondary_edges.cc).
// Sampling of the image curves: a curve is chosen with probability ∝ its weight (its projected
// length, angle at the light, or projected length × material jump), a point uniformly in its
// parameter s, stratified over all samples (SampleCandidates); the estimator is
// ΔL·(m·∂q/∂θ)·|dq/ds|/pdf, credited to the pixel holding q (EmitCurveSample). Both sides are
// traced with the same random numbers, so away from a real jump ΔL is (nearly) zero.
#ifndef SFT_RENDER_INTERNAL_EDGE_SAMPLING_H_
#define SFT_RENDER_INTERNAL_EDGE_SAMPLING_H_

#include <glog/logging.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "src/core/rng.h"
#include "src/render/internal/context.h"
#include "src/render/internal/fp_mode.h"
#include "src/render/internal/path_derivatives.h"
#include "src/render/internal/sampling.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {
namespace render_internal {

// Sides of an edge point are traced this far from it (pixels).
constexpr double kEdgeSideOffset = 1e-3;
// Edge samples are drawn and reduced in chunks of this many (deterministic for any threads).
constexpr int kEdgeChunk = 1024;
// Sample streams of edge samples are told apart from pixel samples by these keys.
constexpr uint64_t kPrimaryEdgeKey = 0xE1D6E00000000000ull;
constexpr uint64_t kShadowEdgeKey = 0xE1D6500000000000ull;
constexpr uint64_t kTexelEdgeKey = 0xE1D6700000000000ull;

// One boundary-term contribution: pixel, parameter, ∂RGB (already divided by the sample count).
struct EdgeEntry {
  int pixel;
  int param;
  Eigen::Vector3d d;
};

// A curve to sample: mesh edge `edge` over the parameter range [s0, s1], with sampling weight.
struct EdgeCandidate {
  int edge;
  double s0, s1;
  double weight;
};

// The vertices that move a boundary point y, with rows_j = (∂y/∂p_j)ᵀ·row for a row vector `row`
// (some linear functional of y's motion). A vertex may appear more than once (the sums are what
// count).
struct BoundaryRows {
  static constexpr int kCapacity = 24;  // 2 × 8 edge-end copies (scene.cc) + 3 receiver corners.
  int count = 0;
  int vertices[kCapacity];
  Eigen::Vector3d rows[kCapacity];
  // A point light's position parameters that move y (point-light shadow boundaries): the first
  // of the three, −1 when none, and (∂y/∂parameters)ᵀ·row.
  int light_param = -1;
  Eigen::Vector3d light_row = Eigen::Vector3d::Zero();
  void Add(int vertex, const Eigen::Vector3d& row) {
    CHECK_LT(count, kCapacity);
    vertices[count] = vertex;
    rows[count++] = row;
  }
};

// Rows of the point a + s(b − a) of welded edge `edge`: each end moves with the copies of it that
// the edge's faces use, shared as EdgeCopy describes (one copy with weight 1 on a welded mesh).
void AddEdgePointRows(const RenderScene& scene, const MeshEdge& edge, double s,
                      const Eigen::Vector3d& row, BoundaryRows* out);

// The unit normals of a manifold edge's faces, f1's oriented consistently with f0's across the
// edge (MeshEdge::flip1), so that the classification below does not depend on face winding: two
// coplanar faces are coplanar whichever way each is wound.
void ConsistentEdgeNormals(const RenderScene& scene, const MeshEdge& edge, Eigen::Vector3d* n0,
                           Eigen::Vector3d* n1);

// Whether flat-shaded radiance can jump across the edge as seen from `eye`: boundary,
// non-manifold or degenerate-neighbour edges always; else silhouettes w.r.t. eye (the two faces,
// consistently oriented, face opposite ways) and (when `creases`) edges between faces that are
// not coplanar.
bool IsDiscontinuityEdge(const RenderScene& scene, const MeshEdge& edge, const Eigen::Vector3d& eye,
                         bool creases);

// The camera of one view as the image-curve terms see it, and their per-thread ray counters.
struct EdgeView {
  explicit EdgeView(const Context& ctx);
  const Context& ctx;
  Eigen::Vector3d center;  // camera centre, world frame.
  Eigen::Matrix3d world_from_cam_rotation;
  Eigen::Matrix3d cam_from_world_rotation;
  FrustumBounds frustum;
  double pixels;  // width × height.
  mutable tbb::enumerable_thread_specific<RenderStats> thread_stats;

  // Image point q, ∂q/∂y and pixel index of a world point y (false when behind the camera or
  // off the image).
  bool Project(const Eigen::Vector3d& y, Eigen::Vector2d* q, Eigen::Matrix<double, 2, 3>* d_q_d_y,
               int* pixel) const;
  // The part s ∈ [s0, s1] of the world segment a + s(b − a) inside the view frustum and its
  // length in the image (pixels); false when none of it is in view.
  bool ClippedImageLength(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double* s0,
                          double* s1, double* length) const;
  // Directions of the camera rays through the two sides q ∓ εm of an image point q (index 0: −).
  void SideDirections(const Eigen::Vector2d& q, const Eigen::Vector2d& m,
                      Eigen::Vector3d dirs[2]) const;
  // The camera rays through the two sides q ∓ εm of a curve point and their first hits.
  void TraceSides(const Eigen::Vector2d& q, const Eigen::Vector2d& m, Eigen::Vector3d dirs[2],
                  RayHit hits[2], RenderStats* stats) const;
};

// L(q − εm) − L(q + εm) from the camera paths through the two side rays: one path shared by
// both sides when their hits have the same normal (TraceSharedSideJump: a texel boundary), else
// two full paths traced with the same random numbers so that only the jump remains (not finite
// when a side's radiance is not).
Eigen::Vector3d SideRadianceJump(const Context& ctx, const Eigen::Vector3d dirs[2],
                                 const RayHit hits[2], const Sampler& sampler, RenderStats* stats);

// Appends the entries jump·(row_j·∂q/∂vertex_j)·scale for the moving vertices of one sample (and
// the light position's, BoundaryRows::light_param). False, appending nothing, when one of them is
// not finite.
bool EmitBoundary(int pixel, const Eigen::Vector3d& jump, double scale, const BoundaryRows& rows,
                  std::vector<EdgeEntry>* out);

// One sample of an image curve at world point y: projects it (pixel q, ∂q/∂y), takes the curve's
// unit normal m from its image tangent dq/ds = `tangent`(∂q/∂y), the jump across it from
// `jump`(q, m), and emits jump·(m·∂q/∂y)-rows (`rows`(m·∂q/∂y, &rows)) × |dq/ds|·inv_pdf·spp.
// A sample whose jump or entries are not finite is dropped and counted in stats.
template <typename Tangent, typename Jump, typename Rows>
void EmitCurveSample(const EdgeView& view, const Eigen::Vector3d& y, double inv_pdf, int spp,
                     const Tangent& tangent, const Jump& jump, const Rows& rows, RenderStats* stats,
                     std::vector<EdgeEntry>* out) {
  Eigen::Vector2d q;
  Eigen::Matrix<double, 2, 3> d_q;
  int pixel;
  if (!view.Project(y, &q, &d_q, &pixel)) return;
  const Eigen::Vector2d dq_ds = tangent(d_q);
  const double speed = dq_ds.norm();
  if (!(speed > 0.0) || !std::isfinite(speed)) return;
  const Eigen::Vector2d m(-dq_ds.y() / speed, dq_ds.x() / speed);
  const Eigen::Vector3d delta = jump(q, m);
  if (delta.isZero()) return;
  const Eigen::Vector3d m_row = d_q.transpose() * m;  // m·∂q/∂y
  BoundaryRows boundary;
  rows(m_row, &boundary);
  if (!delta.allFinite() || !EmitBoundary(pixel, delta, speed * inv_pdf * spp, boundary, out)) {
    ++stats->nonfinite_samples;
  }
}

// Draws `num_samples` samples over the candidates (stratified over their concatenated weights)
// in parallel chunks and appends the entries in chunk order. `sample_one(candidate, s, inv_pdf,
// sampler, out)` evaluates one sample at parameter s, inv_pdf = 1/(pdf · num_samples).
template <typename Candidate, typename SampleOne>
void SampleCandidates(const RenderOptions& options, const std::vector<Candidate>& candidates,
                      int64_t num_samples, uint64_t key, uint64_t view_index,
                      const SampleOne& sample_one, std::vector<EdgeEntry>* entries) {
  if (candidates.empty() || num_samples <= 0) return;
  std::vector<double> weights(candidates.size());
  for (size_t i = 0; i < candidates.size(); ++i) weights[i] = candidates[i].weight;
  const DiscreteDistribution distribution(weights);
  if (distribution.empty()) return;
  const double total = distribution.total();
  const int64_t num_chunks = (num_samples + kEdgeChunk - 1) / kEdgeChunk;
  std::vector<std::vector<EdgeEntry>> chunks(num_chunks);
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(int64_t{0}, num_chunks, [&](int64_t chunk) {
      const ScopedTracingFpMode fp_mode;
      const int64_t end = std::min(num_samples, (chunk + 1) * kEdgeChunk);
      for (int64_t i = chunk * kEdgeChunk; i < end; ++i) {
        Sampler sampler(options.seed, view_index, key + static_cast<uint64_t>(i), 0);
        // Stratified over the concatenated curves: sample i lies in the i-th of N equal slices
        // of the total weight, so the points are spread evenly along all edges (the per-edge
        // integrals, which often cancel between opposite edges, then converge like a
        // quadrature rather than like independent Monte Carlo).
        const double u = (static_cast<double>(i) + sampler.Next1D()) / num_samples;
        const int c = distribution.SampleInverse(u);
        const Candidate& candidate = candidates[c];
        const double before = distribution.CumulativeBefore(c);
        const double local = std::clamp((u * total - before) / candidate.weight, 0.0, 1.0);
        const double s = candidate.s0 + local * (candidate.s1 - candidate.s0);
        // 1/pdf of (candidate, s) over the number of samples.
        const double inv_pdf = total / candidate.weight * (candidate.s1 - candidate.s0) /
                               static_cast<double>(num_samples);
        sample_one(candidate, s, inv_pdf, sampler, &chunks[chunk]);
      }
    });
  });
  for (const auto& chunk : chunks) entries->insert(entries->end(), chunk.begin(), chunk.end());
}

// Boundary terms of one view seen directly by the camera (primary edges, point-light shadow
// edges, texel boundaries; without vertex derivatives the shadow edges' light-position terms
// only), added to per-pixel lists scaled for the caller's 1/spp. With `parts`
// (each part layout-sized; the request has adjoint weights), each term's entries weighted by the
// adjoint weights of their pixel and 1/spp are also added to the term's part.
void AddEdgeTerms(const Context& ctx, std::vector<DerivativeList>* pixel_lists, RenderStats* stats,
                  GradientParts* parts = nullptr);

// The parts of AddEdgeTerms (primary_edges.cc, shadow_edges.cc, texel_edges.cc).
void AddPrimaryEdgeTerms(const EdgeView& view, std::vector<EdgeEntry>* entries);
void AddShadowEdgeTerms(const EdgeView& view, std::vector<EdgeEntry>* entries);
void AddTexelEdgeTerms(const EdgeView& view, std::vector<EdgeEntry>* entries);

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_EDGE_SAMPLING_H_
