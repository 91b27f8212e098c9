// OBJ + MTL + PNG textures, and the seam split shared with the glTF writer.
#include <cstdio>
#include <map>
#include <utility>

#include "src/core/file_util.h"
#include "src/export/export_formats.h"
#include "src/image/image_io.h"

namespace sft {
namespace {

std::string Format(const char* format, double a, double b, double c) {
  char line[128];
  std::snprintf(line, sizeof(line), format, a, b, c);
  return line;
}

}  // namespace

SeamSplitMesh SplitAtSeams(const std::vector<Eigen::Vector3i>& faces, const UvAtlas& atlas) {
  SeamSplitMesh out;
  std::map<std::pair<int, int>, int> index;  // (mesh vertex, chart) → split vertex.
  out.faces.resize(faces.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const auto key = std::make_pair(faces[f][c], atlas.chart_of_face[f]);
      auto [it, inserted] = index.emplace(key, static_cast<int>(out.source_vertex.size()));
      if (inserted) {
        out.source_vertex.push_back(faces[f][c]);
        out.uv.push_back(atlas.corner_uv[3 * f + c]);
      }
      out.faces[f][c] = it->second;
    }
  }
  return out;
}

Status WriteObjExport(const std::string& dir, const std::vector<Eigen::Vector3d>& positions,
                      const std::vector<Eigen::Vector3i>& faces, const UvAtlas& atlas,
                      const BakedMaterial& baked, const Material& material) {
  SFT_RETURN_IF_ERROR(WritePng(JoinPath(dir, kAlbedoPngFile), baked.albedo, /*srgb=*/true));
  SFT_RETURN_IF_ERROR(WritePng(JoinPath(dir, kRoughnessPngFile), baked.roughness, /*srgb=*/false));
  const double s = material.specular;
  std::string mtl =
      "# sft export: albedo (sRGB) and GGX roughness (linear, alpha = roughness^2) textures\n"
      "newmtl sft_material\n"
      "Kd 1 1 1\n" +
      Format("Ks %.6g %.6g %.6g\n", s, s, s) +
      "Ns 0\nillum 2\n"
      "map_Kd " +
      std::string(kAlbedoPngFile) +
      "\n"
      "Pr 1\nPm 0\n"
      "map_Pr " +
      std::string(kRoughnessPngFile) + "\n";
  SFT_RETURN_IF_ERROR(WriteTextFile(JoinPath(dir, kMtlFile), mtl));

  const SeamSplitMesh split = SplitAtSeams(faces, atlas);
  std::string obj = "# sft export: " + std::to_string(positions.size()) + " vertices, " +
                    std::to_string(faces.size()) + " faces, " + std::to_string(atlas.num_charts) +
                    " UV charts\nmtllib " + kMtlFile + "\no sft_model\n";
  obj.reserve(64 * (positions.size() + split.uv.size() + faces.size()));
  for (const Eigen::Vector3d& p : positions)
    obj += Format("v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
  for (const Eigen::Vector2d& uv : split.uv) {
    char line[96];
    std::snprintf(line, sizeof(line), "vt %.9g %.9g\n", uv.x(), uv.y());
    obj += line;
  }
  obj += "usemtl sft_material\n";
  for (size_t f = 0; f < faces.size(); ++f) {
    char line[128];
    std::snprintf(line, sizeof(line), "f %d/%d %d/%d %d/%d\n", faces[f][0] + 1,
                  split.faces[f][0] + 1, faces[f][1] + 1, split.faces[f][1] + 1, faces[f][2] + 1,
                  split.faces[f][2] + 1);
    obj += line;
  }
  return WriteTextFile(JoinPath(dir, kObjFile), obj);
}

}  // namespace sft
