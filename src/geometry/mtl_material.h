// Reading an MTL file (Wavefront material library) as a material: the subset that `sft export`
// writes (docs/export.md) and that describes one textured material, translated to the material
// JSON forms of material.h so that both share one builder and its checks.
#ifndef SFT_GEOMETRY_MTL_MATERIAL_H_
#define SFT_GEOMETRY_MTL_MATERIAL_H_

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "src/core/status.h"

namespace sft {

struct MtlMaterial {
  nlohmann::json json;  // a material JSON (material.h).
  // The MTL statement each JSON field came from, so that errors name what the user wrote.
  std::map<std::string, std::string> statement_of_field;
};

// Translates the MTL text of file `path` (one material):
//   map_Kd FILE  → "uv_albedo": FILE, "colorspace": "srgb" (MTL clients such as Blender read the
//                  diffuse map as sRGB colour; sft export writes it so);
//   Kd r g b     → "albedo" when there is no map_Kd; with map_Kd it must be 1 1 1 (MTL multiplies
//                  the map by it, which the UV material does not model);
//   map_Pr FILE  → "uv_roughness": FILE (linear);
//   Pr x         → "roughness" when there is no map_Pr; with map_Pr it must be 1;
//   Ks r g b     → "specular" (the GGX lobe's weight; r = g = b, sft's specular is grey);
//   Pm x         → must be 0 (sft's BSDF has no metallic lobe).
// Neither map gives the constant form ("albedo", "roughness"), a map the UV-texture form. Comments,
// blank lines, the material's name and Ns, illum, Ka, Ke, Ni, d, Tr (no counterpart in sft's
// BSDF, or opacity) are ignored; any other statement is ignored with one warning listing them.
// Errors (one line naming the file, the line number and the statement): a second `newmtl`,
// texture options (-s, -o, -bm, ...) or a missing file name after a map, a malformed or
// non-finite number, a multiplier other than 1 with its map, a non-grey Ks, a non-zero Pm.
Status ParseMtl(const std::string& text, const std::string& path, MtlMaterial* material);

}  // namespace sft

#endif  // SFT_GEOMETRY_MTL_MATERIAL_H_
