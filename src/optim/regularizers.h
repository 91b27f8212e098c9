// Regularizer residual blocks of the reconstruction (cost_functions/vertex_laplacian.h,
// cost_functions/face_orientation.h, cost_functions/proximal_smoothing.h,
// cost_functions/texel_smoothness.h, cost_functions/exposure_prior.h, cost_functions/pose_prior.h,
// cost_functions/environment_smoothness.h), added for the parameter
// kinds a phase varies.
#ifndef SFT_OPTIM_REGULARIZERS_H_
#define SFT_OPTIM_REGULARIZERS_H_

#include <ceres/problem.h>

#include <string>
#include <vector>

#include "src/geometry/mesh.h"
#include "src/optim/parameters.h"

namespace sft {

// RegularizerOptions::pose_prior: chosen from the lighting (ResolvedPosePrior).
constexpr double kPosePriorAuto = -1.0;
// The auto pose prior under world-fixed lights (docs/design-notes.md, "Pose refinement under
// world-fixed lights").
constexpr double kPosePriorWorldLights = 0.01;

struct RegularizerOptions {
  // Weight of the vertex Laplacian term (√ of the weight multiplies each residual), ≥ 0; 0 = off.
  // The residual is the Laplacian of the displacement from the phase's starting mesh, so the
  // term smooths the update without shrinking the shape. The default suits scenes normalised to
  // a bounding-box diagonal of 1 (as sft synth and the importers write them) and the image
  // residuals of radiance around 0.5 (docs/design-notes.md, "Reconstruction").
  double laplacian_weight = 30.0;
  bool cotangent = false;  // cotangent weights (at the starting mesh) instead of uniform ones.
  // The Laplacian of the shape itself (smooths and shrinks it: what removes i.i.d. vertex noise)
  // instead of the Laplacian of the displacement.
  bool laplacian_of_shape = false;
  // Weight of the fold barrier (cost_functions/face_orientation.h): faces that keep less than
  // `orientation_min_fraction` of their starting area facing their starting normal are pushed
  // back, ≥ 0; 0 = off.
  double orientation_weight = 10.0;
  double orientation_min_fraction = 0.25;  // in (0, 1).
  // μ of the smoothing proximal term μ/2·‖(I + λL)(x − x_a)‖² (cost_functions/proximal_smoothing.h:
  // the Levenberg–Marquardt form of Nicolet et al. 2021's "large steps" preconditioner); range
  // [0, ∞), finite (Check); 0 = off. Unit: cost per squared scene length (the residual is a
  // length), given for scenes normalised to a bounding-box diagonal of 1 like laplacian_weight
  // (for diagonal d the same effect needs μ/d²). x_a is the mesh at the start of the phase's
  // Solve: re-anchored per outer iteration. A large μ turns the LM step into −μ⁻¹(I + λL)⁻²∇ (the
  // large-steps update); μ → 0 gives plain LM.
  double proximal_weight = 0.0;
  // λ of the proximal term: smoothing strength of I + λL, L the combinatorial Laplacian D − A
  // (dimensionless); range [0, 1e6] (Check); 0 = plain Tikhonov damping. The paper uses 19 to 49,
  // Mitsuba 3's shape-optimisation tutorial 25.
  double proximal_lambda = 25.0;
  // Weight of albedo differences of neighbouring texels, ≥ 0; of their log ratios when the phase
  // also fits light scales or the environment, which can take over the albedo's scale
  // (cost_functions/texel_smoothness.h, the log-ratio form).
  double albedo_smoothness = 0.0;
  double roughness_smoothness = 0.0;  // the same for roughness, ≥ 0.
  // Relative weight λ of the exposure gains' prior towards 1 (cost_functions/exposure_prior.h:
  // ½·λ·E_vc·(g_vc − 1)² per gain, E_vc the view's photograph energy, the image term's curvature
  // in the gain), finite, ≥ 0: the prior counts λ times as much as the view's photograph; 0 = no
  // prior (the gauge view alone fixes the scale). The default pulls a gain by 1e-3 of its offset.
  double exposure_prior = 1e-3;
  // Relative weight λ of the pose corrections' prior towards the dataset's poses
  // (cost_functions/pose_prior.h: ½·λ·C·‖δ‖² per view, C the image term's curvature along a
  // correction that slides the image, RenderCache::PoseCurvature), finite, ≥ 0, or
  // kPosePriorAuto; 0 = no prior (the bounds alone). Holds the corrections the photographs hardly
  // see (under world-fixed lights, a turn about the object with the matching shift) while costing
  // those they see a fraction λ. Auto: kPosePriorWorldLights when no fitted view has a light that
  // rides with the camera, else 0 (a flash's shading tells that turn; docs/reconstruct.md).
  double pose_prior = kPosePriorAuto;
  // Weight of differences between neighbouring texels of a fitted environment
  // (cost_functions/environment_smoothness.h; unknown lighting), finite, ≥ 0; 0 = off. Residuals
  // are radiance differences, weighed against image residuals of radiance: 1 lets a few pixels'
  // evidence outweigh the prior, so texels seen through many pixels follow the images and
  // texels seen by none take their neighbours' values.
  double environment_smoothness = 1.0;

  bool Check(std::string* why) const;
};

// Adds the regularizers of the active kinds to `problem`. Their parameter blocks point into
// `params`; blocks new to the problem get the bounds of `bounds`. `rest` is the mesh whose
// positions the Laplacian measures displacements from and the proximal term is anchored at (and
// whose connectivity they use). `gain_curvature` holds E_v per fitted view for the exposure prior
// (RenderCache::GainCurvature); needed only when `active.exposure`. `pose_curvature` holds the
// curvature along each of the six pose-correction components per fitted view for the pose prior
// (RenderCache::PoseCurvature); needed only when `active.poses`.
void AddRegularizers(const TriMesh& rest, const ActiveParameters& active,
                     const RegularizerOptions& options, const ParameterBounds& bounds,
                     const Material& material, SceneParameters* params, ceres::Problem* problem,
                     const std::vector<Eigen::Vector3d>& gain_curvature = {},
                     const std::vector<Eigen::Matrix<double, 6, 1>>& pose_curvature = {});

}  // namespace sft

#endif  // SFT_OPTIM_REGULARIZERS_H_
