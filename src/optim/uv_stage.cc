#include "src/optim/uv_stage.h"

#include <chrono>

#include "src/atlas/bake.h"
#include "src/atlas/texture_size.h"
#include "src/atlas/uv_atlas.h"
#include "src/geometry/texture_sampling.h"
#include "src/geometry/uv_texel_charts.h"

namespace sft {
namespace {

Image TextureImage(const UvTexture& texture) {
  Image image(texture.width(), texture.height(), texture.channels());
  for (size_t i = 0; i < image.data.size(); ++i) {
    image.data[i] = static_cast<float>(texture.values()[i]);
  }
  return image;
}

}  // namespace

Status SwitchToUvTextures(const TriMesh& mesh, const Dataset& dataset, int texture_size,
                          Material* material, nlohmann::json* record) {
  const auto start = std::chrono::steady_clock::now();
  if (material->has_uv_textures()) return Status::Ok();
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  UvAtlasOptions options;
  const bool automatic = texture_size == 0;
  if (automatic) {
    Eigen::Vector3d lo, hi;
    MeshBounds(mesh, &lo, &hi);
    texture_size = TextureSizeFromFootprint(dataset, 0.5 * (lo + hi), SurfaceArea(mesh));
  }
  options.texture_size = texture_size;
  UvAtlas atlas;
  UvAtlasReport atlas_report;
  SFT_RETURN_IF_ERROR(
      BuildUvAtlas(positions, faces, options, &atlas, &atlas_report).Prefixed("uv stage: atlas"));
  BakedMaterial baked;
  BakeReport bake_report;
  SFT_RETURN_IF_ERROR(
      BakeMaterial(atlas, *material, &baked, &bake_report).Prefixed("uv stage: bake"));
  Material uv;
  uv.specular = material->specular;
  uv.fresnel = material->fresnel;
  uv.uv.corner_uvs = atlas.corner_uv;
  uv.uv.albedo = UvTexture::FromImage(baked.albedo, 3);
  uv.uv.roughness = UvTexture::FromImage(baked.roughness, 1);
  *material = std::move(uv);
  const UvTexelCharts charts =
      ComputeUvTexelCharts(faces, material->uv.corner_uvs, texture_size, texture_size);
  *record = {
      {"texture_size", texture_size},
      {"texture_size_from", automatic ? "pixel footprint" : "texture_size"},
      {"charts", atlas_report.charts},
      {"utilization", atlas_report.utilization},
      {"max_stretch", atlas_report.max_stretch},
      {"fitted_texels", charts.used_texels},
      {"covered_texels", bake_report.covered_texels},
      {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}};
  return Status::Ok();
}

void SwitchToMeshColors(int resolution, Material* material) {
  if (!material->has_uv_textures()) return;
  const int num_faces = static_cast<int>(material->uv.corner_uvs.size() / 3);
  Material out;
  out.specular = material->specular;
  out.fresnel = material->fresnel;
  SampleTextureIntoMeshColors(TextureImage(material->uv.albedo), material->uv.corner_uvs, num_faces,
                              resolution, &out.albedo);
  // Grey is replicated into three channels; the roughness is the first.
  MeshColors grey;
  SampleTextureIntoMeshColors(TextureImage(material->uv.roughness), material->uv.corner_uvs,
                              num_faces, resolution, &grey);
  out.roughness = MeshColors(num_faces, resolution, 1);
  for (int k = 0; k < out.roughness.num_texels(); ++k) out.roughness.texel(k)[0] = grey.texel(k)[0];
  *material = std::move(out);
}

}  // namespace sft
