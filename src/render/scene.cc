#include "src/render/scene.h"

#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <tuple>

#include "src/render/vertex_normals.h"

namespace sft {

RTCDevice EmbreeDevice() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice(nullptr);
    CHECK(d != nullptr) << "Embree device creation failed: " << rtcGetDeviceError(nullptr);
    rtcSetDeviceErrorFunction(
        d,
        [](void*, RTCError code, const char* message) {
          LOG(ERROR) << "Embree error " << code << ": " << (message ? message : "");
        },
        nullptr);
    return d;
  }();
  return device;
}

RenderScene::RenderScene(const std::vector<Eigen::Vector3d>& positions,
                         const std::vector<Eigen::Vector3i>& faces)
    : positions_(positions), faces_(faces) {
  Build();
}

RenderScene::RenderScene(const TriMesh& mesh) {
  MeshToArrays(mesh, &positions_, &faces_);
  Build();
}

RenderScene::~RenderScene() {
  if (scene_ != nullptr) rtcReleaseScene(scene_);
}

namespace {

// Embree's limit on ray origin and direction coordinates (its FLT_LARGE): larger ones make the ray
// invalid, which Embree asserts on.
constexpr double kMaxEmbreeCoordinate = 1.8e18;

// Whether Embree accepts a ray with these (float-converted) values.
bool ValidRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, float t_near,
              float t_far) {
  for (int k = 0; k < 3; ++k) {
    if (!(std::abs(origin[k]) <= kMaxEmbreeCoordinate) ||
        !(std::abs(dir[k]) <= kMaxEmbreeCoordinate)) {
      return false;
    }
  }
  if (dir.isZero()) return false;
  return t_near >= 0.0f && std::isfinite(t_near) && t_far >= t_near;
}

}  // namespace

void RenderScene::Build() {
  RTCDevice device = EmbreeDevice();
  scene_ = rtcNewScene(device);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);
  geometry_ = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(geometry_, RTC_BUILD_QUALITY_REFIT);
  vertex_buffer_ = static_cast<float*>(
      rtcSetNewGeometryBuffer(geometry_, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                              3 * sizeof(float), std::max<size_t>(1, positions_.size())));
  unsigned* index_buffer = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry_, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                              3 * sizeof(unsigned), std::max<size_t>(1, faces_.size())));
  // An empty mesh still gets one (degenerate, never hit) primitive: Embree wants non-empty buffers.
  index_buffer[0] = index_buffer[1] = index_buffer[2] = 0;
  vertex_buffer_[0] = vertex_buffer_[1] = vertex_buffer_[2] = 0.0f;
  referenced_.assign(positions_.size(), 0);
  for (size_t f = 0; f < faces_.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      CHECK(faces_[f][k] >= 0 && faces_[f][k] < static_cast<int>(positions_.size()));
      index_buffer[3 * f + k] = static_cast<unsigned>(faces_[f][k]);
      referenced_[faces_[f][k]] = 1;
    }
  }
  Weld();
  BuildEdges();
  UpdateDerived();
  rtcCommitGeometry(geometry_);
  rtcAttachGeometry(scene_, geometry_);
  rtcReleaseGeometry(geometry_);  // the scene holds the reference.
  rtcCommitScene(scene_);
}

void RenderScene::Weld() {
  welded_.resize(positions_.size());
  std::vector<int> order;
  for (size_t v = 0; v < positions_.size(); ++v) {
    welded_[v] = static_cast<int>(v);
    if (referenced_[v] && positions_[v].allFinite()) order.push_back(static_cast<int>(v));
  }
  // Sorted by coordinates, then index: runs of equal coordinates start at their smallest index.
  auto less = [this](int a, int b) {
    const Eigen::Vector3d &p = positions_[a], &q = positions_[b];
    if (p.x() != q.x()) return p.x() < q.x();
    if (p.y() != q.y()) return p.y() < q.y();
    if (p.z() != q.z()) return p.z() < q.z();
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  for (size_t i = 1; i < order.size(); ++i) {
    if (positions_[order[i]] == positions_[order[i - 1]]) welded_[order[i]] = welded_[order[i - 1]];
  }
}

namespace {

// A face's traversal of a welded edge: welded ends (v0 < v1), the face, the direction (+1: from
// v0 to v1 in the face's winding) and the face's own vertices at v0 and v1.
struct HalfEdge {
  int v0, v1, face, direction, copy0, copy1;
  bool operator<(const HalfEdge& o) const {
    return std::tie(v0, v1, face) < std::tie(o.v0, o.v1, o.face);
  }
};

// Copies of the faces' own vertices with weight `share` each, merged per vertex. At most
// kMaxEdgeCopies distinct copies per end are kept (renormalized): only edges shared by that many
// faces that all use different copies — pathological non-manifold input — lose exactness.
constexpr int kMaxEdgeCopies = 8;
int AddCopies(const std::vector<int>& vertices, std::vector<EdgeCopy>* out) {
  const size_t first = out->size();
  for (const int v : vertices) {
    bool merged = false;
    for (size_t i = first; i < out->size() && !merged; ++i) {
      if ((*out)[i].vertex == v) {
        (*out)[i].weight += 1.0;
        merged = true;
      }
    }
    if (!merged && out->size() - first < kMaxEdgeCopies) out->push_back({v, 1.0});
  }
  double total = 0.0;
  for (size_t i = first; i < out->size(); ++i) total += (*out)[i].weight;
  for (size_t i = first; i < out->size(); ++i) (*out)[i].weight /= total;
  return static_cast<int>(out->size() - first);
}

}  // namespace

void RenderScene::BuildEdges() {
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(3 * faces_.size());
  for (size_t f = 0; f < faces_.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = faces_[f][k], b = faces_[f][(k + 1) % 3];
      const int wa = welded_[a], wb = welded_[b];
      if (wa == wb) continue;
      if (wa < wb) {
        half_edges.push_back({wa, wb, static_cast<int>(f), 1, a, b});
      } else {
        half_edges.push_back({wb, wa, static_cast<int>(f), -1, b, a});
      }
    }
  }
  std::sort(half_edges.begin(), half_edges.end());
  edges_.clear();
  edge_copies_.clear();
  std::vector<int> copies0, copies1;
  for (size_t i = 0; i < half_edges.size();) {
    MeshEdge edge;
    edge.v0 = half_edges[i].v0;
    edge.v1 = half_edges[i].v1;
    int direction0 = 0;
    copies0.clear();
    copies1.clear();
    for (; i < half_edges.size() && half_edges[i].v0 == edge.v0 && half_edges[i].v1 == edge.v1;
         ++i) {
      const HalfEdge& h = half_edges[i];
      if (edge.num_faces > 0 && h.face == half_edges[i - 1].face) continue;  // listed twice.
      if (edge.num_faces == 0) {
        edge.f0 = h.face;
        direction0 = h.direction;
      }
      if (edge.num_faces == 1) {
        edge.f1 = h.face;
        edge.flip1 = h.direction != direction0 ? 1 : -1;
      }
      ++edge.num_faces;
      copies0.push_back(h.copy0);
      copies1.push_back(h.copy1);
    }
    edge.first_copy = static_cast<int>(edge_copies_.size());
    edge.num_copies0 = AddCopies(copies0, &edge_copies_);
    edge.num_copies1 = AddCopies(copies1, &edge_copies_);
    edges_.push_back(edge);
  }
}

void RenderScene::UpdateDerived() {
  static std::atomic<uint64_t> next_state_id{1};
  state_id_ = next_state_id.fetch_add(1);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  bool any = false;
  for (size_t i = 0; i < positions_.size(); ++i) {
    for (int k = 0; k < 3; ++k) vertex_buffer_[3 * i + k] = static_cast<float>(positions_[i][k]);
    if (!referenced_[i]) continue;
    lo = lo.cwiseMin(positions_[i]);
    hi = hi.cwiseMax(positions_[i]);
    any = true;
  }
  if (!any) lo = hi = Eigen::Vector3d::Zero();
  lo_ = lo;
  hi_ = hi;
  extent_ = (hi - lo).norm();
  if (!(extent_ > 0) || !std::isfinite(extent_)) extent_ = 1.0;
  face_normals_.resize(faces_.size());
  face_scales_.resize(faces_.size());
  for (size_t f = 0; f < faces_.size(); ++f) {
    const Eigen::Vector3d& p0 = positions_[faces_[f][0]];
    const Eigen::Vector3d n = (positions_[faces_[f][1]] - p0).cross(positions_[faces_[f][2]] - p0);
    const double len = n.norm();
    face_normals_[f] =
        len > 0 && std::isfinite(len) ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
    double scale = 0.0;
    for (int k = 0; k < 3; ++k) {
      scale = std::max(scale, positions_[faces_[f][k]].cwiseAbs().maxCoeff());
    }
    face_scales_[f] = scale;
  }
  AngleWeightedNormalSums(positions_, faces_, welded_, &vertex_normals_);
  for (size_t v = 0; v < positions_.size(); ++v) {
    const Eigen::Vector3d& sum = vertex_normals_[welded_[v]];
    const double len = sum.norm();
    // welded_[v] ≤ v: the representative is normalized before its copies read it.
    vertex_normals_[v] =
        len > 0 && std::isfinite(len) ? Eigen::Vector3d(sum / len) : Eigen::Vector3d::Zero();
  }
}

void RenderScene::Bounds(Eigen::Vector3d* lo, Eigen::Vector3d* hi) const {
  *lo = lo_;
  *hi = hi_;
}

void RenderScene::SetVertices(const std::vector<Eigen::Vector3d>& positions) {
  CHECK_EQ(positions.size(), positions_.size());
  positions_ = positions;
  UpdateDerived();
  rtcUpdateGeometryBuffer(geometry_, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(geometry_);
  rtcCommitScene(scene_);
}

RayHit RenderScene::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                              double t_near, double t_far) const {
  RayHit hit;
  const float t_near_f = static_cast<float>(t_near);
  const float t_far_f = static_cast<float>(std::min(t_far, 3.0e38));
  if (!ValidRay(origin, dir, t_near_f, t_far_f)) return hit;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = static_cast<float>(origin.x());
  rh.ray.org_y = static_cast<float>(origin.y());
  rh.ray.org_z = static_cast<float>(origin.z());
  rh.ray.dir_x = static_cast<float>(dir.x());
  rh.ray.dir_y = static_cast<float>(dir.y());
  rh.ray.dir_z = static_cast<float>(dir.z());
  rh.ray.tnear = t_near_f;
  rh.ray.tfar = t_far_f;
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.hit = true;
  hit.t = rh.ray.tfar;
  hit.face = static_cast<int>(rh.hit.primID);
  hit.u = rh.hit.u;
  hit.v = rh.hit.v;
  return hit;
}

void RenderScene::Intersect8(const Eigen::Vector3d& origin, const Eigen::Vector3d* dirs, int count,
                             RayHit* hits) const {
  CHECK_LE(count, 8);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(32) int valid[8];
  alignas(32) RTCRayHit8 rh;
  for (int i = 0; i < 8; ++i) {
    valid[i] = i < count && ValidRay(origin, dirs[i], 0.0f, 3.0e38f) ? -1 : 0;
    const Eigen::Vector3d& dir = dirs[i < count ? i : 0];
    rh.ray.org_x[i] = static_cast<float>(origin.x());
    rh.ray.org_y[i] = static_cast<float>(origin.y());
    rh.ray.org_z[i] = static_cast<float>(origin.z());
    rh.ray.dir_x[i] = static_cast<float>(dir.x());
    rh.ray.dir_y[i] = static_cast<float>(dir.y());
    rh.ray.dir_z[i] = static_cast<float>(dir.z());
    rh.ray.tnear[i] = 0.0f;
    rh.ray.tfar[i] = 3.0e38f;
    rh.ray.time[i] = 0.0f;
    rh.ray.mask[i] = 0xFFFFFFFFu;
    rh.ray.id[i] = i;
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect8(valid, scene_, &context, &rh);
  for (int i = 0; i < count; ++i) {
    RayHit& hit = hits[i];
    hit = RayHit();
    if (!valid[i]) continue;
    if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
    hit.hit = true;
    hit.t = rh.ray.tfar[i];
    hit.face = static_cast<int>(rh.hit.primID[i]);
    hit.u = rh.hit.u[i];
    hit.v = rh.hit.v[i];
  }
}

bool RenderScene::Occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_near,
                           double t_far) const {
  const float t_near_f = static_cast<float>(t_near);
  const float t_far_f = static_cast<float>(std::min(t_far, 3.0e38));
  if (!ValidRay(origin, dir, t_near_f, t_far_f)) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = static_cast<float>(origin.x());
  ray.org_y = static_cast<float>(origin.y());
  ray.org_z = static_cast<float>(origin.z());
  ray.dir_x = static_cast<float>(dir.x());
  ray.dir_y = static_cast<float>(dir.y());
  ray.dir_z = static_cast<float>(dir.z());
  ray.tnear = t_near_f;
  ray.tfar = t_far_f;
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(scene_, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit.
}

Eigen::Vector3d RenderScene::Point(int face, double u, double v) const {
  const Eigen::Vector3i& f = faces_[face];
  return (1.0 - u - v) * positions_[f[0]] + u * positions_[f[1]] + v * positions_[f[2]];
}

Eigen::Vector3d RenderScene::SmoothNormal(int face, double u, double v) const {
  const Eigen::Vector3i& f = faces_[face];
  const Eigen::Vector3d m =
      (1.0 - u - v) * vertex_normals_[f[0]] + u * vertex_normals_[f[1]] + v * vertex_normals_[f[2]];
  const double len = m.norm();
  if (face_normals_[face].isZero()) return Eigen::Vector3d::Zero();
  return len > 0 && std::isfinite(len) ? Eigen::Vector3d(m / len) : face_normals_[face];
}

}  // namespace sft
