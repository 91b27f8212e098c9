// The side of a UV atlas from the images' pixel footprint: what `sft export` and the schedule's
// uv stage use when no texture size is given.
#ifndef SFT_ATLAS_TEXTURE_SIZE_H_
#define SFT_ATLAS_TEXTURE_SIZE_H_

#include <Eigen/Core>

#include "src/io/dataset.h"

namespace sft {

// The side used when there is nothing to measure (no views); texels.
constexpr int kDefaultTextureSize = 1024;

// The atlas side for a surface of `area` (scene units²) seen by `dataset`'s views: the finest
// pixel footprint over the views, d/f (d the distance from the camera centre to `center`, f the
// focal length in pixels), gives the texel size; the side is the power of two that holds
// area/footprint² texels at 50% utilisation, clamped to [256, 4096]. kDefaultTextureSize when
// the dataset has no views.
int TextureSizeFromFootprint(const Dataset& dataset, const Eigen::Vector3d& center, double area);

// The atlas side at which baking a mesh-colors material keeps its detail: the power of two whose
// square, at 35% utilisation (what our charts reach on scanned and Poisson meshes), holds 4 atlas
// texels per stored mesh-colour sample (num_faces × MeshColors::TexelsPerFace(resolution)),
// clamped to [256, 4096]. Mesh colours give every face the same number of samples whatever its
// area, while an atlas spreads texels by area, so the bake needs this margin; with 2 texels per
// sample a bake of spot_textured_point's r = 2 material lost 0.3 dB of relit PSNR, with 4 none
// (docs/design-notes.md, "The relighting numbers").
int TextureSizeForMeshColors(int num_faces, int resolution);

}  // namespace sft

#endif  // SFT_ATLAS_TEXTURE_SIZE_H_
