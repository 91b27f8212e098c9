// The forward path tracer (docs/architecture.md, "Render core"): camera rays through a box pixel
// filter, next-event estimation to point, directional and environment lights, BSDF sampling with
// multiple importance sampling (power heuristic) against the environment, a fixed number of path
// segments. Deterministic: sample s of pixel p of view v uses Sampler(seed, v, p, s) only, so the
// image is identical for any thread count.
#ifndef SFT_RENDER_RENDER_H_
#define SFT_RENDER_RENDER_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/rng.h"
#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/render/camera.h"
#include "src/render/derivatives.h"
#include "src/render/environment.h"
#include "src/render/scene.h"

namespace sft {

// Which light transport the renderer simulates. Turning an effect off changes the image (it is
// not an approximation switch for derivatives only).
struct Effects {
  bool direct = true;       // light reaching the first surface straight from a light source.
  bool shadows = true;      // occlusion of light sources (shadow rays); off = lights always seen.
  bool bounces = true;      // indirect light (paths of more than one segment before the light).
  bool specular = true;     // the glossy lobe; off = the specular weight is treated as 0.
  bool environment = true;  // environment lights (lighting and the visible background).

  std::string ToString() const;
  // Parses a comma-separated list of enabled effects ("direct,shadows,bounces,specular,
  // environment"; "all"; "none"). Returns false and sets *why on an unknown name.
  static bool Parse(const std::string& list, Effects* effects, std::string* why);
};

enum class RenderPass { kColor, kAlbedo, kRoughness, kNormal, kDepth };
bool RenderPassFromName(const std::string& name, RenderPass* pass);

// How a hit is shaded. kFlat: with its face's geometric normal, so every edge between
// non-coplanar faces is a shading discontinuity (a crease) that edge sampling must cover.
// kSmooth: with the interpolated angle-weighted vertex normals (RenderScene::SmoothNormal, as
// Blender computes them and Cycles interpolates them), continuous across edges, so only
// silhouettes, shadow boundaries and texel boundaries are discontinuities. Geometry (ray
// offsets, edge planes, hit-point motion) always uses the geometric normal.
enum class Shading { kFlat, kSmooth };
// "flat" | "smooth"; false for any other name.
bool ShadingFromName(const std::string& name, Shading* shading);
const char* ShadingName(Shading shading);

struct RenderOptions {
  int spp = 64;     // samples per pixel, >= 1.
  int bounces = 2;  // path segments as in the report: 1 = direct light only, 2 = one
                    // indirect bounce (= Cycles' max_bounces + 1); range 1..16.
  Effects effects;
  uint64_t seed = 0;  // base seed; the image is a deterministic function of it.
  int threads = 0;    // worker threads; 0 = all cores.
  RenderPass pass = RenderPass::kColor;
  Shading shading = Shading::kFlat;  // normals shading uses (see Shading).
  // Not owned. When set, path sampling (lobe choices, directions, pdfs, MIS weights) uses this
  // material while path values use the rendered one ("detached sampling"): renders of nearby
  // materials then follow identical paths, as finite differences and linearizations need. Must
  // have the rendered material's mesh-colors layout.
  const Material* sampling_material = nullptr;
  // Not owned. The same for the environment: when set (and the view has an environment), light-
  // sampled directions and the environment's pdfs (MIS weights) come from this map while radiance
  // comes from the view's, so renders of nearby fitted environments follow identical paths. Must
  // have the view environment's frame; its size may differ.
  const EnvironmentMap* sampling_environment = nullptr;
  // Called once per finished tile of camera samples (RenderTileCount per view), from the worker
  // threads (so it must be thread-safe), e.g. to advance a progress line within a long view. It
  // does not change the image.
  std::function<void()> on_tile_done;

  bool Check(std::string* why) const;
};

// Number of tiles (fixed 8×8 pixel blocks) of a width × height render: the units of
// RenderOptions::on_tile_done.
int64_t RenderTileCount(int width, int height);

struct PointLight {
  Eigen::Vector3d position;   // world frame.
  Eigen::Vector3d intensity;  // radiant intensity, W/sr.
  int light_index = -1;       // dataset light index (for its intensity-scale parameter); -1 none.
  // Whether the light rides with the camera (a flash): its position parameters
  // (ParameterLayout::light_positions) are then the offset o in the camera frame, with
  // position = C + Rᵀ·o for the view's camera centre C and rotation R (cam_from_world).
  bool camera_frame = false;
};

// A light at infinity (the sun): parallel rays along `direction`, irradiance E on a surface
// facing them, so a point with normal n receives E·max(0, n·wi), wi = −direction. A delta light,
// like a point light: reached by next-event estimation only.
struct DirectionalLight {
  Eigen::Vector3d direction;   // unit, world frame: the direction the light travels.
  Eigen::Vector3d irradiance;  // W/m² on a surface facing the light, RGB.
  int light_index = -1;        // dataset light index (its intensity-scale parameter); -1 none.
  // Whether the light turns with the camera: its direction parameters are then in the camera
  // frame, direction = Rᵀ·v/|v| for the view's rotation R (cam_from_world).
  bool camera_frame = false;
  // |v| of the direction parameters v (ParameterLayout::light_directions), > 0: the scale of the
  // normalization's Jacobian (LightDirectionJacobian). 1 when v is kept unit.
  double parameter_norm = 1.0;
};

// Everything one view needs besides the scene and material.
// A finite black support under the object that a world-fixed environment does not show (a table
// top; LightSpec::ground_radius): the environment seen from a point along a direction that hits
// the disc carries no radiance. Rays that miss it below its plane's horizon still see the map.
// The derivatives take the disc as part of the light: its rim is a visibility boundary that no
// edge term samples, so the vertex rows lack the change of which directions the rim cuts off as a
// shading point moves (a small term for a support the size of a table or larger).
struct SupportDisc {
  double radius = 0.0;  // world units; 0 = no disc.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit; the side the object is on.

  // Whether the ray p + t·d, t > 0, hits the disc (d need not be unit).
  bool Hides(const Eigen::Vector3d& p, const Eigen::Vector3d& d) const {
    const double nd = normal.dot(d);
    if (!(radius > 0.0) || !(nd < 0.0)) return false;
    const double t = normal.dot(centre - p) / nd;
    return t > 0.0 && (p + t * d - centre).squaredNorm() <= radius * radius;
  }
};

struct ViewSetup {
  Camera camera;
  Rigid3d cam_from_world;
  std::vector<PointLight> point_lights;
  std::vector<DirectionalLight> directional_lights;
  const EnvironmentMap* environment = nullptr;  // not owned; may be null.
  bool environment_background = false;          // camera rays that miss see the environment.
  int environment_light_index = -1;             // dataset light index of `environment`.
  SupportDisc support;             // hides `environment` where it blocks the view (radius 0: none).
  double environment_scale = 1.0;  // multiplies the environment's radiance, >= 0.
  // ∂(world-frame turn δ of `environment`)/∂(its light's rotation parameters θ,
  // ParameterLayout::environment_rotations): J_l(θ) for a world-fixed environment, Rᵀ·J_l(θ)
  // for a camera-fixed one (R = cam_from_world's rotation, J_l = RotationLeftJacobian). The
  // identity for a world-fixed environment at θ = 0.
  Eigen::Matrix3d environment_rotation_jacobian = Eigen::Matrix3d::Identity();
  uint64_t view_index = 0;  // part of the sample seed.
};

// ∂(world position)/∂(position parameters) of point light `light` in `view`: the identity for a
// world-frame light, Rᵀ (the camera's world-from-camera rotation) for a camera-frame one.
Eigen::Matrix3d LightPositionJacobian(const ViewSetup& view, const PointLight& light);

// ∂(world direction)/∂(direction parameters v) of directional light `light` in `view`:
// (I − d dᵀ)·M/|v| with d the world direction and M the identity for a world-frame light, Rᵀ for
// a camera-frame one (d = M·v/|v|).
Eigen::Matrix3d LightDirectionJacobian(const ViewSetup& view, const DirectionalLight& light);

// Counters of one render: rays (for throughput measurements) and values lost to overflow.
struct RenderStats {
  int64_t camera_rays = 0;
  int64_t shadow_rays = 0;
  int64_t bounce_rays = 0;
  // Samples dropped because a value was not finite: a camera sample whose radiance or any of its
  // derivative terms (interior or secondary-edge) is not finite — its radiance and all its terms
  // are left out of the pixel — and edge samples whose jump or entries are not finite.
  int64_t nonfinite_samples = 0;
  // Output values that are not finite as floats: image pixel values (written as they are) and
  // Jacobian row / adjoint entries (dropped). Non-zero means the render cannot be trusted, e.g.
  // the reconstruction rejects the step.
  int64_t nonfinite_outputs = 0;
  // Adjoint gradient terms (parameter, value) held between the tiles and their reduction into
  // the gradient: the storage of the adjoint pass beyond the gradient itself.
  int64_t gradient_terms = 0;
  double seconds = 0.0;
  int64_t TotalRays() const { return camera_rays + shadow_rays + bounce_rays; }
  int64_t NonFinite() const { return nonfinite_samples + nonfinite_outputs; }
  // Adds the other's counters (not its seconds).
  void AddCounts(const RenderStats& other) {
    camera_rays += other.camera_rays;
    shadow_rays += other.shadow_rays;
    bounce_rays += other.bounce_rays;
    nonfinite_samples += other.nonfinite_samples;
    nonfinite_outputs += other.nonfinite_outputs;
    gradient_terms += other.gradient_terms;
  }
};

// Renders one view into `image` (width × height × 4: RGB of the pass, alpha = pixel coverage,
// i.e. the fraction of samples whose camera ray hit the mesh). Pixel values are averages over
// the pixel's area (box filter). For the color pass the values are radiance; for albedo and
// roughness they are the first-hit material averaged over the pixel (0 where nothing is hit,
// i.e. premultiplied by coverage, like Cycles' DiffCol pass); normal = world-space geometric
// normal facing the camera; depth = camera-frame z.
// Ray conventions of the renderer, shared with benchmarks that replay its rays.
// Rays leave surfaces offset by this fraction of the local surface scale (SurfaceScale). The
// scale is local so that a far-away part of the mesh (a stray vertex, a sliver reaching far out)
// does not change the offsets, hence the image, of the rest.
constexpr double kRelativeRayOffset = 2e-5;
// Point lights closer than this (relative to the local surface scale) to a shaded point are
// skipped: I/d² would overflow, and a light inside the surface lights nothing physical.
constexpr double kMinRelativeLightDistance = 1e-9;
// The scale of float rounding at point p of face `face`: max(FaceScale(face), |p|∞), the
// magnitude of the coordinates Embree computes with there (its float copy of the face's corners,
// and ray origins at p). Like pbrt's error bounds, but one conservative factor for all
// (kRelativeRayOffset = 2e-5 is ~170 float ulps).
double SurfaceScale(const RenderScene& scene, int face, const Eigen::Vector3d& p);
// The offset for a ray leaving face `face` at p: kRelativeRayOffset · SurfaceScale.
double SurfaceRayOffset(const RenderScene& scene, int face, const Eigen::Vector3d& p);

// Sample s of pixel (x, y): resets *sampler to that sample's stream, draws the sub-pixel position
// (its first Next2D) and returns the unit world direction of the camera ray.
Eigen::Vector3d CameraSampleDirection(const ViewSetup& view,
                                      const Eigen::Matrix3d& world_from_cam_rotation, uint64_t seed,
                                      int x, int y, int s, Sampler* sampler);

void RenderView(const RenderScene& scene, const Material& material, const ViewSetup& view,
                const RenderOptions& options, Image* image, RenderStats* stats = nullptr);

// The parameter index space of a scene and material with `num_lights` dataset lights.
ParameterLayout MakeParameterLayout(const RenderScene& scene, const Material& material,
                                    int num_lights);

// RenderView plus derivatives of the (color pass) image from the same sample paths (see
// derivatives.h). `num_lights` sizes the light-scale parameters (the dataset's light count).
// `request` must pass Check().
void RenderViewWithDerivatives(const RenderScene& scene, const Material& material,
                               const ViewSetup& view, const RenderOptions& options,
                               const DerivativeRequest& request, int num_lights, Image* image,
                               DerivativeOutput* output, RenderStats* stats = nullptr);
// The same with the index space given: MakeParameterLayout's plus, for a fitted environment,
// `num_environment_texels` and `environment_light` (the view's environment must then be that
// light's map, of that many texels, wherever the view uses it), and `light_positions` (each
// point light's position parameters, PointLight::camera_frame).
void RenderViewWithDerivatives(const RenderScene& scene, const Material& material,
                               const ViewSetup& view, const RenderOptions& options,
                               const DerivativeRequest& request, const ParameterLayout& layout,
                               Image* image, DerivativeOutput* output,
                               RenderStats* stats = nullptr);

}  // namespace sft

#endif  // SFT_RENDER_RENDER_H_
