// The render cache (docs/reconstruct.md): a ceres::EvaluationCallback that, before Ceres evaluates
// a point, moves the mesh (refitting one Embree scene), writes the material and light scales from
// the flat parameter vector, renders every view once — with Jacobian rows of the active parameter
// kinds whenever Ceres may ask for them — and turns each render into its pyramid levels and their
// rows. Residual blocks (cost_functions/pyramid_pixel.h) then only copy from it.
//
// Rows are rendered at every new point, also at trial points evaluated for their cost only:
// Ceres asks for the Jacobian of an accepted point after evaluating its cost, and rendering with
// rows once costs less than rendering twice. All renders of one outer iteration use the same seed
// (common random numbers: a cost decrease between a trial and the linearization point is not
// sampling noise); SetSeed starts a new outer iteration.
//
// Exposure gains: when the parameters hold gains (SceneParameters::Gains), fitted view v's stored
// render is g_v ⊙ I_v (channel c times g_vc) on every level — the pyramid is linear, so level l is
// g ⊙ P_l(I) — and its rows are those of g ⊙ I: every entry is scaled by g_c, and when the phase
// fits exposure (ActiveParameters::exposure) and v is not the gauge view, each pixel gains the
// entries ∂(g_c I_c)/∂g_c = I_c. The adjoint pass likewise hands the renderer the weights times
// g and adds Σ_p w_pc I_pc to the gains' gradient. The gains are exact (linear); I_c is the Monte
// Carlo render of the same pass.
//
// Pose corrections: when the parameters hold them (SceneParameters::AddPoses), view v renders at
// its corrected pose, and when the phase fits poses (ActiveParameters::poses) and v is not the
// gauge view, each pixel gains the six entries ∂(g ⊙ I)/∂δ_v, contracted from the rows of the
// vertices and world-fixed lights, which are rendered for that even when the phase does not fit
// them (and then dropped); the adjoint pass contracts the gradient the same way.
//
// Every render but RenderPassImage's is a ViewJob (view_jobs.h) run by the ViewRunner installed
// when the cache was created (CurrentViewRunner): in this process, or spread over MPI ranks
// (mpi_views.h). Results come back in view order, so the stored renders, rows and gradient sums
// are the same to the bit either way.
#ifndef SFT_OPTIM_RENDER_CACHE_H_
#define SFT_OPTIM_RENDER_CACHE_H_

#include <ceres/evaluation_callback.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/optim/effect_planner.h"
#include "src/optim/parameters.h"
#include "src/optim/pyramid.h"
#include "src/optim/view_jobs.h"
#include "src/render/render.h"

namespace sft {

// The image term's per-pixel weighting (docs/reconstruct.md, "The image loss").
//   kL2        every pixel weighs 1: ½ Σ (I − T)².
//   kRelative  pixel p weighs √w_p = 2m / (m + ȳ_p), ȳ_p the target's mean over RGB at p and m
//              the median of ȳ over the view's active, non-black level-0 pixels: a median
//              pixel weighs 1,
//              a highlight k times brighter than the median about 2/(k + 1). Monte Carlo noise
//              grows with a pixel's radiance, so a few bright, noisy highlight pixels otherwise
//              decide every step (the relative MSE of Rousselle et al. 2011, with the target in
//              the denominator so the loss stays unbiased in the render).
enum class ImageLoss { kL2, kRelative };
bool ImageLossFromName(const std::string& name, ImageLoss* loss);
const char* ImageLossName(ImageLoss loss);

struct RenderCacheOptions {
  RenderOptions render;       // spp, bounces, effects, threads (seed: see SetSeed).
  DerivativeRequest edges;    // edge-sampling budgets of vertex derivatives (params ignored).
  int pyramid_levels = 4;     // levels 0..L−1 (level l has 2^-l of the resolution), [1, 12].
  double level_weight = 1.0;  // level l's residuals are weighted by level_weight^l, (0, 64].
  double image_weight = 1.0;  // weight of the whole image term, [0, 1e6]; 0 = regularizers only.
  int mask_dilation = 2;      // level-0 pixels within this many pixels of the mask count, [0, 64].
  // The fit's images are the dataset's at 2^-image_scale_log2 of their resolution: targets and
  // masks are box-downsampled (BuildPyramid, MaskPyramid) and cameras scaled (DownscaledCamera);
  // [0, 6]. Pyramid levels are counted from that scale.
  int image_scale_log2 = 0;
  // The filter between pyramid levels (src/optim/pyramid.h), of renders, targets, Jacobian rows,
  // masks and the adjoint alike: kBox (2 × 2 means) or kBinomial ([1 2 1]/4 separable).
  PyramidFilter pyramid_filter = PyramidFilter::kBox;
  ImageLoss image_loss = ImageLoss::kL2;  // per-pixel weighting of the image term (above).
  // The adjoint (gradient) pass draws its own paths, with a seed independent of the render the
  // residual comes from. With one set of paths for both, E[(R̂ − y)·∂R̂] = (E R̂ − y)·∂E R̂ +
  // ½∂Var R̂: the gradient also descends the render's variance, so glossy, low-roughness and
  // high-specular states are pushed away (the bias Azinović et al. 2019, "Inverse Path Tracing",
  // avoid with two independent sample sets).
  // Independent paths make the gradient an unbiased estimate of the noise-free loss's. Used by
  // the first-order solvers (the adjoint pass); LM's rows come from the residual's own pass.
  bool independent_gradient = false;
  // The glossy lobe in the adjoint (gradient) pass. false: the first-order solvers step along the
  // gradient of the image without the lobe, weighted by the residual of the image with it (when
  // the plan renders it). The lobe's vertex derivative is the noisiest part of the step on glossy
  // objects (docs/design-notes.md, "Why the glossy dragon's geometry does not move"), while a
  // residual without the lobe leaves highlights the geometry then tries to explain: with the lobe
  // in the residual, a shape whose full render matches the photographs stays a stationary point
  // of the step. A biased direction elsewhere (not the loss's gradient); no effect on LM's rows.
  bool gradient_specular = true;

  bool Check(std::string* why) const;
};

// Per view: the targets and the active pixels of every level.
struct ViewTargets {
  std::vector<std::vector<uint8_t>> active;  // per level, 1 = the pixel has a residual block.
  bool has_mask = false;
};

class RenderCache : public ceres::EvaluationCallback {
 public:
  // Loads the targets (images and masks) of `view_indices`. `params` is the state that Ceres
  // updates (its blocks point into params->values()); it and `dataset`/`views` must outlive the
  // cache. `material` gives the texel layout and fresnel mode.
  static Status Create(const Dataset& dataset, const DatasetViews* views,
                       const std::vector<int>& view_indices,
                       const std::vector<Eigen::Vector3i>& faces, const Material& material,
                       SceneParameters* params, const RenderCacheOptions& options,
                       std::unique_ptr<RenderCache>* cache);

  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;

  // Renders view v's `pass` (RenderOptions::pass) at the current parameters and the dataset's
  // full resolution (not stored).
  Image RenderPassImage(int v, RenderPass pass);
  // Renders every view at the current parameters: rows of the `active` kinds when `rows`.
  void Render(bool rows);
  // Renders and stores only `views` (no rows), e.g. for their AdjointWeights; the next evaluation
  // renders every view anew. Returns finite() (false when a sample or output was not finite).
  bool RenderSome(const std::vector<int>& views);
  // The seed of the renders from now on (a new outer iteration).
  void SetSeed(uint64_t seed) {
    stale_ = stale_ || seed != seed_;
    seed_ = seed;
  }
  uint64_t seed() const { return seed_; }
  void SetActive(const ActiveParameters& active) { active_ = active; }
  const ActiveParameters& active() const { return active_; }
  // The effects and derivative budgets of the renders from now on (the effect planner's result).
  // The stored render no longer matches them: the next evaluation renders anew.
  void SetPlan(const EffectPlan& plan) {
    plan.ApplyTo(&options_.render, &options_.edges);
    stale_ = true;
  }
  EffectPlan plan() const { return EffectPlan::From(options_.render, options_.edges); }
  const RenderCacheOptions& options() const { return options_; }

  // For measurements at the fit's scale (the effect planner): view v's colour image (RGB, level
  // 0, gains applied) under `plan` with `seed`, not stored. False when the render is not finite.
  bool RenderWith(int v, const EffectPlan& plan, uint64_t seed, Image* image);
  // RenderWith of every view in `views` (their renders may run on other ranks): (*images)[k] is
  // views[k]'s. False when any is not finite.
  bool RenderWith(const std::vector<int>& views, const EffectPlan& plan, uint64_t seed,
                  std::vector<Image>* images);
  // Like AddAdjointGradient, under `plan` with `seed`.
  bool AddAdjointGradientWith(int v, const Image& weights, const EffectPlan& plan, uint64_t seed,
                              std::vector<double>* gradient);
  // AddAdjointGradientWith of every view in `views` with its `weights`, added to *gradient in the
  // order of `views` (the views' renders may run on other ranks). False when any is not finite.
  // With `parts` (each part the size of *gradient), the same passes also add their gradient split
  // by derivative term (GradientParts; the exposure gains' entries go to DerivativeTerm::kRest),
  // so that Σ parts grows by what *gradient grows by; such passes run in this process, because
  // the parts do not travel between ranks.
  bool AddAdjointGradientsWith(const std::vector<int>& views, const std::vector<Image>& weights,
                               const EffectPlan& plan, uint64_t seed, std::vector<double>* gradient,
                               GradientParts* parts = nullptr);

  int num_views() const { return static_cast<int>(levels_.size()); }
  int num_levels(int v) const { return static_cast<int>(levels_[v].size()); }
  const LevelCache& level(int v, int l) const { return *levels_[v][l]; }
  const ViewTargets& targets(int v) const { return targets_[v]; }
  // Whether the last render (image and rows) was finite everywhere, with no sample dropped as
  // not finite (RenderStats::NonFinite); the cost functions fail (reject the step) otherwise.
  const bool* finite() const { return &finite_; }
  // Number of non-finite values in the last render: RenderStats' dropped samples and non-finite
  // outputs, plus row entries made non-finite by light-scale division.
  int64_t non_finite_values() const { return non_finite_; }

  // ½ Σ r² of the image residuals over the active pixels of every level, at the last render.
  double ImageCost() const;
  // The image term's curvature in view v's gains at a render equal to the photograph: per channel
  // c, Σ_l Σ_p w_l w_lp T_lpc² over the active pixels of every level (the exposure prior's scale,
  // cost_functions/exposure_prior.h). Depends on the targets only.
  Eigen::Vector3d GainCurvature(int v) const;
  // The image term's curvature along each component of view v's pose correction (ω then τ, camera
  // frame), approximately (for the pose prior, cost_functions/pose_prior.h): the targets' gradient
  // energy Σ_l Σ_p w_l² w_lp² Σ_c |∇T_lpc|² (central differences over the active pixels whose
  // neighbours are active) times the squared image motion, in level-l pixels, per unit of the
  // component: f_l² for a pan or tilt (a turn of 1 rad slides the image by about f pixels), r_l²
  // for the roll (a pixel r from the principal point moves by r), (f_l/z)² for a sideways shift
  // and (r_l/z)² for a move along the optical axis (the image scales about the principal point by
  // 1/z), with f_l and r_l in level-l pixels at the fit's scale and z the depth of
  // `object_centre` (world) in the view. Depends on the targets only.
  Eigen::Matrix<double, 6, 1> PoseCurvature(int v, const Eigen::Vector3d& object_centre) const;
  // The part of ImageCost from view v.
  double ViewImageCost(int v) const;
  // Mean squared error of level 0 over its active pixels and RGB, per view, at the last render.
  std::vector<double> ViewMse() const;
  // The last render of view v (level 0, RGB) and its target.
  const Image& Rendered(int v) const { return levels_[v][0]->render; }
  const Image& Target(int v) const { return levels_[v][0]->target; }

  // Statistics for reports.
  int64_t renders() const { return renders_; }
  double render_seconds() const { return render_seconds_; }
  double pyramid_seconds() const { return pyramid_seconds_; }
  size_t RowMemoryBytes() const;

  const std::vector<int>& view_indices() const { return view_indices_; }
  // The material of the last render (texel layout: resolutions, fresnel mode).
  const Material& material() const { return material_; }
  const SceneParameters& params() const { return *params_; }

  // The adjoint weight image of view v for the gradient of ImageCost: Σ_l w_l D_lᵀ(P_l(I) − P_l(T))
  // over active pixels (D_lᵀ the adjoint of the pyramid's downsampling chain), as RGB.
  Image AdjointWeights(int v) const;
  // Renders view v at the current parameters with the adjoint gradient for `weights`
  // (no rows stored); adds it to *gradient (layout size). Returns false on non-finite output or
  // samples dropped as not finite (RenderStats::NonFinite).
  bool AddAdjointGradient(int v, const Image& weights, std::vector<double>* gradient);
  // AddAdjointGradient of every view in `views` with its AdjointWeights, added to *gradient in
  // the order of `views` (the views' renders may run on other ranks). False when any is not
  // finite.
  bool AddAdjointGradients(const std::vector<int>& views, std::vector<double>* gradient);

 private:
  RenderCache() = default;
  void UpdateScene();
  ViewSetup ScaledView(int v) const;
  void StoreRender(int v, const Image& image, const JacobianRows* rows);
  // Runs `jobs` at the current parameters through the runner (or here) and hands each result to
  // `consume` in job order; render_seconds_ gets the wall time outside `consume`. The renders use
  // the cache's options and ActiveRequest, or `render` and `request` (a plan's). A request for
  // gradient parts runs here: the parts do not travel between ranks.
  void RunJobs(const std::vector<ViewJob>& jobs, const ViewRunner::Consume& consume);
  void RunJobs(const std::vector<ViewJob>& jobs, const RenderOptions& render,
               const DerivativeRequest& request, const ViewRunner::Consume& consume);
  RenderState CurrentState(const RenderOptions& render, const DerivativeRequest& request) const;
  // The adjoint jobs of `views` (weights ungained) under `render` and `request` with `seed`, their
  // gradients added to *gradient in the order of `views`. False when any is not finite.
  bool RunAdjointJobs(const std::vector<int>& views, const std::vector<Image>& weights,
                      const RenderOptions& render, const DerivativeRequest& request, uint64_t seed,
                      std::vector<double>* gradient, GradientParts* parts = nullptr);
  DerivativeRequest ActiveRequest() const;
  // Whether the phase fits view v's pose correction, and the chain of its rows
  // (src/optim/pose_corrections.h) at the current parameters.
  bool FitsPose(int v) const;
  PoseChain ChainOf(int v) const;
  // Adds view v's adjoint result (of `weights`, ungained) to *gradient: light entries divided by
  // their scales, the exposure gains' part from the result's image. False when not finite.
  // With `parts`, adds the result's gradient parts there alike (the gains' part to kRest).
  bool AddGradientResult(int v, const Image& weights, const ViewResult& result,
                         std::vector<double>* gradient, GradientParts* parts = nullptr) const;

  const Dataset* dataset_ = nullptr;
  const DatasetViews* views_ = nullptr;
  std::vector<int> view_indices_;
  SceneParameters* params_ = nullptr;
  RenderCacheOptions options_;
  ActiveParameters active_;
  Material material_;
  std::unique_ptr<RenderScene> scene_;
  std::vector<Eigen::Vector3d> scene_positions_;
  // The fitted environment at the current parameters (SceneParameters::has_environment): the map
  // views of that light render with instead of the dataset's, rebuilt when its texels change.
  // The maps of the fitted environment's texels (SceneParameters::EnvironmentTexels).
  FittedEnvironmentMaps fitted_environment_;
  RotatedEnvironmentMaps rotated_environments_;  // given probes turned by their fitted rotations.
  // The scene's identity for other ranks (RenderState::scene_id), its faces and first positions.
  int64_t scene_id_ = 0;
  std::vector<Eigen::Vector3i> faces_;
  std::vector<Eigen::Vector3d> scene_build_positions_;
  ViewRunner* runner_ = nullptr;  // null: every job is rendered here.
  std::vector<ViewTargets> targets_;
  std::vector<std::vector<std::unique_ptr<LevelCache>>> levels_;
  uint64_t seed_ = 0;
  bool finite_ = true;
  bool has_rows_ = false;
  bool stale_ = false;  // the stored render is not of the current seed or plan.
  int64_t non_finite_ = 0;
  int64_t renders_ = 0;
  double render_seconds_ = 0.0;
  double pyramid_seconds_ = 0.0;
};

}  // namespace sft

#endif  // SFT_OPTIM_RENDER_CACHE_H_
