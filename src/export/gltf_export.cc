// glTF 2.0 binary (.glb) through TinyGLTF (Debian's libtinygltf-dev). One buffer holds, 4-byte
// aligned: positions (float VEC3), texture coordinates (float VEC2, glTF's v down: 1 − v of the
// atlas), triangle indices (uint32), then the two PNG textures.
#include <tiny_gltf.h>

#include <cstring>
#include <exception>
#include <fstream>
#include <sstream>

#include "src/core/file_util.h"
#include "src/export/export_formats.h"
#include "src/image/image_io.h"

namespace sft {
namespace {

// Appends `bytes` to the buffer as a new buffer view (4-byte aligned); returns its index.
int AddBufferView(const void* bytes, size_t size, int target, tinygltf::Model* model) {
  std::vector<unsigned char>& data = model->buffers[0].data;
  while (data.size() % 4 != 0) data.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const unsigned char* begin = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), begin, begin + size);
  model->bufferViews.push_back(view);
  return static_cast<int>(model->bufferViews.size()) - 1;
}

int AddAccessor(int view, int component_type, int type, size_t count, tinygltf::Model* model) {
  tinygltf::Accessor accessor;
  accessor.bufferView = view;
  accessor.componentType = component_type;
  accessor.type = type;
  accessor.count = count;
  model->accessors.push_back(accessor);
  return static_cast<int>(model->accessors.size()) - 1;
}

// An embedded PNG image and a texture on it; returns the texture's index.
int AddTexture(const std::string& png, const std::string& name, tinygltf::Model* model) {
  tinygltf::Image image;
  image.name = name;
  image.mimeType = "image/png";
  image.bufferView = AddBufferView(png.data(), png.size(), 0, model);
  model->images.push_back(image);
  tinygltf::Texture texture;
  texture.source = static_cast<int>(model->images.size()) - 1;
  texture.sampler = 0;
  model->textures.push_back(texture);
  return static_cast<int>(model->textures.size()) - 1;
}

// The metallic-roughness material and the KHR_materials_specular mapping of docs/export.md.
tinygltf::Material MakeMaterial(int base_color, int metallic_roughness, const Material& m) {
  tinygltf::Material material;
  material.name = "sft_material";
  material.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
  material.pbrMetallicRoughness.baseColorTexture.index = base_color;
  material.pbrMetallicRoughness.metallicRoughnessTexture.index = metallic_roughness;
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 1.0;
  // Dielectric F0 = 0.04 (ior 1.5) × specularColorFactor, times specularFactor; F0 = s needs
  // specularColorFactor = s / 0.04 (the extension allows values above 1). s = 0 turns the lobe off.
  tinygltf::Value::Object specular;
  const double s = m.specular;
  specular["specularFactor"] = tinygltf::Value(s > 0.0 ? 1.0 : 0.0);
  const double color = s > 0.0 ? s / 0.04 : 1.0;
  specular["specularColorFactor"] = tinygltf::Value(tinygltf::Value::Array{
      tinygltf::Value(color), tinygltf::Value(color), tinygltf::Value(color)});
  material.extensions["KHR_materials_specular"] = tinygltf::Value(specular);
  return material;
}

// Seam-split positions, texture coordinates and indices as buffer views and accessors; returns
// the triangle primitive over them (material 0).
tinygltf::Primitive AddGeometry(const std::vector<Eigen::Vector3d>& positions,
                                const std::vector<Eigen::Vector3i>& faces, const UvAtlas& atlas,
                                tinygltf::Model* model) {
  const SeamSplitMesh split = SplitAtSeams(faces, atlas);
  std::vector<float> xyz, uv;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (size_t v = 0; v < split.source_vertex.size(); ++v) {
    const Eigen::Vector3d p = positions[split.source_vertex[v]].cast<float>().cast<double>();
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(p[k]));
    uv.push_back(static_cast<float>(split.uv[v].x()));
    uv.push_back(static_cast<float>(1.0 - split.uv[v].y()));
  }
  std::vector<uint32_t> indices;
  for (const Eigen::Vector3i& f : split.faces) {
    for (int k = 0; k < 3; ++k) indices.push_back(static_cast<uint32_t>(f[k]));
  }

  const size_t n = split.source_vertex.size();
  const int position_view =
      AddBufferView(xyz.data(), xyz.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER, model);
  const int uv_view =
      AddBufferView(uv.data(), uv.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER, model);
  const int index_view = AddBufferView(indices.data(), indices.size() * sizeof(uint32_t),
                                       TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, model);
  const int position_accessor =
      AddAccessor(position_view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n, model);
  model->accessors[position_accessor].minValues = {lo.x(), lo.y(), lo.z()};
  model->accessors[position_accessor].maxValues = {hi.x(), hi.y(), hi.z()};
  const int uv_accessor =
      AddAccessor(uv_view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, n, model);
  const int index_accessor = AddAccessor(index_view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                         TINYGLTF_TYPE_SCALAR, indices.size(), model);

  tinygltf::Primitive primitive;
  primitive.attributes["POSITION"] = position_accessor;
  primitive.attributes["TEXCOORD_0"] = uv_accessor;
  primitive.indices = index_accessor;
  primitive.material = 0;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  return primitive;
}

}  // namespace

Status WriteGlbExport(const std::string& path, const std::vector<Eigen::Vector3d>& positions,
                      const std::vector<Eigen::Vector3i>& faces, const UvAtlas& atlas,
                      const BakedMaterial& baked, const Material& material) {
  std::string albedo_png, roughness_png;
  SFT_RETURN_IF_ERROR(EncodePng(baked.albedo, /*srgb=*/true, &albedo_png).Prefixed(path));
  // glTF's metallicRoughness texture: G = roughness, B = metallic (0); R is unused (0).
  Image metal_rough(baked.roughness.width, baked.roughness.height, 3, 0.0f);
  for (int y = 0; y < metal_rough.height; ++y) {
    for (int x = 0; x < metal_rough.width; ++x) metal_rough.at(x, y, 1) = baked.roughness.at(x, y);
  }
  SFT_RETURN_IF_ERROR(EncodePng(metal_rough, /*srgb=*/false, &roughness_png).Prefixed(path));

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "sft export";
  model.buffers.resize(1);
  tinygltf::Primitive primitive = AddGeometry(positions, faces, atlas, &model);
  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  sampler.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  model.samplers.push_back(sampler);
  const int base_color = AddTexture(albedo_png, "albedo", &model);
  const int metallic_roughness = AddTexture(roughness_png, "metallic_roughness", &model);
  model.materials.push_back(MakeMaterial(base_color, metallic_roughness, material));
  model.extensionsUsed.push_back("KHR_materials_specular");

  tinygltf::Mesh mesh;
  mesh.name = "sft_model";
  mesh.primitives.push_back(primitive);
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "sft_model";
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  std::ostringstream stream;
  try {
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/false,
                                       /*writeBinary=*/true)) {
      return Status::Error(path + ": cannot write glTF binary");
    }
  } catch (const std::exception& e) {
    return Status::Error(path + ": cannot write glTF binary (" + std::string(e.what()) + ")");
  }
  const std::string bytes = stream.str();
  return WriteAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) return Status::Error(path + ": cannot write glTF binary");
    return Status::Ok();
  });
}

}  // namespace sft
