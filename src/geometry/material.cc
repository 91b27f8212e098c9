#include "src/geometry/material.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "src/core/file_util.h"
#include "src/core/image.h"
#include "src/geometry/mtl_material.h"
#include "src/geometry/procedural_pattern.h"
#include "src/geometry/texture_sampling.h"

namespace sft {
namespace {

using Json = nlohmann::json;

constexpr double kDefaultAlbedo = 0.7;
constexpr double kDefaultRoughness = 0.5;
constexpr int kDefaultSampledResolution = 8;  // albedo_texture and procedural.
constexpr int kMaxResolution = 64;
// Default procedural frequencies, in features across the bounding-box diagonal.
constexpr double kDefaultWoodScale = 10.0;
constexpr double kDefaultNoiseScale = 4.0;

// Where errors point: the JSON or MTL file's path or "material (inline JSON)", and for an MTL file
// the statement each field came from.
class Context {
 public:
  explicit Context(std::string where, std::map<std::string, std::string> aliases = {})
      : where_(std::move(where)), aliases_(std::move(aliases)) {}
  Status Error(const std::string& field, const std::string& what) const {
    const auto alias = aliases_.find(field);
    return Status::Error(where_ + ": \"" + (alias == aliases_.end() ? field : alias->second) +
                         "\": " + what);
  }
  Status Error(const std::string& what) const { return Status::Error(where_ + ": " + what); }

 private:
  std::string where_;
  std::map<std::string, std::string> aliases_;
};

std::string FormatNumber(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", v);
  return buffer;
}

Status ReadNumber(const Context& ctx, const Json& json, const std::string& field, double lo,
                  double hi, double* value) {
  const Json& v = json.at(field);
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo ||
      v.get<double>() > hi) {
    std::string range =
        "[" + FormatNumber(lo) + ", " + (std::isinf(hi) ? "inf)" : FormatNumber(hi) + "]");
    return ctx.Error(field, "expected a number in " + range + ", got " + v.dump());
  }
  *value = v.get<double>();
  return Status::Ok();
}

Status ParseColor(const Context& ctx, const std::string& field, const Json& v,
                  Eigen::Vector3d* color) {
  if (!v.is_array() || v.size() != 3) {
    return ctx.Error(field, "expected 3 numbers in [0, 1], got " + v.dump());
  }
  for (int c = 0; c < 3; ++c) {
    if (!v[c].is_number() || !(v[c].get<double>() >= 0.0 && v[c].get<double>() <= 1.0)) {
      return ctx.Error(field, "expected 3 numbers in [0, 1], got " + v.dump());
    }
    (*color)[c] = v[c].get<double>();
  }
  return Status::Ok();
}

Status ReadString(const Context& ctx, const Json& json, const std::string& field,
                  std::string* value) {
  const Json& v = json.at(field);
  if (!v.is_string() || v.get<std::string>().empty()) {
    return ctx.Error(field, "expected a non-empty string, got " + v.dump());
  }
  *value = v.get<std::string>();
  return Status::Ok();
}

void FillConstant(int num_faces, int resolution, const double* value, int channels,
                  MeshColors* colors) {
  *colors = MeshColors(num_faces, resolution, channels);
  for (int k = 0; k < colors->num_texels(); ++k) {
    for (int c = 0; c < channels; ++c) colors->texel(k)[c] = value[c];
  }
}

const std::set<std::string>& KnownKeys() {
  static const std::set<std::string> keys = {
      "albedo",       "albedo_texture", "colorspace", "mesh_colors", "roughness_mesh_colors",
      "procedural",   "colors",         "scale",      "roughness",   "roughness_range",
      "specular",     "fresnel",        "resolution", "seed",        "uv_albedo",
      "uv_roughness", "uv_mesh"};
  return keys;
}

// "colorspace": "linear" (the default) or "srgb"; *srgb is true for the latter.
Status ReadColorspace(const Context& ctx, const Json& json, bool* srgb) {
  *srgb = false;
  if (!json.contains("colorspace")) return Status::Ok();
  const Json& v = json["colorspace"];
  if (v != "linear" && v != "srgb") {
    return ctx.Error("colorspace", "expected \"linear\" or \"srgb\", got " + v.dump());
  }
  *srgb = v == "srgb";
  return Status::Ok();
}

Status ReadMeshColorsFor(const Context& ctx, const std::string& field, const std::string& path,
                         int channels, int num_faces, MeshColors* colors) {
  Status status = ReadMeshColors(path, colors);
  if (!status.ok()) return ctx.Error(field, status.message());
  if (colors->channels() != channels) {
    return ctx.Error(field, path + " has " + std::to_string(colors->channels()) +
                                " channels, expected " + std::to_string(channels));
  }
  if (colors->num_faces() != num_faces) {
    return ctx.Error(field, path + " has " + std::to_string(colors->num_faces()) +
                                " faces, the mesh has " + std::to_string(num_faces));
  }
  for (size_t k = 0; k < colors->values().size(); ++k) {
    const double v = colors->values()[k];
    if (!(v >= 0.0 && v <= 1.0)) {
      return ctx.Error(field, path + ": texel " + std::to_string(k / channels) + " has value " +
                                  FormatNumber(v) + " outside [0, 1]");
    }
  }
  return Status::Ok();
}

// The UV-texture form: "uv_albedo" and/or "uv_roughness" (with a constant "albedo" or the default
// when there is no "uv_albedo"); *source becomes "uv". Refused as a start (MaterialUse::kFit).
Status CheckUvForm(const Context& ctx, const Json& json, MaterialUse use, std::string* source) {
  const bool uv_albedo = json.contains("uv_albedo"), uv_roughness = json.contains("uv_roughness");
  if (!uv_albedo && !uv_roughness) return Status::Ok();
  if (uv_roughness && *source != "albedo" && *source != "uv_albedo") {
    return ctx.Error("uv_roughness", "cannot be combined with \"" + *source + "\"");
  }
  const char* field = uv_albedo ? "uv_albedo" : "uv_roughness";
  if (json.contains("roughness_mesh_colors")) {
    return ctx.Error("roughness_mesh_colors",
                     std::string("cannot be combined with \"") + field + "\"");
  }
  if (use == MaterialUse::kFit) {
    return ctx.Error(field,
                     "a UV-texture material can be rendered (sft render, sft gradcheck) but not "
                     "fitted or saved; \"albedo_texture\" samples a texture into mesh colors");
  }
  *source = "uv";
  return Status::Ok();
}

// Checks the keys: all known, exactly one albedo source (none: the default constant; its name in
// *source, "uv" for the UV-texture form), keys of one form only with that form, at most one
// roughness source, the UV-texture form only for rendering.
Status CheckForm(const Context& ctx, const Json& json, MaterialUse use, std::string* source) {
  if (!json.is_object()) return ctx.Error("expected a JSON object");
  for (auto it = json.begin(); it != json.end(); ++it) {
    if (KnownKeys().count(it.key()) == 0) {
      return ctx.Error("unknown key \"" + it.key() + "\"");
    }
  }
  auto has = [&](const char* key) { return json.contains(key); };
  std::vector<std::string> sources;
  for (const char* key : {"albedo", "albedo_texture", "mesh_colors", "procedural", "uv_albedo"}) {
    if (has(key)) sources.push_back(key);
  }
  if (sources.size() > 1) {
    return ctx.Error(sources[1], "cannot be combined with \"" + sources[0] + "\"");
  }
  *source = sources.empty() ? "albedo" : sources[0];
  SFT_RETURN_IF_ERROR(CheckUvForm(ctx, json, use, source));
  // Keys that belong to one form only.
  const std::pair<const char*, const char*> form_keys[] = {{"colorspace", "albedo_texture"},
                                                           {"colors", "procedural"},
                                                           {"scale", "procedural"},
                                                           {"seed", "procedural"},
                                                           {"roughness_range", "procedural"}};
  for (const auto& fk : form_keys) {
    const bool uv_colorspace =
        *source == "uv" && has("uv_albedo") && std::string(fk.first) == "colorspace";
    if (has(fk.first) && *source != fk.second && !uv_colorspace) {
      return ctx.Error(fk.first, std::string("only applies with \"") + fk.second + "\"");
    }
  }
  if (has("resolution") && *source == "mesh_colors") {
    return ctx.Error("resolution", "does not apply with \"mesh_colors\" (the file has its own)");
  }
  if (has("uv_mesh") && *source != "uv") {
    return ctx.Error("uv_mesh", "only applies with \"uv_albedo\" or \"uv_roughness\"");
  }
  if (has("resolution") && *source == "uv") {
    return ctx.Error("resolution", "does not apply to UV textures (they have their own size)");
  }
  int roughness_sources = 0;
  for (const char* key :
       {"roughness", "roughness_mesh_colors", "roughness_range", "uv_roughness"}) {
    roughness_sources += has(key) ? 1 : 0;
  }
  if (roughness_sources > 1) {
    return ctx.Error("roughness",
                     "give only one of \"roughness\", \"roughness_mesh_colors\", "
                     "\"roughness_range\", \"uv_roughness\"");
  }
  return Status::Ok();
}

// "fresnel", "specular" and "resolution" (default: 1 for constants, kDefaultSampledResolution
// for sampled albedo).
Status ParseCommon(const Context& ctx, const Json& json, const std::string& source,
                   Material* material, int* resolution) {
  if (json.contains("fresnel")) {
    const Json& v = json["fresnel"];
    if (v == "constant") {
      material->fresnel = FresnelMode::kConstant;
    } else if (v == "schlick") {
      material->fresnel = FresnelMode::kSchlick;
    } else {
      return ctx.Error("fresnel", "expected \"constant\" or \"schlick\", got " + v.dump());
    }
  }
  if (json.contains("specular")) {
    // The constant Fresnel weight (or Schlick's F0) is a reflectance: above 1 the glossy lobe
    // reflects more than arrives (1e20 gave inf pixels).
    SFT_RETURN_IF_ERROR(ReadNumber(ctx, json, "specular", 0.0, 1.0, &material->specular));
  }
  *resolution = source == "albedo" ? 1 : kDefaultSampledResolution;
  if (json.contains("resolution")) {
    const Json& v = json["resolution"];
    if (!v.is_number_integer() || v.get<int64_t>() < 1 || v.get<int64_t>() > kMaxResolution) {
      return ctx.Error("resolution", "expected an integer in [1, " +
                                         std::to_string(kMaxResolution) + "], got " + v.dump());
    }
    *resolution = static_cast<int>(v.get<int64_t>());
  }
  return Status::Ok();
}

// "albedo_texture" (with "colorspace"): the texture sampled into mesh colors through the mesh's
// UVs.
Status ParseTextureAlbedo(const Context& ctx, const Json& json, const std::string& base_dir,
                          const TriMesh& mesh, int resolution, MeshColors* albedo) {
  const int num_faces = static_cast<int>(mesh.n_faces());
  std::string file;
  SFT_RETURN_IF_ERROR(ReadString(ctx, json, "albedo_texture", &file));
  file = JoinPath(base_dir, file);
  // Default: texel values are albedo as stored (the issue-2 CLI contract), for PNG and EXR
  // alike; "colorspace": "srgb" decodes sRGB-encoded textures.
  bool srgb = false;
  SFT_RETURN_IF_ERROR(ReadColorspace(ctx, json, &srgb));
  const std::vector<Eigen::Vector2d> corner_uvs = FaceCornerUvs(mesh);
  if (corner_uvs.size() != 3 * static_cast<size_t>(num_faces) || num_faces == 0) {
    return ctx.Error("albedo_texture", "the mesh has no texture coordinates (UVs)");
  }
  Image image;
  const Status status = ReadTextureImage(file, srgb, "albedo", &image);
  if (!status.ok()) return ctx.Error("albedo_texture", status.message());
  SampleTextureIntoMeshColors(std::move(image), corner_uvs, num_faces, resolution, albedo);
  return Status::Ok();
}

// "procedural" (with "colors", "scale", "seed"): the pattern's colours at the texels; the mixing
// weight of each texel in *weights (for "roughness_range").
Status ParseProceduralAlbedo(const Context& ctx, const Json& json, const TriMesh& mesh,
                             int resolution, MeshColors* albedo, std::vector<double>* weights) {
  const Json& kind = json["procedural"];
  if (kind != "wood" && kind != "noise") {
    return ctx.Error("procedural", "expected \"wood\" or \"noise\", got " + kind.dump());
  }
  ProceduralPattern pattern;
  pattern.wood = kind == "wood";
  Eigen::Vector3d colors[2] = {Eigen::Vector3d(0.65, 0.45, 0.25), Eigen::Vector3d(0.35, 0.2, 0.1)};
  if (!pattern.wood) {
    colors[0] = Eigen::Vector3d::Constant(0.8);
    colors[1] = Eigen::Vector3d::Constant(0.2);
  }
  if (json.contains("colors")) {
    const Json& v = json["colors"];
    if (!v.is_array() || v.size() != 2) {
      return ctx.Error("colors", "expected two colors [[r,g,b],[r,g,b]], got " + v.dump());
    }
    for (int k = 0; k < 2; ++k) SFT_RETURN_IF_ERROR(ParseColor(ctx, "colors", v[k], &colors[k]));
  }
  pattern.scale = pattern.wood ? kDefaultWoodScale : kDefaultNoiseScale;
  if (json.contains("scale")) {
    SFT_RETURN_IF_ERROR(ReadNumber(ctx, json, "scale", 0.0, 1e6, &pattern.scale));
    if (pattern.scale <= 0.0) return ctx.Error("scale", "must be positive");
  }
  if (json.contains("seed")) {
    const Json& v = json["seed"];
    if (!v.is_number_integer() || v.get<int64_t>() < 0) {
      return ctx.Error("seed", "expected a non-negative integer, got " + v.dump());
    }
    pattern.seed = static_cast<uint64_t>(v.get<int64_t>());
  }
  *weights = ProceduralWeights(mesh, pattern, resolution);
  *albedo = MeshColors(static_cast<int>(mesh.n_faces()), resolution, 3);
  for (int k = 0; k < albedo->num_texels(); ++k) {
    const double w = (*weights)[k];
    const Eigen::Vector3d c = (1.0 - w) * colors[0] + w * colors[1];
    for (int ch = 0; ch < 3; ++ch) albedo->texel(k)[ch] = c[ch];
  }
  return Status::Ok();
}

// "roughness_mesh_colors", "roughness_range" (mixed by the procedural `weights`) or "roughness".
Status ParseRoughness(const Context& ctx, const Json& json, const std::string& base_dir,
                      int num_faces, int resolution, const std::vector<double>& weights,
                      MeshColors* roughness) {
  if (json.contains("roughness_mesh_colors")) {
    std::string file;
    SFT_RETURN_IF_ERROR(ReadString(ctx, json, "roughness_mesh_colors", &file));
    return ReadMeshColorsFor(ctx, "roughness_mesh_colors", JoinPath(base_dir, file), 1, num_faces,
                             roughness);
  }
  if (json.contains("roughness_range")) {
    const Json& v = json["roughness_range"];
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number() ||
        !(v[0].get<double>() >= 0.0) || !(v[1].get<double>() <= 1.0) ||
        !(v[0].get<double>() <= v[1].get<double>())) {
      return ctx.Error("roughness_range",
                       "expected [lo, hi] with 0 <= lo <= hi <= 1, got " + v.dump());
    }
    const double lo = v[0].get<double>(), hi = v[1].get<double>();
    *roughness = MeshColors(num_faces, resolution, 1);
    for (int k = 0; k < roughness->num_texels(); ++k) {
      roughness->texel(k)[0] = lo + (hi - lo) * weights[k];
    }
    return Status::Ok();
  }
  double value = kDefaultRoughness;
  if (json.contains("roughness")) {
    SFT_RETURN_IF_ERROR(ReadNumber(ctx, json, "roughness", 0.0, 1.0, &value));
  }
  FillConstant(num_faces, resolution, &value, 1, roughness);
  return Status::Ok();
}

// The texture file of `field` of the UV-texture form: an RGB(A) image for albedo (alpha ignored),
// a grey one for roughness.
Status ReadUvTexture(const Context& ctx, const std::string& field, const std::string& file,
                     bool srgb, UvTexture* texture) {
  const bool rgb = field == "uv_albedo";
  Image image;
  const Status status = ReadTextureImage(file, srgb, rgb ? "albedo" : "roughness", &image);
  if (!status.ok()) return ctx.Error(field, status.message());
  if (rgb && image.channels < 3) {
    return ctx.Error(field, file + ": expected an RGB image, got " +
                                std::to_string(image.channels) + " channel(s)");
  }
  if (!rgb && image.channels != 1) {
    return ctx.Error(field, file + ": expected a grey (1-channel) image, got " +
                                std::to_string(image.channels) + " channels");
  }
  *texture = UvTexture::FromImage(image, rgb ? 3 : 1);
  return Status::Ok();
}

// The UV-texture form: the mesh's corner UVs, the albedo texture or constant, the roughness
// texture or constant (constants become 1×1 textures).
Status ParseUvMaterial(const Context& ctx, const Json& json, const std::string& base_dir,
                       const TriMesh& mesh, UvMaterialMaps* maps) {
  const int num_faces = static_cast<int>(mesh.n_faces());
  maps->corner_uvs = FaceCornerUvs(mesh);
  if (json.contains("uv_mesh")) {
    std::string file;
    SFT_RETURN_IF_ERROR(ReadString(ctx, json, "uv_mesh", &file));
    TriMesh uv_mesh;
    const Status read = ReadMesh(JoinPath(base_dir, file), &uv_mesh);
    if (!read.ok()) return ctx.Error("uv_mesh", read.message());
    if (uv_mesh.n_faces() != mesh.n_faces()) {
      return ctx.Error("uv_mesh", JoinPath(base_dir, file) + " has " +
                                      std::to_string(uv_mesh.n_faces()) + " faces, the mesh has " +
                                      std::to_string(num_faces));
    }
    maps->corner_uvs = FaceCornerUvs(uv_mesh);
  }
  if (maps->corner_uvs.size() != 3 * static_cast<size_t>(num_faces) || num_faces == 0) {
    return ctx.Error(json.contains("uv_albedo") ? "uv_albedo" : "uv_roughness",
                     "the mesh has no texture coordinates (UVs)");
  }
  bool srgb = false;
  SFT_RETURN_IF_ERROR(ReadColorspace(ctx, json, &srgb));
  std::string file;
  if (json.contains("uv_albedo")) {
    SFT_RETURN_IF_ERROR(ReadString(ctx, json, "uv_albedo", &file));
    SFT_RETURN_IF_ERROR(
        ReadUvTexture(ctx, "uv_albedo", JoinPath(base_dir, file), srgb, &maps->albedo));
  } else {
    Eigen::Vector3d albedo = Eigen::Vector3d::Constant(kDefaultAlbedo);
    if (json.contains("albedo")) {
      SFT_RETURN_IF_ERROR(ParseColor(ctx, "albedo", json["albedo"], &albedo));
    }
    maps->albedo = UvTexture(1, 1, 3);
    for (int c = 0; c < 3; ++c) maps->albedo.texel(0)[c] = albedo[c];
  }
  if (json.contains("uv_roughness")) {
    SFT_RETURN_IF_ERROR(ReadString(ctx, json, "uv_roughness", &file));
    SFT_RETURN_IF_ERROR(ReadUvTexture(ctx, "uv_roughness", JoinPath(base_dir, file),
                                      /*srgb=*/false, &maps->roughness));
  } else {
    double roughness = kDefaultRoughness;
    if (json.contains("roughness")) {
      SFT_RETURN_IF_ERROR(ReadNumber(ctx, json, "roughness", 0.0, 1.0, &roughness));
    }
    maps->roughness = UvTexture(1, 1, 1, roughness);
  }
  return Status::Ok();
}

Status BuildMaterial(const Context& ctx, const Json& json, const std::string& base_dir,
                     const TriMesh& mesh, MaterialUse use, Material* material) {
  std::string source;
  SFT_RETURN_IF_ERROR(CheckForm(ctx, json, use, &source));
  const int num_faces = static_cast<int>(mesh.n_faces());
  Material result;
  int resolution = 1;
  SFT_RETURN_IF_ERROR(ParseCommon(ctx, json, source, &result, &resolution));
  std::vector<double> weights;  // Procedural mixing weight per texel (for roughness_range).
  if (source == "uv") {
    SFT_RETURN_IF_ERROR(ParseUvMaterial(ctx, json, base_dir, mesh, &result.uv));
    *material = std::move(result);
    return Status::Ok();
  }
  if (source == "albedo") {
    Eigen::Vector3d albedo = Eigen::Vector3d::Constant(kDefaultAlbedo);
    if (json.contains("albedo")) {
      SFT_RETURN_IF_ERROR(ParseColor(ctx, "albedo", json["albedo"], &albedo));
    }
    FillConstant(num_faces, resolution, albedo.data(), 3, &result.albedo);
  } else if (source == "albedo_texture") {
    SFT_RETURN_IF_ERROR(ParseTextureAlbedo(ctx, json, base_dir, mesh, resolution, &result.albedo));
  } else if (source == "mesh_colors") {
    std::string file;
    SFT_RETURN_IF_ERROR(ReadString(ctx, json, "mesh_colors", &file));
    SFT_RETURN_IF_ERROR(ReadMeshColorsFor(ctx, "mesh_colors", JoinPath(base_dir, file), 3,
                                          num_faces, &result.albedo));
    resolution = result.albedo.resolution();
  } else {
    SFT_RETURN_IF_ERROR(
        ParseProceduralAlbedo(ctx, json, mesh, resolution, &result.albedo, &weights));
  }
  SFT_RETURN_IF_ERROR(
      ParseRoughness(ctx, json, base_dir, num_faces, resolution, weights, &result.roughness));
  *material = std::move(result);
  return Status::Ok();
}

// Whether `path` names an MTL file (extension .mtl, any case).
bool IsMtlPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".mtl";
}

}  // namespace

Material ConstantMaterial(int num_faces, const Eigen::Vector3d& albedo, double roughness,
                          double specular, int resolution) {
  Material material;
  FillConstant(num_faces, resolution, albedo.data(), 3, &material.albedo);
  FillConstant(num_faces, resolution, &roughness, 1, &material.roughness);
  material.specular = specular;
  return material;
}

int Material::NumAlbedoTexels() const {
  return has_uv_textures() ? uv.albedo.num_texels() : albedo.num_texels();
}
int Material::NumRoughnessTexels() const {
  return has_uv_textures() ? uv.roughness.num_texels() : roughness.num_texels();
}
std::vector<double>& Material::AlbedoValues() {
  return has_uv_textures() ? uv.albedo.values() : albedo.values();
}
const std::vector<double>& Material::AlbedoValues() const {
  return has_uv_textures() ? uv.albedo.values() : albedo.values();
}
std::vector<double>& Material::RoughnessValues() {
  return has_uv_textures() ? uv.roughness.values() : roughness.values();
}
const std::vector<double>& Material::RoughnessValues() const {
  return has_uv_textures() ? uv.roughness.values() : roughness.values();
}

Status LoadMaterial(const std::string& spec, const TriMesh& mesh, Material* material,
                    MaterialUse use) {
  const size_t first = spec.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) {
    *material = ConstantMaterial(static_cast<int>(mesh.n_faces()),
                                 Eigen::Vector3d::Constant(kDefaultAlbedo), kDefaultRoughness, 0.0);
    return Status::Ok();
  }
  std::string text;
  std::string base_dir;
  std::string where;
  if (spec[first] == '{') {
    text = spec;
    where = "material (inline JSON)";
  } else {
    SFT_RETURN_IF_ERROR(ReadTextFile(spec, &text));
    StripUtf8Bom(&text);  // nlohmann::json skips it too; explicit for every reader.
    base_dir = std::filesystem::path(spec).parent_path().string();
    where = spec;
  }
  Json json;
  std::map<std::string, std::string> aliases;
  if (spec[first] != '{' && IsMtlPath(spec)) {
    MtlMaterial mtl;
    SFT_RETURN_IF_ERROR(ParseMtl(text, spec, &mtl));
    json = std::move(mtl.json);
    aliases = std::move(mtl.statement_of_field);
  } else {
    try {
      json = Json::parse(text);
    } catch (const Json::exception& e) {
      return Context(where).Error(std::string("invalid JSON (") + e.what() + ")");
    }
  }
  const Context ctx(where, std::move(aliases));
  try {
    return BuildMaterial(ctx, json, base_dir, mesh, use, material);
  } catch (const Json::exception& e) {
    // Every access is type-checked above; this is a safety net so that no exception escapes.
    return ctx.Error(std::string("malformed material (") + e.what() + ")");
  }
}

Status SaveMaterial(const std::string& json_path, const Material& material) {
  if (material.has_uv_textures()) {
    return Status::Error(json_path + ": a UV-texture material cannot be saved as mesh colors");
  }
  if (material.albedo.channels() != 3 || material.roughness.channels() != 1) {
    return Status::Error(json_path + ": material needs 3 albedo channels and 1 roughness channel");
  }
  const std::filesystem::path path(json_path);
  const std::string stem = path.stem().string();
  const std::string albedo_name = stem + "_albedo.meshcolors";
  const std::string roughness_name = stem + "_roughness.meshcolors";
  const std::string dir = path.parent_path().string();
  SFT_RETURN_IF_ERROR(WriteMeshColors(JoinPath(dir, albedo_name), material.albedo,
                                      {"albedo_r", "albedo_g", "albedo_b"}));
  SFT_RETURN_IF_ERROR(
      WriteMeshColors(JoinPath(dir, roughness_name), material.roughness, {"roughness"}));
  // The JSON last, so that it never references a file that is not there yet.
  Json json;
  json["mesh_colors"] = albedo_name;
  json["roughness_mesh_colors"] = roughness_name;
  json["specular"] = material.specular;
  json["fresnel"] = material.fresnel == FresnelMode::kSchlick ? "schlick" : "constant";
  return WriteTextFile(json_path, json.dump(2) + "\n");
}

}  // namespace sft
