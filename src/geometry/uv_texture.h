// The UV-texture material representation: per-corner UVs on the mesh and bilinearly sampled
// texel grids for albedo (RGB) and roughness (grey), the form that `sft export` writes and that
// other renderers read. The texels are the material's parameters (the renderer returns their
// derivatives: src/render/derivatives.h).
//
// Conventions (OBJ/Blender, the same as texture_sampling.h):
// - UV: u to the right, v up; v = 0 is the bottom row of the image, v = 1 the top.
// - Texel (x, y) of a W × H texture is image column x, row y (row 0 = the top row, as stored in
//   PNG); its index is y·W + x, and channel c of it is values()[(y·W + x)·channels + c].
// - Texel centres: texel (x, y) is centred at uv = ((x + ½)/W, 1 − (y + ½)/H). In "pixel-centre
//   coordinates" (px, py) = (u·W − ½, (1 − v)·H − ½) texel (x, y) sits at the integer point
//   (x, y), and the value is the bilinear interpolation of the four texels around (px, py).
// - Borders: repeat (wrap) in both directions, as Blender's default image extension and glTF's
//   default sampler do; UVs outside [0, 1] tile the texture. An atlas from `sft export` keeps
//   its charts inside [0, 1] with dilated gutters, so wrapping only blends gutter texels there.
// - Derivatives (src/render/derivatives.h): texels, and vertices through the texture sliding
//   under a moving face; jumps at UV seams between coplanar faces are not sampled.
// - Values are linear: an sRGB-encoded albedo PNG is decoded on load (material.h), roughness is
//   stored linearly (GGX α = roughness²).
#ifndef SFT_GEOMETRY_UV_TEXTURE_H_
#define SFT_GEOMETRY_UV_TEXTURE_H_

#include <Eigen/Core>
#include <vector>

#include "src/core/image.h"

namespace sft {

// The four texels that a bilinear lookup blends and their weights (non-negative, sum 1). Texels
// may repeat (a 1-texel-wide texture); the weights of a repeated texel then add.
struct BilinearFootprint {
  int texel[4];      // (x0, y0), (x1, y0), (x0, y1), (x1, y1).
  double weight[4];  // (1 − s)(1 − t), s(1 − t), (1 − s)t, st.
  double s, t;       // position in the cell, [0, 1): s along +x (+u), t along +y (−v).
};

// A W × H grid of texels with `channels` values each, sampled bilinearly.
class UvTexture {
 public:
  UvTexture() = default;
  UvTexture(int width, int height, int channels, double fill = 0.0);
  // The first `channels` channels of a linear image (float → double).
  static UvTexture FromImage(const Image& image, int channels);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  int num_texels() const { return width_ * height_; }
  bool empty() const { return num_texels() == 0; }
  double* texel(int k) { return &values_[static_cast<size_t>(k) * channels_]; }
  const double* texel(int k) const { return &values_[static_cast<size_t>(k) * channels_]; }
  std::vector<double>& values() { return values_; }
  const std::vector<double>& values() const { return values_; }

  // The texels and weights of the bilinear lookup at `uv` (conventions above).
  BilinearFootprint Footprint(const Eigen::Vector2d& uv) const;
  // The interpolated value at `uv`: channels() values into `out`.
  void Sample(const Eigen::Vector2d& uv, double* out) const;
  // The gradient of the interpolant with respect to uv at a lookup with footprint `f`:
  // channels() values each of ∂/∂u and ∂/∂v, those of the cell the footprint is in (on a cell
  // border, where the interpolant has a kink, the cell to the right / below).
  void Gradient(const BilinearFootprint& f, double* d_du, double* d_dv) const;

 private:
  int width_ = 0, height_ = 0, channels_ = 0;
  std::vector<double> values_;
};

// The UV-texture material's maps: when `corner_uvs` is non-empty the material's albedo and
// roughness come from here instead of mesh colors (Material::has_uv_textures()).
struct UvMaterialMaps {
  std::vector<Eigen::Vector2d> corner_uvs;  // 3 per face, corner order = face vertex order.
  UvTexture albedo;                         // 3 channels, linear, in [0, 1].
  UvTexture roughness;                      // 1 channel, in [0, 1]; GGX α = roughness².

  // The UV at barycentrics (1 − u − v, u, v) of `face` (Embree's u, v).
  Eigen::Vector2d Uv(int face, double u, double v) const {
    return (1.0 - u - v) * corner_uvs[3 * face] + u * corner_uvs[3 * face + 1] +
           v * corner_uvs[3 * face + 2];
  }
};

}  // namespace sft

#endif  // SFT_GEOMETRY_UV_TEXTURE_H_
