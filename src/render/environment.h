// An equirectangular environment light (DESIGN.md §2.5): the env frame is z-up; a direction
// d = (x, y, z) in it maps to u = 0.5 − atan2(y, x)/(2π), v = acos(z)/π (u to the right, v down
// from the top row), so the image centre looks along +x — Blender's convention. World directions
// are taken to the env frame by world_from_envᵀ. Radiance = scale · texel (nearest texel; negative
// texels clamped to 0). Importance sampling is piecewise constant over texels, proportional to
// luminance·sin θ, so the sampled density matches the lookup exactly.
#ifndef SFT_RENDER_ENVIRONMENT_H_
#define SFT_RENDER_ENVIRONMENT_H_

#include <Eigen/Core>
#include <vector>

#include "src/core/image.h"

namespace sft {

class EnvironmentMap {
 public:
  // `rgb` must have 3 or 4 channels (alpha ignored).
  EnvironmentMap(const Image& rgb, const Eigen::Matrix3d& world_from_env, double scale);

  // Radiance arriving from world direction `dir` (unit), i.e. seen looking along `dir`; zero for
  // a zero or non-finite `dir` (no ray, see Camera::CamFromImage).
  Eigen::Vector3d Radiance(const Eigen::Vector3d& dir) const;

  // Samples a world direction with two uniforms; returns false when the map is black.
  bool Sample(double u1, double u2, Eigen::Vector3d* dir, Eigen::Vector3d* radiance,
              double* pdf) const;
  // Solid-angle pdf of Sample() producing world direction `dir`.
  double Pdf(const Eigen::Vector3d& dir) const;

  // Mean radiance over the sphere (solid-angle weighted), for tests and planning.
  Eigen::Vector3d MeanRadiance() const;

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  // Texel coordinates of a world direction.
  void TexelOf(const Eigen::Vector3d& dir, int* x, int* y) const;

  int width_ = 0;
  int height_ = 0;
  std::vector<Eigen::Vector3f> texels_;  // scaled, clamped radiance.
  Eigen::Matrix3d world_from_env_;
  std::vector<double> row_cdf_;     // height_ + 1 entries, normalized.
  std::vector<double> column_cdf_;  // height_ rows of width_ + 1 entries, normalized per row.
  std::vector<double> texel_pdf_;   // probability of each texel (sums to 1).
  bool black_ = true;
};

}  // namespace sft

#endif  // SFT_RENDER_ENVIRONMENT_H_
