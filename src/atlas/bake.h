// Baking the mesh-colors material (src/geometry/material.h) into the textures of a UV atlas.
//
// Every chart face is rasterised in UV space: each texel whose centre lies within one texel of the
// face's UV triangle takes the material at the closest point of the triangle, looked up as the
// renderer does (MeshColors::TexelIndex of the face at that point's barycentric (α, β): nearest
// mesh-colors texel). A texel claimed by several faces keeps the closest one; centres inside a
// triangle (distance 0) are "covered". Texels reached within one texel outside a chart carry the
// value at the chart's edge, so bilinear lookups inside the chart never read a texel from outside.
// The rest of the atlas is then filled by dilation: ring by ring (8-neighbourhood), each empty
// texel next to filled ones takes their mean, until no texel is empty, so that mip-mapping and
// bilinear filtering never pull in black.
#ifndef SFT_ATLAS_BAKE_H_
#define SFT_ATLAS_BAKE_H_

#include "src/atlas/uv_atlas.h"
#include "src/core/image.h"
#include "src/core/status.h"
#include "src/geometry/material.h"

namespace sft {

struct BakedMaterial {
  Image albedo;     // 3 channels, linear, [0, 1]; texture_size², row 0 = v 1 (top).
  Image roughness;  // 1 channel, [0, 1] (GGX α = roughness²).
  Image coverage;   // 1 channel: 1 where a texel centre lies inside a chart face, else 0.
};

struct BakeReport {
  int covered_texels = 0;  // centres inside a face.
  int edge_texels = 0;     // within one texel outside a face.
  int dilated_texels = 0;  // filled by dilation.
  int dilation_rings = 0;
  double seconds = 0.0;
};

// Error when the material's face count differs from the atlas's.
Status BakeMaterial(const UvAtlas& atlas, const Material& material, BakedMaterial* baked,
                    BakeReport* report);

// The texel coordinates (x to the right, y down, texel (i, j) covering [i, i+1] × [j, j+1]) of an
// atlas UV (v up).
inline Eigen::Vector2d UvToTexel(const Eigen::Vector2d& uv, int texture_size) {
  return Eigen::Vector2d(uv.x() * texture_size, (1.0 - uv.y()) * texture_size);
}

}  // namespace sft

#endif  // SFT_ATLAS_BAKE_H_
