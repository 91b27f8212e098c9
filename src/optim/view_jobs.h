// The unit of work of the render cache: one fitted view rendered in one pass at one point of the
// fit. A job's result depends only on the job and the point (scene, material, light scales,
// render options: the RenderState), never on the process or thread that renders it: each view's
// samples are seeded by the job's seed and the dataset view index (ViewSetup::view_index), and
// the renderer reduces in tile order. This is what lets the views of a reconstruction be spread
// over MPI ranks (src/optim/mpi_views.h) with results identical to a single process.
//
// The render cache builds the jobs of one evaluation and hands them to a ViewRunner, which
// renders them (all locally, or a share on each rank) and gives back each result in job order, so
// that everything summed over views (the adjoint gradient) is summed in the same order however
// the views were spread.
#ifndef SFT_OPTIM_VIEW_JOBS_H_
#define SFT_OPTIM_VIEW_JOBS_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "src/core/image.h"
#include "src/geometry/material.h"
#include "src/io/scene_setup.h"
#include "src/optim/pose_corrections.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {

// What a job renders: the image only, the image with Jacobian rows (LM, dogleg), or the image
// with the adjoint gradient Jᵀw for the job's weights (L-BFGS, Adam).
enum class ViewPass : int32_t { kImage = 0, kRows = 1, kAdjoint = 2 };

struct ViewJob {
  int view = 0;  // the render cache's view index (RenderState::view_indices maps it).
  ViewPass pass = ViewPass::kImage;
  uint64_t seed = 0;  // RenderOptions::seed of this render.
  Image weights;      // kAdjoint: the per-pixel RGB weights w (exposure gains applied).
};

struct ViewResult {
  Image image;                   // the render as RenderView returns it (RGBA, ungained).
  JacobianRows rows;             // kRows: the renderer's rows (light entries at scale 1·s_l).
  std::vector<double> gradient;  // kAdjoint: layout-size Jᵀw (light entries at scale 1·s_l).
  // kAdjoint with the request's gradient_parts: the gradient split by derivative term. Filled in
  // the process that renders the job only (the effect planner's own renders); not sent between
  // ranks.
  GradientParts gradient_parts;
  int64_t non_finite = 0;  // RenderStats::NonFinite() of the render.
  double seconds = 0.0;    // the render's wall time on the rank that ran it.
};

// The point every job of one evaluation is rendered at.
struct RenderState {
  // Identifies the RenderScene (its faces and the positions its BVH was built from). The scene
  // of a new id is built from `build_positions` and then moved to `positions`, as the render
  // cache's own scene is (an Embree refit keeps the first build's tree, so two scenes agree to
  // the bit only with the same first positions).
  int64_t scene_id = 0;
  std::vector<Eigen::Vector3d> build_positions;
  std::vector<Eigen::Vector3i> faces;
  std::vector<Eigen::Vector3d> positions;  // current vertex positions.
  Material material;                       // mesh colors (no UV textures).
  std::vector<double> light_scales;        // per dataset light.
  // Fitted point-light positions per dataset light, each in its light's frame (world, or the
  // camera frame of a flash); empty = the dataset's (SceneParameters::LightPositions).
  std::vector<Eigen::Vector3d> light_positions;
  // Fitted directional-light directions per dataset light (v, the light travelling along v/|v|
  // in its frame); empty = the dataset's (SceneParameters::LightDirections).
  std::vector<Eigen::Vector3d> light_directions;
  // Fitted environment rotations per dataset light (rotation vectors in radians, in each
  // environment's frame); empty = the dataset's alignment (SceneParameters::
  // EnvironmentRotations).
  std::vector<Eigen::Vector3d> environment_rotations;
  // Pose corrections per render-cache view (src/optim/pose_corrections.h: each view renders at
  // exp(δ)·cam_from_world); empty = the dataset's poses.
  std::vector<PoseDelta> pose_corrections;
  RenderOptions render;       // spp, bounces, effects, threads, shading.
  DerivativeRequest request;  // derivative kinds and edge budgets (no weights).
  // The index space of rows and gradients (SceneParameters::layout): vertices, texels, lights
  // and a fitted environment's texels.
  ParameterLayout layout;
  int image_scale_log2 = 0;       // RenderCacheOptions::image_scale_log2.
  std::vector<int> view_indices;  // dataset view of each render-cache view.
  // A fitted environment's texels at this point (SceneParameters::EnvironmentTexels: the map of
  // dataset light layout.environment_light, RGB); empty without one.
  Image environment;
  // Where that map is fixed: the world, or each view's camera (LightSpec::frame).
  LightFrame environment_frame = LightFrame::kWorld;
};

// View `dataset_view` of `views` as the fit renders it: its camera downscaled by
// 2^-image_scale_log2, its lights' intensities times their scales and, when `light_positions` is
// not empty (one per dataset light, in the light's frame), its point lights at those positions
// (a camera-frame light at C + Rᵀ·offset), and when `light_directions` is not empty its
// directional lights travelling along v/|v| (Rᵀ·v/|v| for a camera-frame light).
ViewSetup ScaledViewSetup(const DatasetViews& views, int dataset_view, int image_scale_log2,
                          const std::vector<double>& light_scales,
                          const std::vector<Eigen::Vector3d>& light_positions = {},
                          const std::vector<Eigen::Vector3d>& light_directions = {});

// The renderer's maps of a fitted environment's texels: one map when the light is world-fixed,
// one per dataset view when it is camera-fixed (LightSpec::frame; ViewWorldFromEnv).
class FittedEnvironmentMaps {
 public:
  // Rebuilds the maps when `texels` (RGB) differ from the last call's, for light `light` of
  // `dataset`.
  void Update(const Image& texels, const Dataset& dataset, int light);
  // The map view `dataset_view` renders with; null before the first Update.
  const EnvironmentMap* ForView(int dataset_view) const;
  const Image& texels() const { return texels_; }

 private:
  Image texels_;
  bool per_view_ = false;
  std::vector<std::unique_ptr<EnvironmentMap>> maps_;  // one, or one per dataset view.
};

// The renderer's maps of given probes turned by their fitted rotations θ (ParameterLayout::
// environment_rotations): a world-fixed probe's map turned by exp([θ]×) once, a camera-fixed
// probe's per view by Rᵀ·exp([θ]×)·R (R the view's cam_from_world rotation).
class RotatedEnvironmentMaps {
 public:
  // Rebuilds the maps when `rotations` (one per dataset light; empty: none) differ from the last
  // call's, from the dataset's maps in `views`.
  void Update(const std::vector<Eigen::Vector3d>& rotations, const DatasetViews& views);
  // Makes dataset view `dataset_view`'s setup render with its environment turned, and sets its
  // ViewSetup::environment_rotation_jacobian; nothing without rotations.
  void Use(int dataset_view, ViewSetup* view) const;

 private:
  std::vector<Eigen::Vector3d> rotations_;
  // Per dataset view: its turned map (null when it has no environment) and the Jacobian.
  std::vector<std::shared_ptr<const EnvironmentMap>> maps_;
  std::vector<Eigen::Matrix3d> jacobians_;
};

// Makes dataset view `dataset_view`'s setup (its ScaledViewSetup, with the fitted light scales and
// places) render as the fit's state does, in the one order that is right:
//   1. the dataset's probes turned by their fitted rotations (`rotated`);
//   2. the fitted environment (the maps of the state's texels) in place of its light's map, when
//      `layout` fits that light: a fitted map's rotation is held at 0 (a pose fit still needs its
//      parameter for the chain), so step 1 only turned the start map, which this replaces;
//   3. the view's pose correction (`pose`; null: none), which moves the camera of the lit scene.
void UseFittedLightingAndPose(const RotatedEnvironmentMaps& rotated, const ParameterLayout& layout,
                              const FittedEnvironmentMaps& fitted, int dataset_view,
                              const PoseDelta* pose, ViewSetup* view);

// Renders `job` of `view` (its ScaledViewSetup, UseFittedLightingAndPose) on `scene` with
// `material` and the options, its rows or gradient in `layout`'s index space; the request's
// jacobian_rows and adjoint_weights follow the job's pass.
void RenderViewJob(const RenderScene& scene, const Material& material, const ViewSetup& view,
                   const RenderOptions& render, const DerivativeRequest& request,
                   const ParameterLayout& layout, const ViewJob& job, ViewResult* result);

// Renders the jobs of one evaluation. `local` renders one job in this process (on the render
// cache's own scene); `consume` receives every job's result, in job order, exactly once.
class ViewRunner {
 public:
  using LocalRender = std::function<void(const ViewJob&, ViewResult*)>;
  using Consume = std::function<void(size_t job, ViewResult* result)>;
  virtual ~ViewRunner() = default;
  virtual void Run(const RenderState& state, const std::vector<ViewJob>& jobs,
                   const LocalRender& local, const Consume& consume) = 0;
};

// The runner render caches created from now on use; null (the default) renders every job in
// this process. `sft reconstruct` under mpirun installs its MPI runner on rank 0 for the run.
void SetViewRunner(ViewRunner* runner);
ViewRunner* CurrentViewRunner();

}  // namespace sft

#endif  // SFT_OPTIM_VIEW_JOBS_H_
