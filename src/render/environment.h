// An equirectangular environment light (docs/dataset.md, "Conventions"): the env frame is z-up; a
// direction d = (x, y, z) in it maps to u = 0.5 − atan2(y, x)/(2π), v = acos(z)/π (u to the right,
// v down from the top row), so the image centre looks along +x — Blender's convention. World
// directions are taken to the env frame by world_from_envᵀ.
//
// Radiance = scale · the bilinear interpolation of the texels (negative texels clamped to 0), as
// Cycles' default Linear interpolation: texel (x, y) holds the value at its centre
// ((x + 0.5)/W, (y + 0.5)/H); u wraps around, and above the first row's centres (below the last
// row's) the row's value holds to the pole.
//
// Importance sampling draws from exactly that function. The (u, v) plane is cut into cells between
// neighbouring texel centres (W per band; H + 1 bands, the first and last half as tall, reaching
// the poles), on each of which the interpolated value f (mean of RGB) is bilinear. A cell is picked
// with probability ∝ ∫ f sin θ over it (the radiance times the solid angle), then a point in it
// with density ∝ f: first the row coordinate from its linear marginal, then the column coordinate
// from its linear conditional, each by inverting a quadratic CDF. Pdf() evaluates the same density,
// so the pdf is what is looked up (up to the cell's mean sin θ), and Sample() never picks a
// direction where the lookup is zero.
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

  // The texels whose bilinear blend is the radiance along world direction `dir` (unit), and their
  // weights: Radiance(dir) = scale · Σ_k weight[k] · max(0, texel[k]'s value), texel index
  // y·width + x. Always 4 entries (at the poles the top or bottom pair repeats one row, weights
  // summing to 1); all weights 0 for a zero or non-finite `dir`. The derivative of the radiance
  // with respect to a non-negative texel value is scale · weight (fitted environments,
  // ParameterKind::kEnvironment).
  void TexelWeights(const Eigen::Vector3d& dir, int texel[4], double weight[4]) const;
  double scale() const { return scale_; }

  // ∂Radiance/∂θ at θ = 0 (rows: R, G, B; columns: θ's components) for world direction `dir`
  // (unit), where θ is a rotation vector (axis·angle, radians, world frame) that turns the map as
  // world_from_env ← exp([θ]×)·world_from_env. Then the lookup is at e = world_from_envᵀ·
  // exp(−[θ]×)·dir, so ∂e/∂θ = world_from_envᵀ·[dir]× at θ = 0, chained through (u, v)(e) and the
  // bilinear interpolation (one-sided where dir lies on a texel centre's row or column: the cell
  // Radiance() uses). The u term is dropped where |e_xy| ≤ 1e-12 (the poles, where u is
  // undefined; the polar half band has no v term, its row's value holds). Zero for a zero or
  // non-finite `dir`. The radiance environment of a probe whose alignment is refined
  // (ParameterKind::kEnvironmentRotation).
  Eigen::Matrix3d RotationJacobian(const Eigen::Vector3d& dir) const;

  // A copy of this map turned by `rotation` (world_from_env ← rotation·world_from_env). Sampling
  // tables are in the env frame, so they are copied unchanged.
  EnvironmentMap Rotated(const Eigen::Matrix3d& rotation) const;
  const Eigen::Matrix3d& world_from_env() const { return world_from_env_; }

  // Mean radiance over the sphere (solid-angle weighted, of the interpolated map), for tests and
  // planning.
  Eigen::Vector3d MeanRadiance() const;

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  // A point of the (u, v) plane as its cell (column i: between the centres of texel columns i and
  // i + 1 mod W; band j in [0, H]: between the centres of rows j − 1 and j) and its bilinear
  // coordinates (s, t) in [0, 1]² within the cell.
  struct CellPoint {
    int i = 0, j = 0;
    double s = 0.0, t = 0.0;
  };
  // One band of cells: its v range and the rows at its top and bottom edges (equal in the polar
  // half bands), and ∫₀¹ sin θ(t) dt, ∫₀¹ t sin θ(t) dt over it.
  struct Band {
    double v0 = 0.0, dv = 0.0;
    int row0 = 0, row1 = 0;
    double sin0 = 0.0, sin1 = 0.0;
  };

  CellPoint CellOf(double u, double v) const;
  CellPoint CellOfDirection(const Eigen::Vector3d& dir) const;
  // The cell's corner values of f: top-left, top-right, bottom-left, bottom-right.
  Eigen::Vector4d Corners(int i, int j) const;
  // ∫∫ f sin θ ds dt over cell (i, j) (proportional to its sampling probability).
  double CellWeight(int i, int j) const;
  Eigen::Vector3d Interpolate(const CellPoint& p) const;
  // Density of Sample() in (u, v) at p.
  double UvPdf(const CellPoint& p) const;

  int width_ = 0;
  int height_ = 0;
  std::vector<Eigen::Vector3f> texels_;  // scaled, clamped radiance.
  std::vector<double> value_;            // f = mean of RGB per texel.
  std::vector<Band> bands_;              // H + 1 bands.
  Eigen::Matrix3d world_from_env_;
  double scale_ = 1.0;
  std::vector<double> band_cdf_;    // H + 2 entries, normalized.
  std::vector<double> column_cdf_;  // H + 1 bands of W + 1 entries, normalized per band.
  double total_weight_ = 0.0;       // Σ CellWeight.
  bool black_ = true;
};

// exp([θ]×), the rotation by |θ| radians about θ/|θ| (the identity for θ = 0).
Eigen::Matrix3d RotationFromVector(const Eigen::Vector3d& theta);
// The left Jacobian of SO(3) at θ: exp([θ + dθ]×) = exp([J_l(θ)·dθ]×)·exp([θ]×) to first order,
// J_l = I + (1 − cos a)/a²·[θ]× + (a − sin a)/a³·[θ]×² with a = |θ| (series below a = 1e-4).
Eigen::Matrix3d RotationLeftJacobian(const Eigen::Vector3d& theta);

}  // namespace sft

#endif  // SFT_RENDER_ENVIRONMENT_H_
