// The spatially varying material: diffuse albedo (RGB) and GGX roughness stored as mesh colors or,
// alternatively, as bilinear UV textures (uv_texture.h), plus a global specular weight.
// BSDF f = albedo/π + specular·D·G1·G1/(4|n·wi||n·wo|).
#ifndef SFT_GEOMETRY_MATERIAL_H_
#define SFT_GEOMETRY_MATERIAL_H_

#include <string>

#include "src/core/status.h"
#include "src/geometry/mesh.h"
#include "src/geometry/mesh_colors.h"
#include "src/geometry/uv_texture.h"

namespace sft {

enum class FresnelMode { kConstant, kSchlick };

struct Material {
  MeshColors albedo;      // 3 channels, linear, in [0, 1].
  MeshColors roughness;   // 1 channel, in [0, 1]; GGX α = roughness².
  double specular = 0.0;  // glossy lobe weight (constant Fresnel), or F0 with Schlick; [0, 1].
  FresnelMode fresnel = FresnelMode::kConstant;
  // The UV-texture representation: when it has corner UVs, albedo and roughness come from its
  // textures and the mesh colors above are empty (no texels).
  UvMaterialMaps uv;

  bool has_uv_textures() const { return !uv.corner_uvs.empty(); }
  // The albedo and roughness parameters of whichever representation is active, flat: albedo
  // texel t channel c at 3t + c, roughness texel t at t (the renderer's ParameterLayout order).
  int NumAlbedoTexels() const;
  int NumRoughnessTexels() const;
  std::vector<double>& AlbedoValues();
  const std::vector<double>& AlbedoValues() const;
  std::vector<double>& RoughnessValues();
  const std::vector<double>& RoughnessValues() const;
};

// What the caller does with a loaded material. kFit: a start material of a reconstruction, whose
// stages begin with mesh colors, so the UV-texture forms are refused (an error naming the field).
// kCheckpoint: a run folder's material (sft reconstruct --resume, sft export): the kFit forms
// plus the UV-texture form that a uv stage writes (SaveUvMaterial). kRender: every form (sft
// render, sft gradcheck).
enum class MaterialUse { kFit, kCheckpoint, kRender };

// A material with constant albedo and roughness at mesh-colors resolution `resolution`.
Material ConstantMaterial(int num_faces, const Eigen::Vector3d& albedo, double roughness,
                          double specular, int resolution = 1);

// Builds a material from `spec`: the path of a JSON file or of an MTL file (extension .mtl), or
// inline JSON (first non-space character '{'). JSON forms (docs/cli.md, "Materials"):
//   {"albedo": [r,g,b], "roughness": x, "specular": s}                       constants
//   {"albedo_texture": "tex.png", "colorspace": "linear"|"srgb", "roughness": x, "specular": s,
//    "resolution": r}   sampled into mesh colors from the mesh's per-corner UVs (the mesh must
//                       have them)
//   {"mesh_colors": "file", "roughness_mesh_colors": "file", "specular": s}   files sft writes
//   {"procedural": "wood"|"noise", "colors": [[r,g,b],[r,g,b]], "scale": s,
//    "roughness": x | "roughness_range": [lo, hi], "specular": s, "resolution": r, "seed": n}
//   {"uv_albedo": "albedo.png" | "albedo": [r,g,b], "colorspace": "linear"|"srgb",
//    "uv_roughness": "roughness.png" | "roughness": x, "specular": s}   (with at least one of
//    uv_albedo, uv_roughness) the UV-texture material: the textures as given, sampled
//    bilinearly at render time through the mesh's per-corner UVs; a constant becomes a 1×1
//    texture. Albedo: an RGB(A) image (alpha ignored); roughness: a grey image, always linear.
//    The corner UVs are the mesh's, or with "uv_mesh": "file.obj" those of that mesh file (the
//    same faces in the same order; how a run folder keeps them, since mesh.ply has none).
//    Only with MaterialUse::kCheckpoint and kRender.
// An MTL file (what `sft export` writes; mtl_material.h) is read as the UV-texture form.
// Optional everywhere: "fresnel": "constant"|"schlick". Relative paths are relative to the JSON
// file's directory, or to the working directory for inline JSON. Ranges (docs/cli.md "Materials"):
// colours, roughness and specular in [0, 1], resolution in [1, 64], scale in (0, 1e6]; a value
// outside is an error naming the file, the field and the value. Texture texels: non-finite is an
// error, outside [0, 1] is clamped with a warning. Errors name the field. An empty `spec` gives the
// default material (albedo 0.7, roughness 0.5, specular 0).
Status LoadMaterial(const std::string& spec, const TriMesh& mesh, Material* material,
                    MaterialUse use = MaterialUse::kFit);

// Writes albedo and roughness mesh-colors files plus a material JSON that references them
// ({"mesh_colors": ..., "roughness_mesh_colors": ..., "specular": ...}), atomically. A UV-texture
// material is an error (sft export writes those).
Status SaveMaterial(const std::string& json_path, const Material& material);

// Writes a UV-texture material (Material::has_uv_textures()) as STEM_albedo.png (8-bit sRGB),
// STEM_roughness.png (8-bit linear) and the JSON {"uv_albedo", "colorspace": "srgb",
// "uv_roughness", "uv_mesh", "specular", "fresnel"} (STEM = the JSON file's stem), each file
// atomically, the JSON last. `uv_mesh` names (relative to the JSON's folder) a mesh file the
// caller has written with the material's corner UVs. Texel values are clamped to [0, 1]; 8 bits
// quantise them (albedo in sRGB steps of 1/255, roughness in linear steps of 1/255). Error for a
// mesh-colors material.
Status SaveUvMaterial(const std::string& json_path, const Material& material,
                      const std::string& uv_mesh);

}  // namespace sft

#endif  // SFT_GEOMETRY_MATERIAL_H_
