// Which texels of a UV texture the renderer can read, and the chart each belongs to: what the uv
// stage of the schedule fits (the rest — the atlas's gutters — stays out of the fit and is filled
// by dilation) and what its smoothness prior pairs (cost_functions/uv_texel_smoothness.h).
//
// A texel is "used" when some point of some face's UV triangle has it in its bilinear footprint
// (uv_texture.h): in pixel-centre coordinates (px, py) = (u·W − ½, (1 − v)·H − ½) texel (x, y) is
// read by the points with |px − x| < 1 and |py − y| < 1, so it is used exactly when the triangle
// meets that open square (a separating-axis test). Faces whose UV triangle has (near) zero area
// (the atlas's degenerate faces) use nothing. Footprints that wrap around the texture's border
// are not followed (atlas charts keep a gutter from the edge).
//
// Charts are the connected components of faces joined across an edge whose two faces give both
// of its vertices the same UVs (a UV seam separates charts). A texel used by faces of several
// charts belongs to the one met first in face order.
#ifndef SFT_GEOMETRY_UV_TEXEL_CHARTS_H_
#define SFT_GEOMETRY_UV_TEXEL_CHARTS_H_

#include <Eigen/Core>
#include <vector>

#include "src/geometry/uv_texture.h"

namespace sft {

struct UvTexelCharts {
  int width = 0, height = 0;
  std::vector<int> chart_of_texel;  // y·W + x -> chart, or -1 when no face reads the texel.
  std::vector<int> chart_of_face;   // face -> chart (every face has one).
  int num_charts = 0;
  int used_texels = 0;

  bool used(int texel) const { return chart_of_texel[texel] >= 0; }
};

// The used texels and charts of a W × H texture under `corner_uvs` (3 per face, in the order of
// `faces`' corners; `faces` index the mesh's vertices).
UvTexelCharts ComputeUvTexelCharts(const std::vector<Eigen::Vector3i>& faces,
                                   const std::vector<Eigen::Vector2d>& corner_uvs, int width,
                                   int height);

// Fills every unused texel of `values` (W·H texels of `channels` values, texel k at
// [k·channels, (k+1)·channels)) from the used ones, ring by ring over the 8-neighbourhood: each
// unused texel next to filled ones takes their mean. Returns the number of rings. Nothing changes
// when no texel is used.
int DilateUnusedTexels(const UvTexelCharts& charts, int channels, std::vector<double>* values);

// Both textures of `maps` with their unused texels dilated (DilateUnusedTexels), each under its
// own size.
void DilateUvGutters(const std::vector<Eigen::Vector3i>& faces, UvMaterialMaps* maps);

}  // namespace sft

#endif  // SFT_GEOMETRY_UV_TEXEL_CHARTS_H_
