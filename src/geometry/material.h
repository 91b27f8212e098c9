// The spatially varying material: diffuse albedo (RGB) and GGX roughness stored as mesh colors,
// plus a global specular weight. BSDF f = albedo/π + specular·D·G1·G1/(4|n·wi||n·wo|).
#ifndef SFT_GEOMETRY_MATERIAL_H_
#define SFT_GEOMETRY_MATERIAL_H_

#include <string>

#include "src/core/status.h"
#include "src/geometry/mesh.h"
#include "src/geometry/mesh_colors.h"

namespace sft {

enum class FresnelMode { kConstant, kSchlick };

struct Material {
  MeshColors albedo;      // 3 channels, linear, in [0, 1].
  MeshColors roughness;   // 1 channel, in [0, 1]; GGX α = roughness².
  double specular = 0.0;  // glossy lobe weight (constant Fresnel), or F0 with Schlick; [0, 1].
  FresnelMode fresnel = FresnelMode::kConstant;
};

// A material with constant albedo and roughness at mesh-colors resolution `resolution`.
Material ConstantMaterial(int num_faces, const Eigen::Vector3d& albedo, double roughness,
                          double specular, int resolution = 1);

// Builds a material from `spec`: the path of a JSON file, or inline JSON (first non-space character
// '{'). Forms (docs/cli.md, "Materials"):
//   {"albedo": [r,g,b], "roughness": x, "specular": s}                       constants
//   {"albedo_texture": "tex.png", "colorspace": "linear"|"srgb", "roughness": x, "specular": s,
//    "resolution": r}   sampled from the mesh's per-corner UVs (the mesh must have them)
//   {"mesh_colors": "file", "roughness_mesh_colors": "file", "specular": s}   files sft writes
//   {"procedural": "wood"|"noise", "colors": [[r,g,b],[r,g,b]], "scale": s,
//    "roughness": x | "roughness_range": [lo, hi], "specular": s, "resolution": r, "seed": n}
// Optional everywhere: "fresnel": "constant"|"schlick". Relative paths are relative to the JSON
// file's directory, or to the working directory for inline JSON. Ranges (docs/cli.md "Materials"):
// colours, roughness and specular in [0, 1], resolution in [1, 64], scale in (0, 1e6]; a value
// outside is an error naming the file, the field and the value. Texture texels: non-finite is an
// error, outside [0, 1] is clamped with a warning. Errors name the field. An empty `spec` gives the
// default material (albedo 0.7, roughness 0.5, specular 0).
Status LoadMaterial(const std::string& spec, const TriMesh& mesh, Material* material);

// Writes albedo and roughness mesh-colors files plus a material JSON that references them
// ({"mesh_colors": ..., "roughness_mesh_colors": ..., "specular": ...}), atomically.
Status SaveMaterial(const std::string& json_path, const Material& material);

}  // namespace sft

#endif  // SFT_GEOMETRY_MATERIAL_H_
