// The material switches of the schedule's uv stage (StageOptions::material_model = "uv";
// docs/reconstruct.md, "The uv stage"): from mesh colors to UV textures (chart and pack a UV
// atlas of the current mesh, bake the mesh colors into it: src/atlas/) and back (sample the
// textures into mesh colors, before a topology change or a mesh-colors stage).
#ifndef SFT_OPTIM_UV_STAGE_H_
#define SFT_OPTIM_UV_STAGE_H_

#include <nlohmann/json.hpp>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"

namespace sft {

// Replaces the mesh-colors material `material` of `mesh` by UV textures of side `texture_size`
// texels (0 = from the dataset's pixel footprint, TextureSizeFromFootprint): the atlas's corner
// UVs, albedo and roughness baked from the mesh colors (gutters dilated); specular and Fresnel
// mode are kept. `record` receives the atlas's and the bake's numbers. Errors: the atlas's
// (charts that do not fit the texture, a mesh without faces).
Status SwitchToUvTextures(const TriMesh& mesh, const Dataset& dataset, int texture_size,
                          Material* material, nlohmann::json* record);

// Replaces the UV textures of `material` by mesh colors of `resolution` ([1, 64]): each texel the
// area average of the texture over its part of the face (SampleTextureIntoMeshColors). No-op for
// a mesh-colors material.
void SwitchToMeshColors(int resolution, Material* material);

}  // namespace sft

#endif  // SFT_OPTIM_UV_STAGE_H_
