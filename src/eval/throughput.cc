#include "src/eval/throughput.h"

#include <pmmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <xmmintrin.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "src/core/rng.h"

namespace sft {
namespace {

// Rays per TBB task (a multiple of the packet width 8); RenderView's 8×8 pixel tiles at 4 spp
// are 256 camera rays as well.
constexpr size_t kRaysPerTask = 256;
constexpr int kPacketWidth = 8;

// The most camera rays the benchmark accepts (res² · spp; 32 bytes each, 512 MB, and as much
// again per point light for the shadow-ray slots).
constexpr int64_t kMaxCameraRays = int64_t{1} << 24;

void SetFlushToZero() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

int ArenaConcurrency(int threads) { return threads > 0 ? threads : tbb::task_arena::automatic; }

// The camera rays of a pixel, through the renderer's own CameraSampleDirection.
struct CameraFrame {
  Eigen::Vector3d center;
  Eigen::Matrix3d world_from_cam_rotation;
  explicit CameraFrame(const ViewSetup& view) {
    const Rigid3d world_from_cam = view.cam_from_world.Inverse();
    center = world_from_cam.translation;
    world_from_cam_rotation = world_from_cam.rotation.toRotationMatrix();
  }
  // Writes the unit directions of the `spp` samples of pixel (x, y) to dirs[0, spp).
  void PixelDirections(const ViewSetup& view, uint64_t seed, int x, int y, int spp,
                       Eigen::Vector3d* dirs) const {
    Sampler sampler;
    for (int s = 0; s < spp; ++s) {
      dirs[s] = CameraSampleDirection(view, world_from_cam_rotation, seed, x, y, s, &sampler);
    }
  }
};

BenchRay MakeRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_near,
                 double t_far) {
  BenchRay ray;
  for (int k = 0; k < 3; ++k) {
    ray.org[k] = static_cast<float>(origin[k]);
    ray.dir[k] = static_cast<float>(dir[k]);
  }
  ray.tnear = static_cast<float>(t_near);
  ray.tfar = static_cast<float>(std::min(t_far, 3.0e38));
  return ray;
}

void FillRay(const BenchRay& in, RTCRay* ray) {
  ray->org_x = in.org[0];
  ray->org_y = in.org[1];
  ray->org_z = in.org[2];
  ray->tnear = in.tnear;
  ray->dir_x = in.dir[0];
  ray->dir_y = in.dir[1];
  ray->dir_z = in.dir[2];
  ray->time = 0.0f;
  ray->tfar = in.tfar;
  ray->mask = 0xFFFFFFFFu;
  ray->id = 0;
  ray->flags = 0;
}

// Traces rays [begin, end) and returns the number of hits (or occluded rays).
int64_t TraceRange(RTCScene scene, const BenchRay* rays, size_t begin, size_t end,
                   EmbreeQuery query) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  int64_t hits = 0;
  switch (query) {
    case EmbreeQuery::kIntersect1:
      for (size_t i = begin; i < end; ++i) {
        RTCRayHit rh;
        FillRay(rays[i], &rh.ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &context, &rh);
        hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
      }
      break;
    case EmbreeQuery::kIntersect8: {
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // camera rays.
      RTCRayHit8 rh;                                        // RTC_ALIGN(32) by declaration.
      alignas(32) int valid[kPacketWidth];
      for (size_t i = begin; i < end; i += kPacketWidth) {
        for (int k = 0; k < kPacketWidth; ++k) {
          const bool active = i + k < end;
          valid[k] = active ? -1 : 0;
          const BenchRay& in = rays[active ? i + k : begin];  // inactive lanes: any valid ray.
          rh.ray.org_x[k] = in.org[0];
          rh.ray.org_y[k] = in.org[1];
          rh.ray.org_z[k] = in.org[2];
          rh.ray.tnear[k] = in.tnear;
          rh.ray.dir_x[k] = in.dir[0];
          rh.ray.dir_y[k] = in.dir[1];
          rh.ray.dir_z[k] = in.dir[2];
          rh.ray.time[k] = 0.0f;
          rh.ray.tfar[k] = in.tfar;
          rh.ray.mask[k] = 0xFFFFFFFFu;
          rh.ray.id[k] = 0;
          rh.ray.flags[k] = 0;
          rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
          rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect8(valid, scene, &context, &rh);
        for (int k = 0; k < kPacketWidth; ++k) {
          hits += valid[k] != 0 && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
        }
      }
      break;
    }
    case EmbreeQuery::kOccluded1:
      for (size_t i = begin; i < end; ++i) {
        RTCRay ray;
        FillRay(rays[i], &ray);
        rtcOccluded1(scene, &context, &ray);
        hits += ray.tfar < 0.0f ? 1 : 0;  // Embree sets tfar = -inf on a hit.
      }
      break;
  }
  return hits;
}

nlohmann::json RateJson(const RayRate& rate) {
  return {{"rays", rate.rays},
          {"hits", rate.hits},
          {"seconds", rate.seconds},
          {"rays_per_second", rate.RaysPerSecond()}};
}

nlohmann::json StatsJson(const RenderStats& stats, int bounces) {
  return {{"bounces", bounces},
          {"camera_rays", stats.camera_rays},
          {"shadow_rays", stats.shadow_rays},
          {"bounce_rays", stats.bounce_rays},
          {"rays", stats.TotalRays()},
          {"seconds", stats.seconds},
          {"rays_per_second", stats.seconds > 0.0 ? stats.TotalRays() / stats.seconds : 0.0}};
}

}  // namespace

bool ThroughputOptions::Check(std::string* why) const {
  if (resolution < 1 || resolution > 65536) {
    *why = "res: must be in [1, 65536], got " + std::to_string(resolution);
    return false;
  }
  if (spp < 1 || spp > (1 << 20)) {
    *why = "spp: must be in [1, 1048576], got " + std::to_string(spp);
    return false;
  }
  if (int64_t{resolution} * resolution * spp > kMaxCameraRays) {
    *why = "res, spp: res² · spp must be at most " + std::to_string(kMaxCameraRays) + ", got " +
           std::to_string(int64_t{resolution} * resolution * spp);
    return false;
  }
  if (threads < 0) {
    *why = "threads: must be >= 0 (0 = all cores), got " + std::to_string(threads);
    return false;
  }
  if (repeats < 1 || repeats > 1000) {
    *why = "repeats: must be in [1, 1000], got " + std::to_string(repeats);
    return false;
  }
  return true;
}

const char* EmbreeQueryName(EmbreeQuery query) {
  switch (query) {
    case EmbreeQuery::kIntersect1:
      return "intersect1";
    case EmbreeQuery::kIntersect8:
      return "intersect8";
    case EmbreeQuery::kOccluded1:
      return "occluded1";
  }
  return "?";
}

double ThroughputReport::DirectRaysPerSecond() const {
  return direct.seconds > 0.0 ? direct.TotalRays() / direct.seconds : 0.0;
}

double ThroughputReport::TwoBouncesRaysPerSecond() const {
  return two_bounces.seconds > 0.0 ? two_bounces.TotalRays() / two_bounces.seconds : 0.0;
}

ViewSetup ThroughputView(const RenderScene& scene, int resolution) {
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);  // of the referenced vertices.
  const Eigen::Vector3d target = 0.5 * (lo + hi);
  const double radius = 0.5 * scene.extent();  // bounding sphere of the box.

  // Camera axes in world (COLMAP: +x right, +y down, +z forward), looking from a fixed oblique
  // direction with world +y up.
  const Eigen::Vector3d world_up = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d back = Eigen::Vector3d(0.4, 0.3, 1.0).normalized();
  const Eigen::Vector3d z_axis = -back;
  const Eigen::Vector3d x_axis = z_axis.cross(world_up).normalized();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);
  Eigen::Matrix3d cam_from_world_rotation;
  cam_from_world_rotation.row(0) = x_axis.transpose();
  cam_from_world_rotation.row(1) = y_axis.transpose();
  cam_from_world_rotation.row(2) = z_axis.transpose();

  // focal = resolution, so normalized image coordinates x/z span [−0.5, 0.5] across the image.
  // The distance is chosen (bisection, the span shrinks with distance) so that the vertices'
  // projection spans kFill of the image along its larger axis.
  constexpr double kFill = 0.6;
  auto span_at = [&](double distance) {
    Eigen::Vector2d min_xy = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d max_xy = -min_xy;
    for (size_t v = 0; v < scene.positions().size(); ++v) {
      if (!scene.IsReferenced(static_cast<int>(v))) continue;
      const Eigen::Vector3d& p = scene.positions()[v];
      const Eigen::Vector3d q =
          cam_from_world_rotation * (p - target) + Eigen::Vector3d(0, 0, distance);
      if (!(q.z() > 0.0)) return std::numeric_limits<double>::infinity();
      const Eigen::Vector2d xy = q.head<2>() / q.z();
      min_xy = min_xy.cwiseMin(xy);
      max_xy = max_xy.cwiseMax(xy);
    }
    return max_xy.x() >= min_xy.x() ? (max_xy - min_xy).maxCoeff() : 0.0;
  };
  double near = 1.001 * radius, far = 1e4 * radius;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (near + far);
    (span_at(mid) > kFill ? near : far) = mid;
  }
  const double distance = far;
  const Eigen::Vector3d eye = target + distance * back;

  ViewSetup view;
  view.camera.id = "bench";
  view.camera.model = CameraModel::kPinhole;
  view.camera.width = view.camera.height = resolution;
  view.camera.params = {double(resolution), double(resolution), 0.5 * resolution, 0.5 * resolution};
  view.cam_from_world.rotation = Eigen::Quaterniond(cam_from_world_rotation).normalized();
  view.cam_from_world.translation = -(view.cam_from_world.rotation * eye);
  // Light slightly above and to the right of the camera; intensity gives irradiance ~1.
  PointLight light;
  light.position = eye + 0.3 * radius * (x_axis - y_axis);
  light.intensity = Eigen::Vector3d::Constant(distance * distance);
  view.point_lights.push_back(light);
  return view;
}

std::vector<BenchRay> CameraRays(const ViewSetup& view, int spp, uint64_t seed) {
  const int width = view.camera.width, height = view.camera.height;
  std::vector<BenchRay> rays(static_cast<size_t>(width) * height * spp);
  const CameraFrame frame(view);
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      std::vector<Eigen::Vector3d> dirs(spp);
      for (int x = 0; x < width; ++x) {
        frame.PixelDirections(view, seed, x, y, spp, dirs.data());
        for (int s = 0; s < spp; ++s) {
          const size_t i = (static_cast<size_t>(y) * width + x) * spp + s;
          rays[i] = MakeRay(frame.center, dirs[s], 0.0, std::numeric_limits<double>::infinity());
        }
      }
    }
  });
  return rays;
}

std::vector<BenchRay> ShadowRays(const RenderScene& scene, const ViewSetup& view, int spp,
                                 uint64_t seed, int threads) {
  const int width = view.camera.width, height = view.camera.height;
  const size_t num_lights = view.point_lights.size();
  const size_t num_camera = static_cast<size_t>(width) * height * spp;
  // One slot per (camera ray, light), compacted afterwards to keep the renderer's order.
  std::vector<BenchRay> slots(num_camera * num_lights);
  std::vector<char> used(slots.size(), 0);
  const CameraFrame frame(view);
  tbb::task_arena arena(ArenaConcurrency(threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
      SetFlushToZero();
      std::vector<Eigen::Vector3d> dirs(spp);
      for (int y = rows.begin(); y < rows.end(); ++y) {
        for (int x = 0; x < width; ++x) {
          frame.PixelDirections(view, seed, x, y, spp, dirs.data());
          for (int s = 0; s < spp; ++s) {
            const size_t i = (static_cast<size_t>(y) * width + x) * spp + s;
            const Eigen::Vector3d& dir = dirs[s];
            const RayHit hit =
                scene.Intersect(frame.center, dir, 0.0, std::numeric_limits<double>::infinity());
            if (!hit.hit) continue;
            const Eigen::Vector3d p = scene.Point(hit.face, hit.u, hit.v);
            Eigen::Vector3d n = scene.FaceNormal(hit.face);
            if (n.isZero()) continue;
            if (n.dot(-dir) < 0.0) n = -n;
            const double offset = SurfaceRayOffset(scene, hit.face, p);
            const double min_dist = kMinRelativeLightDistance * SurfaceScale(scene, hit.face, p);
            const Eigen::Vector3d p_off = p + offset * n;
            for (size_t l = 0; l < num_lights; ++l) {
              const Eigen::Vector3d to_light = view.point_lights[l].position - p;
              const double dist2 = to_light.squaredNorm();
              if (!(dist2 > min_dist * min_dist)) continue;
              const double dist = std::sqrt(dist2);
              const Eigen::Vector3d wi = to_light / dist;
              if (n.dot(wi) <= 0.0) continue;
              slots[i * num_lights + l] = MakeRay(p_off, wi, 0.0, dist - offset);
              used[i * num_lights + l] = 1;
            }
          }
        }
      }
    });
  });
  std::vector<BenchRay> rays;
  rays.reserve(std::count(used.begin(), used.end(), 1));
  for (size_t i = 0; i < slots.size(); ++i) {
    if (used[i]) rays.push_back(slots[i]);
  }
  return rays;
}

RayRate TraceEmbree(RTCScene scene, const std::vector<BenchRay>& rays, EmbreeQuery query,
                    int threads) {
  RayRate rate;
  rate.rays = static_cast<int64_t>(rays.size());
  tbb::task_arena arena(ArenaConcurrency(threads));
  arena.initialize();
  tbb::enumerable_thread_specific<int64_t> hits(0);
  const size_t num_tasks = (rays.size() + kRaysPerTask - 1) / kRaysPerTask;
  arena.execute([&] {
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, num_tasks),
                      [&](const tbb::blocked_range<size_t>& tasks) {
                        SetFlushToZero();
                        const size_t begin = tasks.begin() * kRaysPerTask;
                        const size_t end = std::min(rays.size(), tasks.end() * kRaysPerTask);
                        hits.local() += TraceRange(scene, rays.data(), begin, end, query);
                      });
    rate.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  rate.hits = hits.combine([](int64_t a, int64_t b) { return a + b; });
  return rate;
}

Status MeasureThroughput(const RenderScene& scene, const Material& material, const ViewSetup& view,
                         const ThroughputOptions& options, ThroughputReport* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (!view.camera.Check(&why)) return Status::Error("camera: " + why);
  if (view.point_lights.empty()) return Status::Error("view: needs at least one point light");
  if (scene.faces().empty()) return Status::Error("mesh: has no faces");

  ThroughputReport result;
  result.num_faces = static_cast<int>(scene.faces().size());
  {
    tbb::task_arena arena(ArenaConcurrency(options.threads));
    arena.initialize();
    result.threads = arena.max_concurrency();
  }
  result.width = view.camera.width;
  result.height = view.camera.height;
  result.spp = options.spp;
  result.repeats = options.repeats;

  // Raw Embree on the same BVH.
  const std::vector<BenchRay> camera_rays = CameraRays(view, options.spp, options.seed);
  const std::vector<BenchRay> shadow_rays =
      ShadowRays(scene, view, options.spp, options.seed, options.threads);
  auto best_of = [&](const std::vector<BenchRay>& rays, EmbreeQuery query) {
    RayRate best;
    for (int r = 0; r < options.repeats; ++r) {
      const RayRate rate = TraceEmbree(scene.embree_scene(), rays, query, options.threads);
      if (r == 0 || rate.seconds < best.seconds) best = rate;
    }
    return best;
  };
  result.intersect1 = best_of(camera_rays, EmbreeQuery::kIntersect1);
  result.intersect8 = best_of(camera_rays, EmbreeQuery::kIntersect8);
  result.occluded1 = best_of(shadow_rays, EmbreeQuery::kOccluded1);

  // The renderer.
  auto best_render = [&](int bounces) {
    RenderOptions render;
    render.spp = options.spp;
    render.bounces = bounces;
    render.seed = options.seed;
    render.threads = options.threads;
    RenderStats best;
    for (int r = 0; r < options.repeats; ++r) {
      Image image;
      RenderStats stats;
      RenderView(scene, material, view, render, &image, &stats);
      if (r == 0 || stats.seconds < best.seconds) best = stats;
    }
    return best;
  };
  result.direct = best_render(1);
  result.two_bounces = best_render(2);

  // t_raw for the renderer's own counts (a rate of 0 only happens with 0 rays).
  const double rate_primary = result.intersect1.RaysPerSecond();
  const double rate_shadow = result.occluded1.RaysPerSecond();
  result.raw_direct_seconds =
      (result.direct.camera_rays > 0 && rate_primary > 0.0
           ? result.direct.camera_rays / rate_primary
           : 0.0) +
      (result.direct.shadow_rays > 0 && rate_shadow > 0.0 ? result.direct.shadow_rays / rate_shadow
                                                          : 0.0);
  result.ratio =
      result.direct.seconds > 0.0 ? result.raw_direct_seconds / result.direct.seconds : 0.0;
  *report = result;
  return Status::Ok();
}

Status MeasureMeshThroughput(const TriMesh& mesh, const ThroughputOptions& options,
                             ThroughputReport* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  if (mesh.n_faces() == 0) return Status::Error("mesh: has no faces");
  const RenderScene scene(mesh);
  const Material material =
      ConstantMaterial(static_cast<int>(mesh.n_faces()), Eigen::Vector3d::Constant(0.7), 0.5, 0.0);
  return MeasureThroughput(scene, material, ThroughputView(scene, options.resolution), options,
                           report);
}

nlohmann::json ThroughputReportToJson(const ThroughputReport& report) {
  nlohmann::json json;
  json["mesh_faces"] = report.num_faces;
  json["threads"] = report.threads;
  json["width"] = report.width;
  json["height"] = report.height;
  json["spp"] = report.spp;
  json["repeats"] = report.repeats;
  json["embree"] = {{"intersect1", RateJson(report.intersect1)},
                    {"intersect8", RateJson(report.intersect8)},
                    {"occluded1", RateJson(report.occluded1)}};
  json["ours"] = {{"direct", StatsJson(report.direct, 1)},
                  {"two_bounces", StatsJson(report.two_bounces, 2)}};
  json["raw_direct_seconds"] = report.raw_direct_seconds;
  json["ratio"] = report.ratio;
  return json;
}

std::string ThroughputReportTable(const ThroughputReport& report) {
  std::string out;
  char line[256];
  auto add = [&](const char* format, auto... args) {
    std::snprintf(line, sizeof(line), format, args...);
    out += line;
  };
  const double coverage =
      report.intersect1.rays > 0 ? 100.0 * report.intersect1.hits / report.intersect1.rays : 0.0;
  add("mesh faces     %d\n", report.num_faces);
  add("threads        %d\n", report.threads);
  add("image          %d x %d, %d spp, %.0f%% of camera rays hit; best of %d\n", report.width,
      report.height, report.spp, coverage, report.repeats);
  add("%-30s %10s %10s %9s\n", "rays", "count", "Mrays/s", "ms");
  auto row = [&](const char* name, int64_t rays, double seconds) {
    add("%-30s %10lld %10.2f %9.2f\n", name, static_cast<long long>(rays),
        seconds > 0.0 ? rays / seconds * 1e-6 : 0.0, seconds * 1e3);
  };
  row("embree intersect1 (camera)", report.intersect1.rays, report.intersect1.seconds);
  row("embree intersect8 (camera)", report.intersect8.rays, report.intersect8.seconds);
  row("embree occluded1 (shadow)", report.occluded1.rays, report.occluded1.seconds);
  row("ours, 1 bounce (camera+shadow)", report.direct.TotalRays(), report.direct.seconds);
  row("ours, 2 bounces (all rays)", report.two_bounces.TotalRays(), report.two_bounces.seconds);
  add("ratio ours/raw (1 bounce)      %.3f  (raw Embree: %.2f ms for the same %lld camera + "
      "%lld shadow rays)\n",
      report.ratio, report.raw_direct_seconds * 1e3,
      static_cast<long long>(report.direct.camera_rays),
      static_cast<long long>(report.direct.shadow_rays));
  return out;
}

}  // namespace sft
