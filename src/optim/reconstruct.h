// One fit of the reconstruction (a stage of the schedule, src/optim/schedule.h): outer iterations,
// each one phase or two (texture, then geometry) of at most `solver.steps` solver iterations with a
// fixed seed; fresh seeds per outer iteration. Each outer iteration of a trust-region solver builds
// a new problem (supersets from renders at the current state), so that pixel supersets follow the
// moving mesh.
#ifndef SFT_OPTIM_RECONSTRUCT_H_
#define SFT_OPTIM_RECONSTRUCT_H_

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/optim/effect_planner.h"
#include "src/optim/regularizers.h"
#include "src/optim/render_cache.h"
#include "src/optim/solvers.h"

namespace sft {

enum class PhaseSchedule { kTexture, kGeometry, kAlternate };
bool PhaseScheduleFromName(const std::string& name, PhaseSchedule* schedule);
const char* PhaseScheduleName(PhaseSchedule schedule);

struct ReconstructOptions {
  RenderCacheOptions cache;  // render (spp, bounces, effects, threads), pyramid, mask.
  // "effects": "auto": the planner chooses, before every outer iteration, which of cache's
  // effects and edge budgets (the ceiling) the fit uses. Disabled = they are used as configured.
  EffectPlannerOptions planner;
  ProblemOptions problem;                            // supersets and bounds.
  SolverOptions solver;                              // which solver and its options.
  RegularizerOptions regularizers;                   // Laplacian and texel smoothness weights.
  PhaseSchedule phases = PhaseSchedule::kAlternate;  // texture, geometry or both alternating.
  int outer_iterations = 4;   // outer iterations (fresh seeds each), [1, 10000].
  bool fit_albedo = true;     // the texture phase fits the albedo texels (false: held as given).
  bool fit_roughness = true;  // the texture phase fits the roughness texels (false: held).
  bool fit_specular = false;  // the texture phase also fits the specular weight.
  bool fit_lights = false;    // the texture phase also fits the light intensity scales.
  // The texture phase also fits the point lights' positions (3 per light: a world-frame light's
  // world position, a camera-frame light's offset in the camera frame; docs/reconstruct.md,
  // "Fitted point lights").
  bool fit_light_positions = false;
  // The texture phase also fits the directional lights' directions (3 numbers v per light in its
  // frame, the light travelling along v/|v|; docs/reconstruct.md, "Fitted directional lights").
  bool fit_light_directions = false;
  // The texture phase also refines the rotation of each given probe (environment light): a
  // rotation vector θ per probe, radians, in its frame, 0 at the dataset's alignment and bounded
  // by ParameterBounds::environment_rotation_max (docs/reconstruct.md, "Probe rotation").
  bool fit_environment_rotation = false;
  // The texture phase also fits per-view exposure gains (3 per fitted view, the first fitted view
  // the fixed gauge; src/optim/parameters.h, kExposureGaugeView).
  bool fit_exposure = false;
  // The texture phase also refines each fitted view's camera pose: 6 numbers per view (rotation
  // vector and translation in the camera frame, src/optim/pose_corrections.h), the first fitted
  // view the fixed gauge, bounded by ParameterBounds::pose_rotation_max and pose_translation_max
  // (docs/reconstruct.md, "Camera poses").
  bool fit_poses = false;
  // The texture phase also fits the fitted environment's texels (unknown lighting,
  // src/optim/fitted_environment.h); without a fitted environment it changes nothing. Off by
  // default: `sft reconstruct` fits the map in an automatic first stage with the material held
  // (schedule_config.h, EnvironmentStage) and holds it after, since fitted with the albedo the
  // map and the albedo trade shading between them.
  bool fit_environment = false;
  uint64_t seed = 1;       // base seed of the renders.
  std::vector<int> views;  // dataset views to fit; empty = all.
  // Shading of the fit's renders: "auto" (the dataset's, DatasetShading in src/io/scene_setup.h:
  // its ground_truth.shading, else smooth), "flat" or "smooth". Create resolves it into
  // cache.render.shading.
  std::string shading = "auto";

  ReconstructOptions();
  bool Check(std::string* why) const;
};

// One solver iteration, as metrics.csv writes it.
struct IterationRecord {
  int outer = 0;         // over the whole run (all stages).
  std::string stage;     // the schedule's stage name ("" outside a schedule).
  std::string phase;     // "texture" | "geometry".
  int iteration = 0;     // within the phase's solve.
  double cost = 0.0;     // objective (image + regularizers) at the accepted point.
  double seconds = 0.0;  // wall time since the start of the run (resumed runs continue it).
  bool accepted = false;
  bool full = false;  // Adam's closing evaluation of all views, not a step (IterationInfo::full).
  std::vector<double> view_psnr;  // level-0 PSNR over active pixels, peak 1, per fitted view.
};

// One phase of one outer iteration.
struct PhaseRecord {
  int outer = 0;
  std::string phase;
  SolverRunStats stats;
  int64_t non_finite_values = 0;  // in the last render.
};

class Reconstruction {
 public:
  // `mesh` and `material` are the initial state (copied). `light_scales` may be empty (all 1).
  // `view_gains` are the exposure gains per dataset view (empty = all 1; otherwise one per
  // dataset view): the fitted views' gains start from them. `view_poses` likewise the pose
  // corrections per dataset view (empty = all zero).
  static Status Create(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                       const std::vector<double>& light_scales, const ReconstructOptions& options,
                       std::unique_ptr<Reconstruction>* out,
                       const std::vector<Eigen::Vector3d>& view_gains = {},
                       const Image& environment = Image(),
                       const std::vector<Eigen::Vector3d>& light_positions = {},
                       const std::vector<Eigen::Vector3d>& light_directions = {},
                       const std::vector<Eigen::Vector3d>& environment_rotations = {},
                       const std::vector<PoseDelta>& view_poses = {});

  // Runs the effect planner for outer iteration `outer` (its renders use the chosen plan from
  // now on). The ceiling is the configured effects and budgets; `image_signal_scale` and
  // `step_signal_scale` are PlannerContext's (0 = none).
  Status PlanEffects(int outer, EffectPlanReport* report, double image_signal_scale = 0.0,
                     double step_signal_scale = 0.0);

  // Runs outer iteration `outer` (its phases). `on_iteration` is called after every solver
  // iteration; returning false stops the run (the state so far is kept).
  Status RunOuter(int outer, const std::function<bool(const IterationRecord&)>& on_iteration);

  // The pose prior's weight this run uses: RegularizerOptions::pose_prior, its auto value resolved
  // from the fitted views' lights.
  double ResolvedPosePrior() const;

  // The current state.
  TriMesh Mesh() const;
  Material CurrentMaterial() const;  // unsampled texels filled from their neighbours.
  std::vector<double> LightScales() const { return params_.LightScales(); }
  // The point lights' position parameters per dataset light, each in its light's frame (empty
  // when they are not parameters).
  std::vector<Eigen::Vector3d> LightPositions() const { return params_.LightPositions(); }
  // The directional lights' direction parameters per dataset light (empty when they are not
  // parameters).
  std::vector<Eigen::Vector3d> LightDirections() const { return params_.LightDirections(); }
  // The environments' rotation parameters per dataset light (empty when they are not
  // parameters).
  std::vector<Eigen::Vector3d> EnvironmentRotations() const {
    return params_.EnvironmentRotations();
  }
  // The fitted environment's texels (empty without one).
  Image EnvironmentTexels() const { return params_.EnvironmentTexels(); }
  // The exposure gains per dataset view: the fitted views' current ones, the others' as given to
  // Create (1 when none were given).
  std::vector<Eigen::Vector3d> ViewGains() const;
  // The pose corrections per dataset view: the fitted views' current ones, the others' as given
  // to Create (zero when none were given).
  std::vector<PoseDelta> ViewPoses() const;
  // Renders every fitted view at the current state (seed `seed`) and returns level-0 images.
  std::vector<Image> RenderViews(uint64_t seed);
  // The normal pass of fitted view `v` at the current state (RGB: world-space geometric normals
  // facing the camera; alpha: coverage), at the dataset's resolution.
  Image RenderNormals(int v);
  const RenderCache& cache() const { return *cache_; }
  const std::vector<PhaseRecord>& phases() const { return phase_records_; }
  const std::vector<int>& view_indices() const { return cache_->view_indices(); }
  // Adam's moments (kept across outer iterations; empty before the first Adam phase), for
  // checkpoints. SetAdamState refuses (false, state unchanged) moments whose size is not the
  // parameter layout's, or m and v of different sizes.
  const AdamState& adam_state() const { return adam_; }
  bool SetAdamState(const AdamState& state);
  double elapsed_offset = 0.0;  // seconds of earlier (resumed) runs, added to records.

 private:
  Reconstruction() = default;

  const Dataset* dataset_ = nullptr;
  ReconstructOptions options_;
  TriMesh mesh_;
  std::vector<Eigen::Vector3i> faces_;
  Material material_;
  DatasetViews views_;
  SceneParameters params_;
  std::unique_ptr<RenderCache> cache_;
  AdamState adam_;
  std::vector<PhaseRecord> phase_records_;
  std::vector<Eigen::Vector3d> view_gains_;  // per dataset view, as given to Create.
  std::vector<PoseDelta> view_poses_;        // per dataset view, as given to Create.
  double start_time_ = 0.0;
};

// Faces of `mesh` whose normal turned by more than 90° from the same face of `initial`, and faces
// of (nearly) zero area (≤ 1e-12 × the squared bounding-box diagonal): what a geometry fit must
// not leave behind.
struct MeshQuality {
  int flipped_faces = 0;
  int degenerate_faces = 0;
};
MeshQuality CompareMeshQuality(const TriMesh& initial, const TriMesh& mesh);

// Peak-1 PSNR of a mean squared error (capped at 100 dB for a zero error).
double PsnrFromMse(double mse);

}  // namespace sft

#endif  // SFT_OPTIM_RECONSTRUCT_H_
