#include "src/render/internal/edge_sampling.h"

#include <utility>

#include "src/render/internal/integrator.h"

namespace sft {
namespace render_internal {

void AddEdgePointRows(const RenderScene& scene, const MeshEdge& edge, double s,
                      const Eigen::Vector3d& row, BoundaryRows* out) {
  const EdgeCopy* copies = scene.edge_copies().data() + edge.first_copy;
  for (int i = 0; i < edge.num_copies0; ++i) {
    out->Add(copies[i].vertex, (copies[i].weight * (1.0 - s)) * row);
  }
  for (int i = edge.num_copies0; i < edge.num_copies0 + edge.num_copies1; ++i) {
    out->Add(copies[i].vertex, (copies[i].weight * s) * row);
  }
}

void ConsistentEdgeNormals(const RenderScene& scene, const MeshEdge& edge, Eigen::Vector3d* n0,
                           Eigen::Vector3d* n1) {
  *n0 = scene.FaceNormal(edge.f0);
  *n1 = edge.flip1 * scene.FaceNormal(edge.f1);
}

bool IsDiscontinuityEdge(const RenderScene& scene, const MeshEdge& edge, const Eigen::Vector3d& eye,
                         bool creases) {
  if (edge.num_faces != 2) return true;
  Eigen::Vector3d n0, n1;
  ConsistentEdgeNormals(scene, edge, &n0, &n1);
  if (n0.isZero() || n1.isZero()) return true;
  const Eigen::Vector3d to_eye = eye - scene.positions()[edge.v0];
  if ((n0.dot(to_eye) > 0.0) != (n1.dot(to_eye) > 0.0)) return true;
  return creases && std::abs(n0.dot(n1)) < 1.0 - 1e-12;
}

EdgeView::EdgeView(const Context& context) : ctx(context) {
  const Rigid3d world_from_cam = ctx.view.cam_from_world.Inverse();
  center = world_from_cam.translation;
  world_from_cam_rotation = world_from_cam.rotation.toRotationMatrix();
  cam_from_world_rotation = world_from_cam_rotation.transpose();
  frustum = ViewFrustum(ctx.view.camera, ctx.scene.extent());
  pixels = static_cast<double>(ctx.view.camera.width) * ctx.view.camera.height;
}

bool EdgeView::Project(const Eigen::Vector3d& y, Eigen::Vector2d* q,
                       Eigen::Matrix<double, 2, 3>* d_q_d_y, int* pixel) const {
  const Camera& camera = ctx.view.camera;
  const Eigen::Vector3d p_in_cam = ctx.view.cam_from_world * y;
  if (!(p_in_cam.z() > 0.0)) return false;
  *q = camera.ImageFromCam(p_in_cam);
  if (!(q->x() >= 0.0 && q->y() >= 0.0 && q->x() < camera.width && q->y() < camera.height)) {
    return false;
  }
  *d_q_d_y = camera.ImageFromCamJacobian(p_in_cam) * cam_from_world_rotation;
  *pixel = static_cast<int>(q->y()) * camera.width + static_cast<int>(q->x());
  return true;
}

bool EdgeView::ClippedImageLength(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double* s0,
                                  double* s1, double* length) const {
  const Camera& camera = ctx.view.camera;
  const Eigen::Vector3d a_cam = ctx.view.cam_from_world * a;
  const Eigen::Vector3d b_cam = ctx.view.cam_from_world * b;
  if (!ClipSegment(a_cam, b_cam, frustum, s0, s1)) return false;
  const Eigen::Vector2d q0 = camera.ImageFromCam(a_cam + *s0 * (b_cam - a_cam));
  const Eigen::Vector2d q1 = camera.ImageFromCam(a_cam + *s1 * (b_cam - a_cam));
  *length = (q1 - q0).norm();
  return true;
}

void EdgeView::SideDirections(const Eigen::Vector2d& q, const Eigen::Vector2d& m,
                              Eigen::Vector3d dirs[2]) const {
  for (int i = 0; i < 2; ++i) {
    const double side = i == 0 ? -1.0 : 1.0;
    dirs[i] =
        (world_from_cam_rotation * ctx.view.camera.CamFromImage(q + side * kEdgeSideOffset * m))
            .normalized();
  }
}

void EdgeView::TraceSides(const Eigen::Vector2d& q, const Eigen::Vector2d& m,
                          Eigen::Vector3d dirs[2], RayHit hits[2], RenderStats* stats) const {
  SideDirections(q, m, dirs);
  for (int i = 0; i < 2; ++i) hits[i] = ctx.scene.Intersect(center, dirs[i], 0.0, kInfinity);
  stats->camera_rays += 2;
}

Eigen::Vector3d SideRadianceJump(const Context& ctx, const Eigen::Vector3d dirs[2],
                                 const RayHit hits[2], const Sampler& sampler, RenderStats* stats) {
  Eigen::Vector3d jump = Eigen::Vector3d::Zero();
  if (TraceSharedSideJump(ctx, sampler, dirs, hits, stats, &jump)) return jump;
  for (int i = 0; i < 2; ++i) {
    Sampler copy = sampler;
    const Eigen::Vector3d radiance = TraceRadiance(ctx, &copy, dirs[i], hits[i], stats, nullptr);
    jump += i == 0 ? radiance : -radiance;
  }
  return jump;
}

bool EmitBoundary(int pixel, const Eigen::Vector3d& jump, double scale, const BoundaryRows& rows,
                  std::vector<EdgeEntry>* out) {
  const size_t first = out->size();
  for (int j = 0; j < rows.count; ++j) {
    for (int k = 0; k < 3; ++k) {
      const double w = rows.rows[j][k] * scale;
      if (w == 0.0) continue;
      const Eigen::Vector3d d = jump * w;
      if (!std::isfinite(w) || !d.allFinite()) {
        out->resize(first);
        return false;
      }
      out->push_back({pixel, 3 * rows.vertices[j] + k, d});
    }
  }
  if (rows.light_param >= 0) {
    for (int k = 0; k < 3; ++k) {
      const double w = rows.light_row[k] * scale;
      if (w == 0.0) continue;
      const Eigen::Vector3d d = jump * w;
      if (!std::isfinite(w) || !d.allFinite()) {
        out->resize(first);
        return false;
      }
      out->push_back({pixel, rows.light_param + k, d});
    }
  }
  return true;
}

namespace {

// Adds Σ w_pixel·d/spp of entries [first, end) to *part (the adjoint gradient of those entries,
// as the tiles weigh the pixels' sums).
void AddWeightedEntries(const Context& ctx, const std::vector<EdgeEntry>& entries, size_t first,
                        std::vector<double>* part) {
  const Image& weights = *ctx.request->adjoint_weights;
  const int width = ctx.view.camera.width;
  const double inv_spp = 1.0 / ctx.options.spp;
  for (size_t i = first; i < entries.size(); ++i) {
    const EdgeEntry& e = entries[i];
    const int x = e.pixel % width, y = e.pixel / width;
    const Eigen::Vector3d w(weights.at(x, y, 0), weights.at(x, y, 1), weights.at(x, y, 2));
    (*part)[e.param] += w.dot(e.d) * inv_spp;
  }
}

}  // namespace

void AddEdgeTerms(const Context& ctx, std::vector<DerivativeList>* pixel_lists, RenderStats* stats,
                  GradientParts* parts) {
  const EdgeView view(ctx);
  std::vector<EdgeEntry> entries;
  using AddTerms = void (*)(const EdgeView&, std::vector<EdgeEntry>*);
  const std::pair<DerivativeTerm, AddTerms> terms[] = {
      {DerivativeTerm::kPrimaryEdges, AddPrimaryEdgeTerms},
      {DerivativeTerm::kShadowEdges, AddShadowEdgeTerms},
      {DerivativeTerm::kTexelEdges, AddTexelEdgeTerms}};
  for (const auto& [term, add_terms] : terms) {
    // Without vertex derivatives only the shadow edges have terms (light positions).
    if (!ctx.request->params.vertices && term != DerivativeTerm::kShadowEdges) continue;
    const size_t first = entries.size();
    add_terms(view, &entries);
    if (parts != nullptr) AddWeightedEntries(ctx, entries, first, &parts->part(term));
  }
  for (const EdgeEntry& entry : entries) {
    (*pixel_lists)[entry.pixel].emplace_back(entry.param, entry.d);
  }
  for (const RenderStats& s : view.thread_stats) stats->AddCounts(s);
}

}  // namespace render_internal
}  // namespace sft
