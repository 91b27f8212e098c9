// The reconstruction's state as one flat vector in the renderer's parameter layout
// (ParameterLayout, src/render/derivatives.h): x[i] is parameter i — vertex coordinates, albedo
// texels (RGB), roughness texels, the specular weight, one intensity scale per dataset light, the
// texels of a fitted environment (RGB radiance; src/optim/fitted_environment.h), and with
// AddLightPositions three position coordinates per dataset light (a point light's position in its
// own frame: world, or the camera frame for a flash; ParameterLayout::light_positions), with
// AddLightDirections three direction numbers per dataset light (ParameterLayout::
// light_directions), with AddEnvironmentRotations a rotation vector per dataset light
// (ParameterLayout::environment_rotations) —
// followed by the fit-only exposure gains: 3 per fitted view (R, G, B), which multiply that view's
// rendered image before the residual (the renderer never sees them; docs/reconstruct.md,
// "Exposure and white balance"). Ceres parameter blocks point into this vector: one block per
// vertex (3), per albedo texel (3), per roughness texel (1), the specular weight (1), each light
// scale (1), each environment texel (3), each light position (3), each light direction (3), each
// environment rotation (3), each view's gains (3) and, with AddPoses, each view's pose correction
// (6: src/optim/pose_corrections.h, after the gains), so
// the mapping between Ceres
// blocks and indices is the block's offset in the vector.
#ifndef SFT_OPTIM_PARAMETERS_H_
#define SFT_OPTIM_PARAMETERS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/geometry/material.h"
#include "src/optim/pose_corrections.h"
#include "src/render/derivatives.h"

namespace sft {

// The feasible set, the same for every solver (Ceres bounds for trust-region solvers, projection
// for L-BFGS and Adam).
struct ParameterBounds {
  // Lowest roughness the fit may use. The renderer floors GGX α = roughness² at 1e-4, i.e.
  // roughness 0.01; below that the image no longer depends on roughness, so the bound matches.
  double roughness_min = 0.01;
  // Light scales stay positive: the renderer's light derivatives are divided by the scale.
  double light_scale_min = 1e-6;
  // Light scales above this are treated as a runaway fit.
  double light_scale_max = 1e6;
  // Exposure gains stay in [gain_min, gain_max]: a gain is a camera's exposure × white-balance
  // factor relative to the gauge view, so factors beyond 20× (over 4 stops) mean a runaway fit
  // and a gain of 0 would erase the view.
  double gain_min = 0.05;
  double gain_max = 20.0;
  // Fitted environment texels (linear radiance) stay in [0, environment_max]: the renderer
  // clamps negative texels to 0, and a texel beyond the bound means a runaway fit.
  double environment_max = 1e6;
  // Each component of an environment's rotation vector (ParameterLayout::environment_rotations)
  // stays in [−max, max], radians: a refinement of a given alignment by a few degrees, not a
  // search (0.1 rad ≈ 5.7°; docs/reconstruct.md, "Probe rotation").
  double environment_rotation_max = 0.1;
  // Each rotation component of a view's pose correction (src/optim/pose_corrections.h) stays in
  // [−pose_rotation_max, pose_rotation_max], radians (0.05 rad ≈ 2.9°: a refinement of poses good
  // to about half a degree), and each translation component in ±pose_translation_max, scene units
  // (the importers normalise the object to a bounding-box diagonal of 1: 5% of it).
  double pose_rotation_max = 0.05;
  double pose_translation_max = 0.05;

  bool Check(std::string* why) const;
};

// Which parameter kinds a phase varies; the others are held constant.
struct ActiveParameters {
  bool vertices = false;
  bool albedo = true;
  bool roughness = true;
  bool specular = false;
  bool lights = false;
  bool exposure = false;         // the per-view exposure gains (all views but the gauge view).
  bool environment = false;      // the fitted environment's texels (when the parameters have them).
  bool light_positions = false;  // point-light positions (when the parameters have them).
  bool light_directions = false;  // directional-light directions (when the parameters have them).
  bool environment_rotations = false;  // environment rotations (when the parameters have them).
  bool poses = false;  // the per-view pose corrections (all views but the gauge view).

  // The renderer's kinds (exposure gains are applied by the render cache, not the renderer).
  ParameterSelection ToSelection() const;
  bool Includes(ParameterKind kind) const;
  bool Any() const {
    return vertices || albedo || roughness || specular || lights || exposure || environment ||
           light_positions || light_directions || environment_rotations || poses;
  }
};

// The gauge of the exposure gains: albedo × light intensity × gain is otherwise ambiguous (any
// common factor moves between them), so the gains of fitted view 0 — the lowest dataset index
// fitted — stay 1 and are never a parameter. Every other gain is relative to that view.
constexpr int kExposureGaugeView = 0;

// One Ceres parameter block: [offset, offset + size) of the flat vector.
struct BlockSpan {
  int offset = 0;
  int size = 0;
  ParameterKind kind = ParameterKind::kVertex;  // meaningless when `exposure`.
  bool exposure = false;                        // one view's 3 exposure gains.
  bool pose = false;                            // one view's 6 pose-correction numbers.
};

class SceneParameters {
 public:
  SceneParameters() = default;
  // Packs positions, the material's texels and specular weight, `num_lights` scales of 1 and
  // `num_gain_views` × 3 exposure gains of 1.
  SceneParameters(const std::vector<Eigen::Vector3d>& positions, const Material& material,
                  int num_lights, int num_gain_views = 0);
  // The same with dataset light `environment_light`'s map as parameters, starting at `texels`
  // (W × H, ≥ 3 channels; negative or non-finite values start at 0).
  SceneParameters(const std::vector<Eigen::Vector3d>& positions, const Material& material,
                  int num_lights, int num_gain_views, int environment_light, const Image& texels);

  // The renderer's part of the vector (every index below layout().size()).
  const ParameterLayout& layout() const { return layout_; }
  // All parameters: the layout's, then the exposure gains.
  int size() const { return static_cast<int>(values_.size()); }
  int ExposureOffset() const { return layout_.size(); }
  int num_gain_views() const { return num_gain_views_; }
  bool IsExposure(int index) const { return index >= layout_.size() && index < PoseOffset(); }
  // Index of fitted view v's gain of channel c.
  int GainIndex(int view, int c) const { return ExposureOffset() + 3 * view + c; }
  // Fitted view v's gains (1, 1, 1 when the vector has none).
  Eigen::Vector3d Gains(int view) const;
  // Whether fitted view v's gains are parameters of an exposure fit (not the gauge view).
  bool GainFitted(int view) const {
    return view != kExposureGaugeView && view >= 0 && view < num_gain_views_;
  }
  // Pose corrections (src/optim/pose_corrections.h): 6 per fitted view after the gains, added by
  // AddPoses (all zero: the dataset's poses).
  void AddPoses(int num_pose_views);
  int PoseOffset() const { return ExposureOffset() + 3 * num_gain_views_; }
  int num_pose_views() const { return num_pose_views_; }
  bool IsPose(int index) const { return index >= PoseOffset(); }
  // Index of fitted view v's correction component k (0–2 rotation, 3–5 translation).
  int PoseIndex(int view, int k) const { return PoseOffset() + 6 * view + k; }
  // Fitted view v's correction (zero when the vector has none).
  PoseDelta Pose(int view) const;
  // Whether fitted view v's correction is a parameter of a pose fit (not the gauge view).
  bool PoseFitted(int view) const {
    return view != kPoseGaugeView && view >= 0 && view < num_pose_views_;
  }
  std::vector<double>& values() { return values_; }
  const std::vector<double>& values() const { return values_; }
  double* data() { return values_.data(); }

  // Every block in order: vertices, albedo texels, roughness texels, specular, lights,
  // environment texels, light positions, light directions, environment rotations, gains, poses.
  std::vector<BlockSpan> Blocks() const;
  // The block holding parameter `index`.
  BlockSpan BlockOf(int index) const;

  // Makes the lights' positions parameters (ParameterLayout::light_positions), starting at
  // `positions` (one per dataset light, each in its light's frame; entries of lights that are
  // not point lights are kept but get no derivatives). The exposure gains keep their values.
  void AddLightPositions(const std::vector<Eigen::Vector3d>& positions) {
    AddLightVectors(positions, ParameterKind::kLightPosition);
  }
  bool has_light_positions() const { return layout_.light_positions; }
  // The lights' position parameters, one per dataset light (empty without them).
  std::vector<Eigen::Vector3d> LightPositions() const {
    return LightVectors(ParameterKind::kLightPosition);
  }
  // The same for directional lights' directions (ParameterLayout::light_directions): three
  // numbers v per dataset light in its frame, the light travelling along v/|v| (entries of lights
  // that are not directional are kept but get no derivatives).
  void AddLightDirections(const std::vector<Eigen::Vector3d>& directions) {
    AddLightVectors(directions, ParameterKind::kLightDirection);
  }
  bool has_light_directions() const { return layout_.light_directions; }
  std::vector<Eigen::Vector3d> LightDirections() const {
    return LightVectors(ParameterKind::kLightDirection);
  }
  // The same for environments' rotation vectors (ParameterLayout::environment_rotations, radians,
  // in each environment's frame; entries of lights that are not environments are kept but get no
  // derivatives).
  void AddEnvironmentRotations(const std::vector<Eigen::Vector3d>& rotations) {
    AddLightVectors(rotations, ParameterKind::kEnvironmentRotation);
  }
  bool has_environment_rotations() const { return layout_.environment_rotations; }
  std::vector<Eigen::Vector3d> EnvironmentRotations() const {
    return LightVectors(ParameterKind::kEnvironmentRotation);
  }

  // Current state, for rendering and output. `material` must have the layout's texel counts;
  // its fresnel mode and resolutions are kept.
  void Positions(std::vector<Eigen::Vector3d>* positions) const;
  void WriteMaterial(Material* material) const;
  double LightScale(int light) const { return values_[layout_.LightOffset() + light]; }
  std::vector<double> LightScales() const;
  // The fitted environment's texels as a W × H RGB image (empty when there are none).
  bool has_environment() const { return layout_.num_environment_texels > 0; }
  Image EnvironmentTexels() const;
  int environment_width() const { return environment_width_; }
  int environment_height() const { return environment_height_; }

  // Lower/upper bound of parameter `index` (±infinity for vertices, light positions and
  // directions; ±environment_rotation_max for environment rotations; ±pose_rotation_max and
  // ±pose_translation_max for pose corrections).
  double Lower(int index, const ParameterBounds& bounds) const;
  double Upper(int index, const ParameterBounds& bounds) const;
  // Clamps every value into the bounds (projection onto the feasible set).
  void Project(const ParameterBounds& bounds, std::vector<double>* values) const;

 private:
  // AddLightPositions, AddLightDirections or AddEnvironmentRotations (`kind`: their kind), and
  // their getters.
  void AddLightVectors(const std::vector<Eigen::Vector3d>& vectors, ParameterKind kind);
  std::vector<Eigen::Vector3d> LightVectors(ParameterKind kind) const;
  // The layout's flag and first index of `kind`'s three numbers per light.
  bool& LightVectorsPresent(ParameterKind kind);
  bool HasLightVectors(ParameterKind kind) const;
  int LightVectorsOffset(ParameterKind kind) const;

  ParameterLayout layout_;
  int num_gain_views_ = 0;
  int num_pose_views_ = 0;
  int environment_width_ = 0;
  int environment_height_ = 0;
  std::vector<double> values_;
};

}  // namespace sft

#endif  // SFT_OPTIM_PARAMETERS_H_
