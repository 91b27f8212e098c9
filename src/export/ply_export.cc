// PLY with per-vertex colours (for point-cloud tools).
#include <cstdint>
#include <cstring>
#include <fstream>

#include "src/core/file_util.h"
#include "src/export/export_formats.h"
#include "src/image/image_io.h"

namespace sft {
namespace {

template <typename T>
void Append(std::string* bytes, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));  // x86-64 and the PLY header agree: little endian.
  bytes->append(raw, sizeof(T));
}

}  // namespace

Status WriteColoredPly(const std::string& path, const std::vector<Eigen::Vector3d>& positions,
                       const std::vector<Eigen::Vector3i>& faces, const Material& material) {
  // Mean albedo at each vertex: the mesh-colors texel at each corner (α, β at the corner), or the
  // UV texture at the corner's UV.
  std::vector<Eigen::Vector3d> sum(positions.size(), Eigen::Vector3d::Zero());
  std::vector<int> count(positions.size(), 0);
  const Eigen::Vector2d corner_ab[3] = {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int c = 0; c < 3; ++c) {
      Eigen::Vector3d a;
      if (material.has_uv_textures()) {  // the bilinear texture at the corner's UV.
        material.uv.albedo.Sample(material.uv.corner_uvs[3 * f + c], a.data());
      } else {
        const double* t = material.albedo.texel(
            material.albedo.TexelIndex(static_cast<int>(f), corner_ab[c].x(), corner_ab[c].y()));
        a = Eigen::Vector3d(t[0], t[1], t[2]);
      }
      sum[faces[f][c]] += a;
      ++count[faces[f][c]];
    }
  }
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\ncomment sft export: albedo as sRGB vertex colours\n"
      "element vertex " +
      std::to_string(positions.size()) +
      "\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      "element face " +
      std::to_string(faces.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (size_t v = 0; v < positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) Append(&bytes, static_cast<float>(positions[v][k]));
    const Eigen::Vector3d albedo =
        count[v] > 0 ? Eigen::Vector3d(sum[v] / count[v]) : Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const float srgb = LinearToSrgb(static_cast<float>(albedo[k]));
      Append(&bytes, static_cast<uint8_t>(std::lround(std::clamp(srgb, 0.0f, 1.0f) * 255.0f)));
    }
  }
  for (const Eigen::Vector3i& face : faces) {
    Append(&bytes, static_cast<uint8_t>(3));
    for (int k = 0; k < 3; ++k) Append(&bytes, static_cast<int32_t>(face[k]));
  }
  return WriteAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) return Status::Error(path + ": cannot write PLY");
    return Status::Ok();
  });
}

}  // namespace sft
