#include "src/geometry/mesh_colors.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"

namespace sft {
namespace {

constexpr char kFormat[] = "sft-mesh-colors/1";
// Sanity limits for files (not for the class): beyond these a header is surely corrupt.
constexpr int kMaxFileResolution = 1024;
constexpr int kMaxFileChannels = 64;
// The header line is short; refuse to scan megabytes of binary for a newline.
constexpr size_t kMaxHeaderBytes = 1 << 16;

// Grid coordinates r·α are snapped up by this much before flooring, so that lattice points
// computed as i/r (e.g. TexelCenter of the corner texels, or a vertex) land on texel i even when
// r·(i/r) rounds to i − 1 ulp. It moves texel boundaries by 1e-9 of a texel, far below anything a
// renderer resolves.
constexpr double kLatticeSnap = 1e-9;

bool HostIsLittleEndian() {
  const uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

}  // namespace

MeshColors::MeshColors(int num_faces, int resolution, int channels, double fill)
    : num_faces_(num_faces), resolution_(resolution), channels_(channels) {
  CHECK_GE(num_faces, 0);
  CHECK_GE(resolution, 0);
  CHECK_GE(channels, 1);
  values_.assign(static_cast<size_t>(num_faces) * TexelsPerFace(resolution) * channels, fill);
}

int MeshColors::TexelIndex(int face, double alpha, double beta) const {
  DCHECK(face >= 0 && face < num_faces_) << "face " << face << " of " << num_faces_;
  const int r = resolution_;
  // Clamp into the triangle: negative weights to 0 (NaN too), then scale back onto the edge
  // α + β = 1 when the point lies beyond it.
  alpha = alpha > 0.0 ? std::min(alpha, 1.0) : 0.0;
  beta = beta > 0.0 ? std::min(beta, 1.0) : 0.0;
  const double sum = alpha + beta;
  if (sum > 1.0) {
    alpha /= sum;
    beta /= sum;
  }
  int i = static_cast<int>(std::floor(r * alpha + kLatticeSnap));
  int j = static_cast<int>(std::floor(r * beta + kLatticeSnap));
  i = std::min(std::max(i, 0), r);
  j = std::min(std::max(j, 0), r - i);
  return face * TexelsPerFace(r) + LocalIndex(r, i, j);
}

// In grid coordinates (x, y) = r·(α, β), texel (i, j) owns the points of the triangle
// {x, y ≥ 0, x + y ≤ r} with floor(x) = i and floor(y) = j. Exactly:
//   i + j ≤ r − 2: the whole unit square [i, i+1] × [j, j+1]  → centroid (i + 1/2, j + 1/2);
//   i + j = r − 1: the square is cut by x + y = r through its corners (i+1, j) and (i, j+1),
//                  leaving the lower triangle (i, j), (i+1, j), (i, j+1) → (i + 1/3, j + 1/3);
//   i + j = r:     only the lattice point (i, j) itself (zero area: these r + 1 texels per face
//                  are hit only at vertices and at lattice points of the edge α + β = 1) → (i, j).
// r = 0 has a single texel owning the whole triangle → its centroid.
Eigen::Vector2d MeshColors::TexelCenter(int resolution, int i, int j) {
  DCHECK(i >= 0 && j >= 0 && i + j <= resolution);
  const int r = resolution;
  if (r == 0) return Eigen::Vector2d(1.0 / 3.0, 1.0 / 3.0);
  double offset = 0.0;
  if (i + j <= r - 2) {
    offset = 0.5;
  } else if (i + j == r - 1) {
    offset = 1.0 / 3.0;
  }
  return Eigen::Vector2d((i + offset) / r, (j + offset) / r);
}

Status WriteMeshColors(const std::string& path, const MeshColors& colors,
                       const std::vector<std::string>& channel_names) {
  if (static_cast<int>(channel_names.size()) != colors.channels()) {
    return Status::Error(path + ": " + std::to_string(channel_names.size()) +
                         " channel names for " + std::to_string(colors.channels()) + " channels");
  }
  nlohmann::json header;
  header["format"] = kFormat;
  header["num_faces"] = colors.num_faces();
  header["resolution"] = colors.resolution();
  header["channels"] = colors.channels();
  header["names"] = channel_names;
  header["dtype"] = "float32";
  header["byte_order"] = "little";
  const std::string header_line = header.dump() + "\n";

  std::vector<float> payload(colors.values().begin(), colors.values().end());
  if (!HostIsLittleEndian()) {
    for (float& v : payload) {
      unsigned char b[4];
      std::memcpy(b, &v, 4);
      std::swap(b[0], b[3]);
      std::swap(b[1], b[2]);
      std::memcpy(&v, b, 4);
    }
  }
  return WriteAtomically(path, [&](const std::string& tmp) -> Status {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) return Status::Error(path + ": cannot open for writing");
    out.write(header_line.data(), static_cast<std::streamsize>(header_line.size()));
    out.write(reinterpret_cast<const char*>(payload.data()),
              static_cast<std::streamsize>(payload.size() * sizeof(float)));
    out.close();
    if (!out) return Status::Error(path + ": write failed");
    return Status::Ok();
  });
}

Status ReadMeshColors(const std::string& path, MeshColors* colors,
                      std::vector<std::string>* channel_names) {
  std::string data;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &data));
  return ParseMeshColors(data, path, colors, channel_names);
}

Status ParseMeshColors(const std::string& data, const std::string& path, MeshColors* colors,
                       std::vector<std::string>* channel_names) {
  const size_t newline = data.find('\n');
  if (newline == std::string::npos || newline > kMaxHeaderBytes) {
    return Status::Error(path + ": not a mesh-colors file (no one-line JSON header)");
  }
  nlohmann::json header;
  try {
    header = nlohmann::json::parse(data.begin(), data.begin() + newline);
  } catch (const nlohmann::json::exception& e) {
    return Status::Error(path + ": header is not valid JSON (" + e.what() + ")");
  }
  if (!header.is_object()) return Status::Error(path + ": header is not a JSON object");
  auto field_error = [&](const std::string& field, const std::string& what) {
    return Status::Error(path + ": header field \"" + field + "\": " + what);
  };
  auto get_string = [&](const char* field, const char* expected) -> Status {
    if (!header.contains(field)) return field_error(field, "missing");
    if (!header[field].is_string() || header[field].get<std::string>() != expected) {
      return field_error(field,
                         std::string("expected \"") + expected + "\", got " + header[field].dump());
    }
    return Status::Ok();
  };
  auto get_int = [&](const char* field, int lo, int hi, int* value) -> Status {
    if (!header.contains(field)) return field_error(field, "missing");
    const nlohmann::json& v = header[field];
    if (!v.is_number_integer() || v.get<int64_t>() < lo || v.get<int64_t>() > hi) {
      return field_error(field, "expected an integer in [" + std::to_string(lo) + ", " +
                                    std::to_string(hi) + "], got " + v.dump());
    }
    *value = static_cast<int>(v.get<int64_t>());
    return Status::Ok();
  };
  SFT_RETURN_IF_ERROR(get_string("format", kFormat));
  int num_faces = 0, resolution = 0, channels = 0;
  SFT_RETURN_IF_ERROR(get_int("num_faces", 0, 1 << 30, &num_faces));
  SFT_RETURN_IF_ERROR(get_int("resolution", 0, kMaxFileResolution, &resolution));
  SFT_RETURN_IF_ERROR(get_int("channels", 1, kMaxFileChannels, &channels));
  SFT_RETURN_IF_ERROR(get_string("dtype", "float32"));
  SFT_RETURN_IF_ERROR(get_string("byte_order", "little"));
  std::vector<std::string> names;
  if (!header.contains("names")) return field_error("names", "missing");
  const nlohmann::json& names_json = header["names"];
  if (!names_json.is_array() || static_cast<int>(names_json.size()) != channels) {
    return field_error("names", "expected an array of " + std::to_string(channels) +
                                    " strings, got " + names_json.dump());
  }
  for (const nlohmann::json& name : names_json) {
    if (!name.is_string()) return field_error("names", "entries must be strings");
    names.push_back(name.get<std::string>());
  }

  const uint64_t expected_values =
      static_cast<uint64_t>(num_faces) * MeshColors::TexelsPerFace(resolution) * channels;
  const uint64_t payload_bytes = data.size() - newline - 1;
  if (payload_bytes != expected_values * sizeof(float)) {
    return Status::Error(
        path + ": payload has " + std::to_string(payload_bytes) + " bytes, header (num_faces " +
        std::to_string(num_faces) + ", resolution " + std::to_string(resolution) + ", channels " +
        std::to_string(channels) + ") needs " + std::to_string(expected_values * sizeof(float)));
  }
  MeshColors result(num_faces, resolution, channels);
  const char* payload = data.data() + newline + 1;
  const bool swap = !HostIsLittleEndian();
  for (uint64_t k = 0; k < expected_values; ++k) {
    unsigned char b[4];
    std::memcpy(b, payload + 4 * k, 4);
    if (swap) {
      std::swap(b[0], b[3]);
      std::swap(b[1], b[2]);
    }
    float v;
    std::memcpy(&v, b, 4);
    if (!std::isfinite(v)) {
      return Status::Error(path + ": non-finite value at texel " + std::to_string(k / channels) +
                           ", channel " + std::to_string(k % channels));
    }
    result.values()[k] = v;
  }
  *colors = std::move(result);
  if (channel_names != nullptr) *channel_names = std::move(names);
  return Status::Ok();
}

}  // namespace sft
