// Throughput of the renderer against its limit, raw Embree (`sft bench render`). One run traces
// the renderer's own ray set on the renderer's own BVH (RenderScene::embree_scene()):
//   - camera rays: the same camera, the same sub-pixel positions (RenderView's first Next2D of
//     each sample's Sampler, replicated here) and the same spp as RenderView, through rtcIntersect1
//     and through rtcIntersect8 packets (rtcIntersect16 is emulated on AVX2 CPUs: design notes);
//   - shadow rays: from the first hits to every point light, spawned exactly as RenderView does at
//     the first vertex (same offset, same cosine and distance tests), through rtcOccluded1;
// all multithreaded with TBB on the same number of threads as the renderer, with flush-to-zero /
// denormals-are-zero set in every tracing thread. It then renders the view with RenderView at
// bounces = 1 (camera + shadow rays) and bounces = 2 and compares: the time raw Embree needs for
// the renderer's ray counts, t_raw = N_camera / rate_intersect1 + N_shadow / rate_occluded1,
// against the renderer's time, ratio = t_raw / t_ours (1 = no overhead over tracing).
// Every measurement is repeated and the fastest run is kept.
#ifndef SFT_EVAL_THROUGHPUT_H_
#define SFT_EVAL_THROUGHPUT_H_

#include <embree3/rtcore.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {

struct ThroughputOptions {
  int resolution = 256;  // image width = height in pixels (ThroughputView), >= 1.
  int spp = 4;           // camera rays per pixel (pixel jitter samples), as RenderOptions::spp.
  int threads = 0;       // tracing threads for Embree and the renderer; 0 = all cores.
  int repeats = 3;       // runs per measurement; the fastest is kept. >= 1.
  uint64_t seed = 0;     // sample seed shared by the raw ray set and the renderer.

  bool Check(std::string* why) const;
};

// One ray in Embree's float layout (origin, t range, direction).
struct BenchRay {
  float org[3];
  float tnear;
  float dir[3];
  float tfar;
};

// How TraceEmbree traces a ray set.
enum class EmbreeQuery { kIntersect1, kIntersect8, kOccluded1 };
const char* EmbreeQueryName(EmbreeQuery query);

// A number of rays traced in a wall-clock time (all threads together).
struct RayRate {
  int64_t rays = 0;
  double seconds = 0.0;
  int64_t hits = 0;  // rays that hit (intersect) or were occluded; 0 for the renderer.

  double RaysPerSecond() const { return seconds > 0.0 ? rays / seconds : 0.0; }
};

struct ThroughputReport {
  int num_faces = 0;
  int threads = 0;  // actual thread count (0 in the options resolved to the core count).
  int width = 0, height = 0, spp = 0, repeats = 0;
  // Raw Embree on the renderer's ray set.
  RayRate intersect1;  // camera rays, rtcIntersect1.
  RayRate intersect8;  // camera rays, rtcIntersect8 packets.
  RayRate occluded1;   // shadow rays from the first hits, rtcOccluded1.
  // The renderer (fastest run): rays = camera + shadow (+ bounce) rays of RenderStats.
  RenderStats direct;               // bounces = 1, direct light with shadows.
  RenderStats two_bounces;          // bounces = 2, for information.
  double raw_direct_seconds = 0.0;  // t_raw for direct's camera and shadow ray counts.
  double ratio = 0.0;               // raw_direct_seconds / direct.seconds.

  double DirectRaysPerSecond() const;
  double TwoBouncesRaysPerSecond() const;
};

// The benchmark view of `scene`: a square PINHOLE camera (focal length = resolution, ~53° field
// of view) looking at the bounding-box centre from a fixed oblique direction (world +y up), from
// the distance at which the vertices' projection spans 60% of the image along its larger axis,
// and one point light slightly above the camera.
ViewSetup ThroughputView(const RenderScene& scene, int resolution);

// The renderer's camera rays for `view` at `spp` samples per pixel with `seed` (RenderView's
// sub-pixel positions), in pixel order (row-major) with a pixel's samples consecutive.
std::vector<BenchRay> CameraRays(const ViewSetup& view, int spp, uint64_t seed);

// Shadow rays spawned where the camera rays of (view, spp, seed) first hit `scene`, towards every
// point light, as RenderView spawns them at the first vertex (the BSDF is assumed non-zero there,
// true for any albedo > 0). Traced with `threads` threads (0 = all cores).
std::vector<BenchRay> ShadowRays(const RenderScene& scene, const ViewSetup& view, int spp,
                                 uint64_t seed, int threads);

// Traces every ray of `rays` once through `query` on `threads` TBB threads (0 = all cores) and
// returns the wall-clock time of the tracing alone (rays are built into Embree's structures
// inside the timed loop, as a renderer must).
RayRate TraceEmbree(RTCScene scene, const std::vector<BenchRay>& rays, EmbreeQuery query,
                    int threads);

// The full measurement (see the file comment) of `view` rendered with `material` on `scene`.
// `view` needs at least one point light; options.resolution is ignored (the camera is the view's).
Status MeasureThroughput(const RenderScene& scene, const Material& material, const ViewSetup& view,
                         const ThroughputOptions& options, ThroughputReport* report);

// Convenience: the measurement on `mesh` with ThroughputView(options.resolution) and the default
// material (albedo 0.7, roughness 0.5, no specular).
Status MeasureMeshThroughput(const TriMesh& mesh, const ThroughputOptions& options,
                             ThroughputReport* report);

// The report as JSON (rates in rays/s) and as a small human-readable table (Mrays/s).
nlohmann::json ThroughputReportToJson(const ThroughputReport& report);
std::string ThroughputReportTable(const ThroughputReport& report);

}  // namespace sft

#endif  // SFT_EVAL_THROUGHPUT_H_
