#include "src/render/internal/texel_edges.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>

#include "src/core/rng.h"

namespace sft {
namespace render_internal {
namespace {

// Texel look-ups either side of a texel boundary are made this far from it (barycentric units;
// far above MeshColors' lattice snap of 1e-9 texels, far below a texel).
constexpr double kTexelSideOffset = 1e-6;

// A texel boundary segment to sample over s ∈ [s0, s1] (the part in view): the points
// Σ_k b_k(s)·p_k of the segment's face (corners p_k), b(s) = b0 + s·(b1 − b0) (TexelSegment).
struct TexelCandidate {
  const TexelSegment* segment;  // in the TexelSegments set, which outlives the candidates.
  double s0, s1;
  double weight;
};

// L(q − εm) − L(q + εm) across a texel boundary between faces `face_a` and `face_b` (equal for a
// grid line inside a face). Zero without tracing paths unless the two sides see these faces, one
// each: otherwise the boundary is hidden at q, or q is where it meets a face border (where the
// primary edge term, if any, takes over).
Eigen::Vector3d TexelJump(const EdgeView& view, const Eigen::Vector2d& q, const Eigen::Vector2d& m,
                          int face_a, int face_b, const Sampler& sampler, RenderStats* stats) {
  Eigen::Vector3d dirs[2];
  RayHit hits[2];
  view.TraceSides(q, m, dirs, hits, stats);
  if (!hits[0].hit || !hits[1].hit) return Eigen::Vector3d::Zero();
  const bool seen = (hits[0].face == face_a && hits[1].face == face_b) ||
                    (hits[0].face == face_b && hits[1].face == face_a);
  if (!seen) return Eigen::Vector3d::Zero();
  return SideRadianceJump(view.ctx, dirs, hits, sampler, stats);
}

// Interior lines k/r (0 < k < r) of the albedo and the roughness texel grids, sorted; a line of
// both grids (equal fractions) appears once.
std::vector<double> TexelGridLines(const Material& material) {
  std::vector<double> lines;
  for (const int r : {material.albedo.resolution(), material.roughness.resolution()}) {
    for (int k = 1; k < r; ++k) lines.push_back(static_cast<double>(k) / r);
  }
  std::sort(lines.begin(), lines.end());
  // Distinct fractions k/r ≠ k'/r' differ by at least 1/(r·r'), far above 1e-9.
  lines.erase(
      std::unique(lines.begin(), lines.end(), [](double a, double b) { return b - a < 1e-9; }),
      lines.end());
  return lines;
}

// Whether the texels of `face` are not all equal.
bool FaceTexelsVary(const MeshColors& colors, int face) {
  const int n = MeshColors::TexelsPerFace(colors.resolution());
  const double* first = colors.texel(face * n);
  for (int k = 1; k < n; ++k) {
    const double* texel = colors.texel(face * n + k);
    for (int c = 0; c < colors.channels(); ++c) {
      if (texel[c] != first[c]) return true;
    }
  }
  return false;
}

// Size of the material jump between the barycentric points ab_a of face_a and ab_b of face_b:
// the mean absolute albedo difference over RGB plus, when the glossy lobe is on, the absolute
// roughness difference (without it roughness changes nothing). Zero when the two points look
// the same. It only weights the sampling (the pdf accounts for it), so any scale will do.
double MaterialJump(const Material& material, bool glossy, int face_a, const Eigen::Vector2d& ab_a,
                    int face_b, const Eigen::Vector2d& ab_b) {
  const double* a = material.albedo.texel(material.albedo.TexelIndex(face_a, ab_a.x(), ab_a.y()));
  const double* b = material.albedo.texel(material.albedo.TexelIndex(face_b, ab_b.x(), ab_b.y()));
  double size = (std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2])) / 3.0;
  if (glossy) {
    size += std::abs(
        *material.roughness.texel(material.roughness.TexelIndex(face_a, ab_a.x(), ab_a.y())) -
        *material.roughness.texel(material.roughness.TexelIndex(face_b, ab_b.x(), ab_b.y())));
  }
  return std::isfinite(size) ? size : 0.0;
}

Eigen::Vector3d Barycentrics(const Eigen::Vector2d& ab) {
  return Eigen::Vector3d(1.0 - ab.x() - ab.y(), ab.x(), ab.y());
}

// The grid-line pieces inside the faces whose texels vary (TexelSegments).
void AddGridLineSegments(const RenderScene& scene, const Material& material, bool glossy,
                         const std::vector<double>& lines, std::vector<TexelSegment>* out) {
  const auto& faces = scene.faces();
  auto barycentrics = Barycentrics;
  std::vector<TexelSegment>& segments = *out;
  std::vector<double> cuts;
  // Grid lines inside the faces: α = a (axis 0) or β = a (axis 1), the other coordinate t over
  // [0, 1 − a], cut where the other grid lines cross.
  for (size_t f = 0; f < faces.size(); ++f) {
    const int face = static_cast<int>(f);
    if (scene.FaceNormal(face).isZero()) continue;
    if (!FaceTexelsVary(material.albedo, face) &&
        !(glossy && FaceTexelsVary(material.roughness, face))) {
      continue;
    }
    for (const double a : lines) {
      const double extent = 1.0 - a;
      cuts.assign(1, 0.0);
      for (const double c : lines) {
        if (c < extent - 1e-9) cuts.push_back(c);  // lines ending on this one: not a cut.
      }
      cuts.push_back(extent);
      for (int axis = 0; axis < 2; ++axis) {
        // (α, β) of the point at distance `across` from the line's axis and `along` it.
        auto ab = [axis](double across, double along) {
          return axis == 0 ? Eigen::Vector2d(across, along) : Eigen::Vector2d(along, across);
        };
        for (size_t k = 0; k + 1 < cuts.size(); ++k) {
          const double mid = 0.5 * (cuts[k] + cuts[k + 1]);
          const double size = MaterialJump(material, glossy, face, ab(a - kTexelSideOffset, mid),
                                           face, ab(a + kTexelSideOffset, mid));
          if (!(size > 0.0)) continue;
          const Eigen::Vector3d b0 = barycentrics(ab(a, cuts[k]));
          const Eigen::Vector3d b1 = barycentrics(ab(a, cuts[k + 1]));
          segments.push_back({face, face, -1, b0, b1, size, b0, b1});
        }
      }
    }
  }
}

// The pieces of edges between coplanar faces (TexelSegments).
void AddCoplanarEdgeSegments(const RenderScene& scene, const Material& material, bool glossy,
                             const std::vector<double>& lines, std::vector<TexelSegment>* out) {
  const auto& faces = scene.faces();
  const auto& positions = scene.positions();
  std::vector<TexelSegment>& segments = *out;
  std::vector<double> cuts;
  // Edges between coplanar faces (the others are mesh edges, sampled as such, whose jump
  // includes the material's), cut at the grid lines' crossings t = k/r (the same on every edge).
  cuts.assign(1, 0.0);
  cuts.insert(cuts.end(), lines.begin(), lines.end());
  cuts.push_back(1.0);
  for (size_t e = 0; e < scene.edges().size(); ++e) {
    const MeshEdge& edge = scene.edges()[e];
    if (edge.num_faces != 2 || positions[edge.v0] == positions[edge.v1]) continue;
    Eigen::Vector3d n0, n1;
    ConsistentEdgeNormals(scene, edge, &n0, &n1);
    if (n0.isZero() || n1.isZero() || !(n0.dot(n1) >= 1.0 - 1e-12)) continue;
    // Per face (0: f0, 1: f1): the barycentric unit vectors of the edge's ends and of the
    // opposite corner.
    const int side_faces[2] = {edge.f0, edge.f1};
    Eigen::Vector3d end0[2], end1[2], opposite[2];
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector3i& corners = faces[side_faces[i]];
      for (int k = 0; k < 3; ++k) {
        const int welded = scene.WeldedVertex(corners[k]);
        end0[i][k] = welded == edge.v0 ? 1.0 : 0.0;
        end1[i][k] = welded == edge.v1 ? 1.0 : 0.0;
        opposite[i][k] = welded != edge.v0 && welded != edge.v1 ? 1.0 : 0.0;
      }
    }
    for (size_t k = 0; k + 1 < cuts.size(); ++k) {
      const double mid = 0.5 * (cuts[k] + cuts[k + 1]);
      Eigen::Vector2d ab[2];
      for (int i = 0; i < 2; ++i) {
        // The edge point, moved slightly into face i so that it looks up that face's texel.
        const Eigen::Vector3d b =
            (1.0 - kTexelSideOffset) * ((1.0 - mid) * end0[i] + mid * end1[i]) +
            kTexelSideOffset * opposite[i];
        ab[i] = Eigen::Vector2d(b[1], b[2]);
      }
      const double size = MaterialJump(material, glossy, edge.f0, ab[0], edge.f1, ab[1]);
      if (!(size > 0.0)) continue;
      segments.push_back({edge.f0, edge.f1, static_cast<int>(e),
                          (1.0 - cuts[k]) * end0[0] + cuts[k] * end1[0],
                          (1.0 - cuts[k + 1]) * end0[0] + cuts[k + 1] * end1[0], size,
                          (1.0 - cuts[k]) * end0[1] + cuts[k] * end1[1],
                          (1.0 - cuts[k + 1]) * end0[1] + cuts[k + 1] * end1[1]});
    }
  }
}

}  // namespace

void AddTexelPointRows(const RenderScene& scene, int face, int other, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c, const Eigen::Vector3d& row, BoundaryRows* out) {
  const Eigen::Vector3i& corners = scene.faces()[face];
  if (other == face) {
    for (int k = 0; k < 3; ++k) out->Add(corners[k], b[k] * row);
    return;
  }
  const Eigen::Vector3i& other_corners = scene.faces()[other];
  Eigen::Vector3d own = 0.5 * b, across = 0.5 * c;
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) {
      if (other_corners[j] == corners[k]) {
        own[k] += across[j];
        across[j] = 0.0;
      }
    }
  }
  for (int k = 0; k < 3; ++k) out->Add(corners[k], own[k] * row);
  for (int j = 0; j < 3; ++j) {
    if (across[j] != 0.0) out->Add(other_corners[j], across[j] * row);
  }
}

void TexelSegmentEnds(const RenderScene& scene, const TexelSegment& segment, Eigen::Vector3d* y0,
                      Eigen::Vector3d* y1) {
  const Eigen::Vector3i& corners = scene.faces()[segment.face];
  y0->setZero();
  y1->setZero();
  for (int k = 0; k < 3; ++k) {
    *y0 += segment.b0[k] * scene.positions()[corners[k]];
    *y1 += segment.b1[k] * scene.positions()[corners[k]];
  }
}

namespace {

std::vector<TexelSegment> BuildTexelSegments(const RenderScene& scene, const Material& material,
                                             bool glossy) {
  std::vector<TexelSegment> segments;
  const std::vector<double> lines = TexelGridLines(material);
  if (lines.empty()) return segments;
  AddGridLineSegments(scene, material, glossy, lines, &segments);
  AddCoplanarEdgeSegments(scene, material, glossy, lines, &segments);
  return segments;
}

// A 64-bit fingerprint of everything BuildTexelSegments reads: the mesh state (faces and
// positions decide which edges are coplanar), both mesh-colors grids and their values, and
// `glossy`.
uint64_t SegmentsKey(const RenderScene& scene, const Material& material, bool glossy) {
  uint64_t key = Mix64(glossy ? 0x6C055Eull : 0xD1FF05Eull);
  // Four independent lanes over consecutive words, folded at the end: the same fingerprint
  // quality at about a quarter of one chain's latency (the material's texels are tens of MB, and
  // every view's passes ask for the key).
  const auto add_bits = [&key](const void* data, size_t bytes) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    uint64_t lane[4] = {key, Mix64(key ^ 1), Mix64(key ^ 2), Mix64(key ^ 3)};
    size_t i = 0;
    for (; i + 32 <= bytes; i += 32) {
      uint64_t words[4];
      std::memcpy(words, p + i, 32);
      for (int k = 0; k < 4; ++k) lane[k] = Mix64(lane[k] ^ words[k]);
    }
    key = Mix64(lane[0] ^ Mix64(lane[1] ^ Mix64(lane[2] ^ Mix64(lane[3]))));
    for (; i + 8 <= bytes; i += 8) {
      uint64_t word;
      std::memcpy(&word, p + i, 8);
      key = Mix64(key ^ word);
    }
    for (; i < bytes; ++i) key = Mix64(key ^ p[i]);
    key = Mix64(key ^ bytes);
  };
  const uint64_t state = scene.state_id();
  add_bits(&state, sizeof(state));
  for (const MeshColors* colors : {&material.albedo, &material.roughness}) {
    const int shape[2] = {colors->num_faces(), colors->resolution()};
    add_bits(shape, sizeof(shape));
    add_bits(colors->values().data(), colors->values().size() * sizeof(double));
  }
  return key;
}

}  // namespace

std::shared_ptr<const std::vector<TexelSegment>> TexelSegments(const RenderScene& scene,
                                                               const Material& material,
                                                               bool glossy) {
  // A bilinear UV texture is continuous inside every face: no texel boundaries (texel_edges.h).
  if (material.has_uv_textures()) return std::make_shared<const std::vector<TexelSegment>>();
  // The last build, shared by every view of a pass, by both passes of an evaluation and by the
  // direct and secondary terms of a view, until the mesh state or material changes.
  static std::mutex mutex;
  static uint64_t cached_key = 0;
  static std::shared_ptr<const std::vector<TexelSegment>> cached;
  const uint64_t key = SegmentsKey(scene, material, glossy);
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (cached != nullptr && cached_key == key) return cached;
  }
  auto built = std::make_shared<const std::vector<TexelSegment>>(
      BuildTexelSegments(scene, material, glossy));
  std::lock_guard<std::mutex> lock(mutex);
  cached_key = key;
  cached = built;
  return built;
}

namespace {

// Texel boundaries in view (those not on primary edges), clipped to the frustum, weighted by
// projected length × material jump.
std::vector<TexelCandidate> TexelCandidates(const EdgeView& view,
                                            const std::vector<TexelSegment>& segments) {
  const RenderScene& scene = view.ctx.scene;
  std::vector<TexelCandidate> candidates;
  candidates.reserve(segments.size());
  for (const TexelSegment& segment : segments) {
    // A coplanar edge seen edge-on from the camera is a primary edge there.
    if (segment.edge >= 0 &&
        IsDiscontinuityEdge(scene, scene.edges()[segment.edge], view.center,
                            /*creases=*/view.ctx.options.shading == Shading::kFlat)) {
      continue;
    }
    Eigen::Vector3d y0, y1;
    TexelSegmentEnds(scene, segment, &y0, &y1);
    double s0, s1, length;
    if (!view.ClippedImageLength(y0, y1, &s0, &s1, &length)) continue;
    const double weight = length * segment.size;
    if (!(weight > 0.0) || !std::isfinite(weight)) continue;
    candidates.push_back({&segment, s0, s1, weight});
  }
  return candidates;
}

}  // namespace

void AddTexelEdgeTerms(const EdgeView& view, std::vector<EdgeEntry>* entries) {
  const Context& ctx = view.ctx;
  const double ratio = ctx.request->texel_edge_ratio;
  if (!(ratio > 0.0)) return;
  const RenderScene& scene = ctx.scene;
  const RenderOptions& options = ctx.options;
  const auto& positions = scene.positions();
  const auto sample_texel = [&](const TexelCandidate& candidate, double s, double inv_pdf,
                                const Sampler& sampler, std::vector<EdgeEntry>* out) {
    const TexelSegment& segment = *candidate.segment;
    RenderStats& local = view.thread_stats.local();
    const Eigen::Vector3i& corners = scene.faces()[segment.face];
    const Eigen::Vector3d b = segment.b0 + s * (segment.b1 - segment.b0);
    const Eigen::Vector3d db_ds = segment.b1 - segment.b0;
    Eigen::Vector3d y = Eigen::Vector3d::Zero(), dy_ds = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      y += b[k] * positions[corners[k]];
      dy_ds += db_ds[k] * positions[corners[k]];
    }
    EmitCurveSample(
        view, y, inv_pdf, options.spp,
        [&](const Eigen::Matrix<double, 2, 3>& d_q) { return (d_q * dy_ds).eval(); },
        [&](const Eigen::Vector2d& q, const Eigen::Vector2d& m) {
          return TexelJump(view, q, m, segment.face, segment.other, sampler, &local);
        },
        [&](const Eigen::Vector3d& m_row, BoundaryRows* rows) {
          // ∂y/∂p_k = b_k·I.
          const Eigen::Vector3d c = segment.c0 + s * (segment.c1 - segment.c0);
          AddTexelPointRows(scene, segment.face, segment.other, b, c, m_row, rows);
        },
        &local, out);
  };
  const int64_t num_samples = static_cast<int64_t>(std::ceil(ratio * options.spp * view.pixels));
  // Held for the candidates, which point into the set.
  const std::shared_ptr<const std::vector<TexelSegment>> segments =
      TexelSegments(scene, ctx.material, ctx.material.specular * ctx.specular_scale > 0.0);
  SampleCandidates(options, TexelCandidates(view, *segments), num_samples, kTexelEdgeKey,
                   ctx.view.view_index, sample_texel, entries);
}

}  // namespace render_internal
}  // namespace sft
