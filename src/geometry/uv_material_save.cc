// SaveUvMaterial (material.h): a UV-texture material as PNG textures and its JSON.
#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"
#include "src/geometry/material.h"
#include "src/image/image_io.h"

namespace sft {
namespace {

Image TextureImage(const UvTexture& texture) {
  Image image(texture.width(), texture.height(), texture.channels());
  for (size_t i = 0; i < image.data.size(); ++i) {
    image.data[i] = static_cast<float>(std::clamp(texture.values()[i], 0.0, 1.0));
  }
  return image;
}

}  // namespace

Status SaveUvMaterial(const std::string& json_path, const Material& material,
                      const std::string& uv_mesh) {
  if (!material.has_uv_textures()) {
    return Status::Error(json_path + ": not a UV-texture material");
  }
  if (material.uv.albedo.channels() != 3 || material.uv.roughness.channels() != 1) {
    return Status::Error(json_path +
                         ": UV textures need 3 albedo channels and 1 roughness channel");
  }
  const std::filesystem::path path(json_path);
  const std::string stem = path.stem().string();
  const std::string albedo_name = stem + "_albedo.png";
  const std::string roughness_name = stem + "_roughness.png";
  const std::string dir = path.parent_path().string();
  SFT_RETURN_IF_ERROR(
      WritePng(JoinPath(dir, albedo_name), TextureImage(material.uv.albedo), /*srgb=*/true));
  SFT_RETURN_IF_ERROR(WritePng(JoinPath(dir, roughness_name), TextureImage(material.uv.roughness),
                               /*srgb=*/false));
  // The JSON last, so that it never references a file that is not there yet.
  nlohmann::json json;
  json["uv_albedo"] = albedo_name;
  json["colorspace"] = "srgb";
  json["uv_roughness"] = roughness_name;
  json["uv_mesh"] = uv_mesh;
  json["specular"] = material.specular;
  json["fresnel"] = material.fresnel == FresnelMode::kSchlick ? "schlick" : "constant";
  return WriteTextFile(json_path, json.dump(2) + "\n");
}

}  // namespace sft
