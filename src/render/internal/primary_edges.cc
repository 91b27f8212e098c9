// Primary edges: the projection of every mesh edge where the image is discontinuous —
// silhouettes (adjacent faces facing opposite ways from the camera), boundary and non-manifold
// edges, and creases (flat shading only: any edge whose faces are not coplanar; smooth shading is
// continuous across them). See edge_sampling.h.
#include <algorithm>
#include <cmath>

#include "src/render/internal/edge_sampling.h"

namespace sft {
namespace render_internal {
namespace {

// Relative sampling density of a primary edge, ∝ the size of the jump expected across it:
// 1 where the image may jump to something unrelated (silhouettes, boundary, non-manifold and
// degenerate-neighbour edges); for a crease between faces with unit normals n0, n1 the
// flat-shaded radiance jumps by about |∂L/∂n|·|n0 − n1|, so |n0 − n1| (at least 1/16, because a
// glossy highlight makes ∂L/∂n large). Any positive density leaves the estimator unbiased (the
// pdf includes it); this one spends the samples where the derivative is.
double PrimaryEdgeImportance(const RenderScene& scene, const MeshEdge& edge,
                             const Eigen::Vector3d& eye) {
  if (edge.num_faces != 2) return 1.0;
  Eigen::Vector3d n0, n1;
  ConsistentEdgeNormals(scene, edge, &n0, &n1);
  if (n0.isZero() || n1.isZero()) return 1.0;
  const Eigen::Vector3d to_eye = eye - scene.positions()[edge.v0];
  if ((n0.dot(to_eye) > 0.0) != (n1.dot(to_eye) > 0.0)) return 1.0;
  return std::clamp((n0 - n1).norm(), 1.0 / 16.0, 1.0);
}

// Relative depth margin by which a surface must lie in front of an edge's own face, along a side
// ray, to count as hiding the edge (not just float noise of Embree's single-precision t).
constexpr double kEdgeOcclusionMargin = 1e-5;

// The face of `edge` that the camera ray center + t·dir, passing just beside the edge, meets on
// its own side of the edge: among the edge's faces lying on that side of the plane through the
// centre and the edge (one each for a crease, both for a silhouette, none on a silhouette's outer
// side), the one whose plane the ray meets first — the one in front. On success *hit is that
// ray's hit on the face's plane, its barycentrics clamped to the triangle (the ray passes within
// a hair of the edge, so the clamp moves the point by at most that much).
bool EdgeFaceHit(const RenderScene& scene, const MeshEdge& edge, const Eigen::Vector3d& center,
                 const Eigen::Vector3d& dir, RayHit* hit) {
  if (edge.num_faces != 1 && edge.num_faces != 2) return false;
  const auto& positions = scene.positions();
  const Eigen::Vector3d& a = positions[edge.v0];
  const Eigen::Vector3d edge_plane = (a - center).cross(positions[edge.v1] - center);
  const double ray_side = edge_plane.dot(dir);
  hit->hit = false;
  for (const int face : {edge.f0, edge.f1}) {
    if (face < 0) continue;
    const Eigen::Vector3i& corners = scene.faces()[face];
    int third = 0;
    while (third < 2 && (scene.WeldedVertex(corners[third]) == edge.v0 ||
                         scene.WeldedVertex(corners[third]) == edge.v1)) {
      ++third;
    }
    if (edge_plane.dot(positions[corners[third]] - center) * ray_side <= 0.0) continue;
    const Eigen::Vector3d n = scene.FaceNormal(face);
    const double t = n.dot(a - center) / n.dot(dir);
    if (!(t > 0.0) || !std::isfinite(t) || (hit->hit && t >= hit->t)) continue;
    // Barycentrics of x = center + t·dir: x − p0 = u·e1 + v·e2, N = e1 × e2.
    const Eigen::Vector3d& p0 = positions[corners[0]];
    const Eigen::Vector3d e1 = positions[corners[1]] - p0, e2 = positions[corners[2]] - p0;
    const Eigen::Vector3d normal = e1.cross(e2);
    const double norm2 = normal.squaredNorm();
    if (!(norm2 > 0.0)) continue;
    const Eigen::Vector3d x = center + t * dir - p0;
    double u = std::max(0.0, x.cross(e2).dot(normal) / norm2);
    double v = std::max(0.0, e1.cross(x).dot(normal) / norm2);
    if (u + v > 1.0) {
      const double sum = u + v;
      u /= sum;
      v /= sum;
    }
    hit->hit = true;
    hit->t = t;
    hit->face = face;
    hit->u = u;
    hit->v = v;
  }
  return hit->hit;
}

// L(q − εm) − L(q + εm) across primary edge `edge` at image point q, for camera paths with the
// same random numbers on both sides. Zero without tracing paths when the edge is hidden there:
// both sides see the same face (or nothing), or a side sees a surface in front of the edge's own
// face on that side.
//
// A side ray must see the edge's face on its side (EdgeFaceHit) for the difference to be this
// edge's jump. Where that face is narrower than ε in the image — near a vertex where another
// edge of the face meets this one at a small angle, as for the nearly edge-on faces along a
// silhouette — the ray passes it and lands on whatever lies beyond the other edge (a
// neighbouring face, the background), so the difference would be the jump across both edges,
// and the other edge's jump, sampled on its own, would be counted twice. That side is then
// shaded on the face itself (the ray's hit on its plane); see docs/design-notes.md ("Silhouette
// bias") and VertexDerivativesTest.SilhouetteAgainstBackgroundMatchesExactAreaDerivative.
Eigen::Vector3d PrimaryJump(const EdgeView& view, const MeshEdge& edge, const Eigen::Vector2d& q,
                            const Eigen::Vector2d& m, const Sampler& sampler, RenderStats* stats) {
  const Context& ctx = view.ctx;
  const Eigen::Vector3d& center = view.center;
  Eigen::Vector3d dirs[2];
  RayHit hits[2];
  view.TraceSides(q, m, dirs, hits, stats);
  for (int i = 0; i < 2; ++i) {
    RayHit own;
    if (!EdgeFaceHit(ctx.scene, edge, center, dirs[i], &own)) continue;
    if (hits[i].hit && hits[i].face == own.face) continue;
    if (hits[i].hit && hits[i].face != edge.f0 && hits[i].face != edge.f1 &&
        hits[i].t < own.t * (1.0 - kEdgeOcclusionMargin)) {
      return Eigen::Vector3d::Zero();
    }
    hits[i] = own;
  }
  if (hits[0].hit == hits[1].hit && (!hits[0].hit || hits[0].face == hits[1].face)) {
    return Eigen::Vector3d::Zero();
  }
  return SideRadianceJump(ctx, dirs, hits, sampler, stats);
}

// Primary edges in view, weighted by projected length (+ 1e-3 px) × PrimaryEdgeImportance.
std::vector<EdgeCandidate> PrimaryEdgeCandidates(const EdgeView& view) {
  const RenderScene& scene = view.ctx.scene;
  const auto& positions = scene.positions();
  const auto& edges = scene.edges();
  std::vector<EdgeCandidate> candidates;
  // Smooth shading is continuous across creases: only silhouettes (and boundaries) jump.
  const bool flat = view.ctx.options.shading == Shading::kFlat;
  for (size_t e = 0; e < edges.size(); ++e) {
    const MeshEdge& edge = edges[e];
    const Eigen::Vector3d& a = positions[edge.v0];
    const Eigen::Vector3d& b = positions[edge.v1];
    if (a == b || !IsDiscontinuityEdge(scene, edge, view.center, /*creases=*/flat)) continue;
    double s0, s1, length;
    if (!view.ClippedImageLength(a, b, &s0, &s1, &length) || !std::isfinite(length)) continue;
    candidates.push_back({static_cast<int>(e), s0, s1,
                          (length + 1e-3) * PrimaryEdgeImportance(scene, edge, view.center)});
  }
  return candidates;
}

}  // namespace

void AddPrimaryEdgeTerms(const EdgeView& view, std::vector<EdgeEntry>* entries) {
  const Context& ctx = view.ctx;
  const double ratio = ctx.request->primary_edge_ratio;
  if (!(ratio > 0.0)) return;
  const RenderScene& scene = ctx.scene;
  const RenderOptions& options = ctx.options;
  const auto sample_primary = [&](const EdgeCandidate& candidate, double s, double inv_pdf,
                                  const Sampler& sampler, std::vector<EdgeEntry>* out) {
    RenderStats& local = view.thread_stats.local();
    const MeshEdge& edge = scene.edges()[candidate.edge];
    const Eigen::Vector3d& a = scene.positions()[edge.v0];
    const Eigen::Vector3d& b = scene.positions()[edge.v1];
    EmitCurveSample(
        view, a + s * (b - a), inv_pdf, options.spp,
        [&](const Eigen::Matrix<double, 2, 3>& d_q) { return (d_q * (b - a)).eval(); },
        [&](const Eigen::Vector2d& q, const Eigen::Vector2d& m) {
          return PrimaryJump(view, edge, q, m, sampler, &local);
        },
        [&](const Eigen::Vector3d& m_row, BoundaryRows* rows) {
          AddEdgePointRows(scene, edge, s, m_row, rows);
        },
        &local, out);
  };
  const int64_t num_samples = static_cast<int64_t>(std::ceil(ratio * options.spp * view.pixels));
  SampleCandidates(options, PrimaryEdgeCandidates(view), num_samples, kPrimaryEdgeKey,
                   ctx.view.view_index, sample_primary, entries);
}

}  // namespace render_internal
}  // namespace sft
