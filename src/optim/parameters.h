// The reconstruction's state as one flat vector in the renderer's parameter layout
// (ParameterLayout, src/render/derivatives.h): x[i] is parameter i — vertex coordinates, albedo
// texels (RGB), roughness texels, the specular weight, one intensity scale per dataset light. Ceres
// parameter blocks point into this vector: one block per vertex (3), per albedo texel (3), per
// roughness texel (1), the specular weight (1) and each light scale (1), so the mapping between
// Ceres blocks and layout indices is the block's offset in the vector.
#ifndef SFT_OPTIM_PARAMETERS_H_
#define SFT_OPTIM_PARAMETERS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/geometry/material.h"
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

  bool Check(std::string* why) const;
};

// Which parameter kinds a phase varies; the others are held constant.
struct ActiveParameters {
  bool vertices = false;
  bool albedo = true;
  bool roughness = true;
  bool specular = false;
  bool lights = false;

  ParameterSelection ToSelection() const;
  bool Includes(ParameterKind kind) const;
  bool Any() const { return vertices || albedo || roughness || specular || lights; }
};

// One Ceres parameter block: [offset, offset + size) of the flat vector.
struct BlockSpan {
  int offset = 0;
  int size = 0;
  ParameterKind kind = ParameterKind::kVertex;
};

class SceneParameters {
 public:
  SceneParameters() = default;
  // Packs positions, the material's texels and specular weight, and `num_lights` scales of 1.
  SceneParameters(const std::vector<Eigen::Vector3d>& positions, const Material& material,
                  int num_lights);

  const ParameterLayout& layout() const { return layout_; }
  std::vector<double>& values() { return values_; }
  const std::vector<double>& values() const { return values_; }
  double* data() { return values_.data(); }

  // Every block in layout order: vertices, albedo texels, roughness texels, specular, lights.
  std::vector<BlockSpan> Blocks() const;
  // The block holding parameter `index`.
  BlockSpan BlockOf(int index) const;

  // Current state, for rendering and output. `material` must have the layout's texel counts;
  // its fresnel mode and resolutions are kept.
  void Positions(std::vector<Eigen::Vector3d>* positions) const;
  void WriteMaterial(Material* material) const;
  double LightScale(int light) const { return values_[layout_.LightOffset() + light]; }
  std::vector<double> LightScales() const;

  // Lower/upper bound of parameter `index` (±infinity for vertices).
  double Lower(int index, const ParameterBounds& bounds) const;
  double Upper(int index, const ParameterBounds& bounds) const;
  // Clamps every value into the bounds (projection onto the feasible set).
  void Project(const ParameterBounds& bounds, std::vector<double>* values) const;

 private:
  ParameterLayout layout_;
  std::vector<double> values_;
};

}  // namespace sft

#endif  // SFT_OPTIM_PARAMETERS_H_
