// Image textures for materials: reading a texture file as linear values, and sampling a texture
// mapped by the mesh's per-corner UVs into mesh colors (the "albedo_texture" material form) as
// exact area averages of its bilinear interpolant over each texel's region.
//
// UV convention (OBJ/Blender): u to the right, v up (v = 0 is the bottom row of the image), pixel
// centres at half-integers, repeat-wrapped at the borders.
#ifndef SFT_GEOMETRY_TEXTURE_SAMPLING_H_
#define SFT_GEOMETRY_TEXTURE_SAMPLING_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/geometry/mesh_colors.h"

namespace sft {

// Reads `file` (PNG or EXR, src/image/image_io.h) without colour conversion, then checks and
// linearises its values in place: a non-finite value is an error naming the pixel; values outside
// [0, 1] are clamped with one warning that names `what` (e.g. "albedo"); `srgb` decodes the sRGB
// transfer function after clamping. Errors (one line, naming the file): missing or unreadable
// file, empty image, non-finite value.
Status ReadTextureImage(const std::string& file, bool srgb, const std::string& what, Image* image);

// Fills `albedo` (mesh colors of `resolution`, 3 channels) with, per texel, the area average of
// the bilinear texture `image` (linear; grey replicates its channel, alpha is ignored) over the
// part of the face's UV triangle that maps to the texel. `corner_uvs` holds 3 UVs per face
// (FaceCornerUvs). The image is first box-filtered to the mip level that the texel regions can
// hold (16 texture pixels across the regions of the faces at the 10th percentile of UV size).
// Values are clamped to [0, 1].
void SampleTextureIntoMeshColors(Image image, const std::vector<Eigen::Vector2d>& corner_uvs,
                                 int num_faces, int resolution, MeshColors* albedo);

}  // namespace sft

#endif  // SFT_GEOMETRY_TEXTURE_SAMPLING_H_
