// PLY files for src/geometry/mesh.h: the validating parser (ascii, binary little and big endian)
// and the writer (OpenMesh's, binary little endian, float32 vertices); see mesh.cc.
#include <glog/logging.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "src/core/file_util.h"
#include "src/geometry/mesh_internal.h"

namespace sft {
namespace mesh_internal {

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool ParsePlyType(std::string_view name, PlyType* type) {
  static const std::pair<const char*, PlyType> kTypes[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& t : kTypes) {
    if (name == t.first) {
      *type = t.second;
      return true;
    }
  }
  return false;
}

int PlyTypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

// Reads PLY body values: whitespace-separated tokens (ascii) or packed binary values.
class PlyBodyReader {
 public:
  enum class Format { kAscii, kBinaryLittle, kBinaryBig };
  PlyBodyReader(const std::string& text, size_t start, Format format)
      : text_(text), pos_(start), format_(format) {}

  // Reads one value of `type` as a double. Returns false at the end of data or on a malformed
  // ascii token.
  bool Read(PlyType type, double* value) {
    if (format_ == Format::kAscii) {
      while (pos_ < text_.size() && (IsSpace(text_[pos_]) || text_[pos_] == '\n')) ++pos_;
      const size_t start = pos_;
      while (pos_ < text_.size() && !IsSpace(text_[pos_]) && text_[pos_] != '\n') ++pos_;
      if (pos_ == start) return false;
      return ParseDouble(std::string_view(text_).substr(start, pos_ - start), value);
    }
    const int size = PlyTypeSize(type);
    if (pos_ + size > text_.size()) return false;
    unsigned char bytes[8];
    std::memcpy(bytes, text_.data() + pos_, size);
    pos_ += size;
    if ((format_ == Format::kBinaryBig) == HostIsLittleEndian()) {
      for (int i = 0; i < size / 2; ++i) std::swap(bytes[i], bytes[size - 1 - i]);
    }
    switch (type) {
      case PlyType::kInt8:
        *value = static_cast<int8_t>(bytes[0]);
        break;
      case PlyType::kUint8:
        *value = bytes[0];
        break;
      case PlyType::kInt16:
        *value = Load<int16_t>(bytes);
        break;
      case PlyType::kUint16:
        *value = Load<uint16_t>(bytes);
        break;
      case PlyType::kInt32:
        *value = Load<int32_t>(bytes);
        break;
      case PlyType::kUint32:
        *value = Load<uint32_t>(bytes);
        break;
      case PlyType::kFloat32:
        *value = Load<float>(bytes);
        break;
      case PlyType::kFloat64:
        *value = Load<double>(bytes);
        break;
    }
    return true;
  }

 private:
  static bool HostIsLittleEndian() {
    const uint16_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    return first == 1;
  }
  template <typename T>
  static T Load(const unsigned char* bytes) {
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }

  const std::string& text_;
  size_t pos_;
  Format format_;
};

Status ParsePly(const std::string& path, const std::string& text, ParsedMesh* out) {
  // Header: lines up to "end_header".
  LineReader reader(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  if (!reader.Next(&line) || (Tokenize(line, &tokens), tokens.size() != 1 || tokens[0] != "ply")) {
    return Status::Error(path + ": not a PLY file (first line must be 'ply')");
  }
  PlyBodyReader::Format format = PlyBodyReader::Format::kAscii;
  bool have_format = false, have_end = false;
  std::vector<PlyElement> elements;
  size_t body_start = 0;
  while (reader.Next(&line)) {
    const int ln = reader.line_number();
    // Comments start with the keyword "comment", not '#': tokenize without comment stripping.
    tokens.clear();
    {
      size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && IsSpace(line[i])) ++i;
        const size_t s = i;
        while (i < line.size() && !IsSpace(line[i])) ++i;
        if (i > s) tokens.push_back(line.substr(s, i - s));
      }
    }
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      have_end = true;
      body_start = static_cast<size_t>(line.data() + line.size() - text.data()) + 1;
      break;
    }
    if (key == "format") {
      if (tokens.size() < 2) return Status::Error(LinePrefix(path, ln) + ": malformed format");
      if (tokens[1] == "ascii") {
        format = PlyBodyReader::Format::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        format = PlyBodyReader::Format::kBinaryLittle;
      } else if (tokens[1] == "binary_big_endian") {
        format = PlyBodyReader::Format::kBinaryBig;
      } else {
        return Status::Error(LinePrefix(path, ln) + ": unknown PLY format '" +
                             std::string(tokens[1]) + "'");
      }
      have_format = true;
    } else if (key == "element") {
      long long count = 0;
      if (tokens.size() != 3 || !ParseInt(tokens[2], &count) || count < 0 ||
          count > std::numeric_limits<int>::max()) {
        return Status::Error(LinePrefix(path, ln) + ": malformed element line");
      }
      elements.push_back({std::string(tokens[1]), count, {}});
    } else if (key == "property") {
      if (elements.empty()) {
        return Status::Error(LinePrefix(path, ln) + ": property before any element");
      }
      PlyProperty property;
      if (tokens.size() == 5 && tokens[1] == "list") {
        property.is_list = true;
        if (!ParsePlyType(tokens[2], &property.count_type) ||
            !ParsePlyType(tokens[3], &property.type) || property.count_type == PlyType::kFloat32 ||
            property.count_type == PlyType::kFloat64) {
          return Status::Error(LinePrefix(path, ln) + ": malformed list property");
        }
        property.name = std::string(tokens[4]);
      } else if (tokens.size() == 3 && ParsePlyType(tokens[1], &property.type)) {
        property.name = std::string(tokens[2]);
      } else {
        return Status::Error(LinePrefix(path, ln) + ": malformed property line");
      }
      elements.back().properties.push_back(property);
    } else {
      return Status::Error(LinePrefix(path, ln) + ": unknown PLY header line '" + std::string(key) +
                           "'");
    }
  }
  if (!have_format) return Status::Error(path + ": PLY header has no format line");
  if (!have_end) return Status::Error(path + ": PLY header has no end_header");
  if (body_start > text.size()) body_start = text.size();

  // Which properties carry what we need.
  const PlyElement* vertex_element = nullptr;
  const PlyElement* face_element = nullptr;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex") vertex_element = &e;
    if (e.name == "face") face_element = &e;
  }
  if (vertex_element == nullptr) return Status::Error(path + ": PLY has no vertex element");
  if (face_element == nullptr || face_element->count == 0) {
    return Status::Error(path + ": no faces");
  }
  auto find = [](const PlyElement& e, std::initializer_list<const char*> names, bool list) {
    for (const char* name : names) {
      for (size_t i = 0; i < e.properties.size(); ++i) {
        if (e.properties[i].name == name && e.properties[i].is_list == list) {
          return static_cast<int>(i);
        }
      }
    }
    return -1;
  };
  const int px = find(*vertex_element, {"x"}, false);
  const int py = find(*vertex_element, {"y"}, false);
  const int pz = find(*vertex_element, {"z"}, false);
  if (px < 0 || py < 0 || pz < 0) {
    return Status::Error(path + ": PLY vertex element lacks scalar x, y, z properties");
  }
  const int pu = find(*vertex_element, {"u", "s", "texture_u", "texture_s"}, false);
  const int pv = find(*vertex_element, {"v", "t", "texture_v", "texture_t"}, false);
  const bool vertex_uvs = pu >= 0 && pv >= 0;
  const int pindices = find(*face_element, {"vertex_indices", "vertex_index"}, true);
  if (pindices < 0) {
    return Status::Error(path + ": PLY face element lacks a vertex_indices list property");
  }
  const int ptexcoord = find(*face_element, {"texcoord"}, true);  // MeshLab per-corner UVs.

  PlyBodyReader body(text, body_start, format);
  const long long num_vertices = vertex_element->count;
  std::vector<double> values;
  for (const PlyElement& e : elements) {
    // An element without properties occupies no bytes, whatever its count: skipping it keeps the
    // loop below bounded by the file's size (a count of 2^31 - 1 would otherwise spin for
    // minutes on nothing).
    if (e.properties.empty()) continue;
    for (long long n = 0; n < e.count; ++n) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      Eigen::Vector2d uv = Eigen::Vector2d::Zero();
      int face_uv_begin = 0, face_uv_count = -1;  // This face's per-corner UVs in the pool.
      for (size_t pi = 0; pi < e.properties.size(); ++pi) {
        const PlyProperty& prop = e.properties[pi];
        auto truncated = [&]() {
          return Status::Error(path + ": truncated or malformed data in element '" + e.name + "' " +
                               std::to_string(n) + ", property '" + prop.name + "'");
        };
        if (!prop.is_list) {
          double value = 0.0;
          if (!body.Read(prop.type, &value)) return truncated();
          if (&e == vertex_element) {
            const int i = static_cast<int>(pi);
            if (i == px) p.x() = value;
            if (i == py) p.y() = value;
            if (i == pz) p.z() = value;
            if (i == pu) uv.x() = value;
            if (i == pv) uv.y() = value;
          }
          continue;
        }
        double count_value = 0.0;
        if (!body.Read(prop.count_type, &count_value)) return truncated();
        if (count_value < 0 || count_value != std::floor(count_value) || count_value > 1e6) {
          return truncated();
        }
        const int count = static_cast<int>(count_value);
        values.resize(count);
        for (int k = 0; k < count; ++k) {
          if (!body.Read(prop.type, &values[k])) return truncated();
        }
        if (&e != face_element) continue;
        if (static_cast<int>(pi) == pindices) {
          if (count < 3) {
            return Status::Error(path + ": face " + std::to_string(n) + " has " +
                                 std::to_string(count) + " vertices (at least 3 needed)");
          }
          for (int k = 0; k < count; ++k) {
            const double v = values[k];
            if (v != std::floor(v) || v < 0 || v >= static_cast<double>(num_vertices)) {
              return Status::Error(path + ": face " + std::to_string(n) + ": vertex index " +
                                   std::to_string(static_cast<long long>(v)) + " out of range (" +
                                   std::to_string(num_vertices) + " vertices)");
            }
            out->corner_vertices.push_back(static_cast<int>(v));
          }
        } else if (static_cast<int>(pi) == ptexcoord) {
          // Appended to the pool now; attached to the corners once the face is complete.
          face_uv_begin = static_cast<int>(out->uvs.size());
          face_uv_count = count / 2;
          for (int k = 0; k + 1 < count; k += 2) {
            const Eigen::Vector2d uv(values[k], values[k + 1]);
            if (!uv.allFinite()) {
              return Status::Error(path + ": face " + std::to_string(n) +
                                   ": non-finite texture coordinate");
            }
            out->uvs.push_back(uv);
          }
        }
      }
      if (&e == vertex_element) {
        if (!p.allFinite()) {
          return Status::Error(path + ": vertex " + std::to_string(n) + ": non-finite coordinate");
        }
        out->positions.push_back(p);
        if (vertex_uvs) {
          if (!uv.allFinite()) {
            return Status::Error(path + ": vertex " + std::to_string(n) +
                                 ": non-finite texture coordinate");
          }
          if (ptexcoord < 0) out->uvs.push_back(uv);
        }
      } else if (&e == face_element) {
        const int begin = out->face_offsets.back();
        const int corners = static_cast<int>(out->corner_vertices.size()) - begin;
        out->corner_uvs.resize(out->corner_vertices.size(), -1);
        if (ptexcoord >= 0) {
          // A face whose UV count differs from its corner count gets none (and BuildMesh then
          // drops the UVs of the whole mesh with a warning).
          if (face_uv_count == corners) {
            for (int k = 0; k < corners; ++k) out->corner_uvs[begin + k] = face_uv_begin + k;
          }
        } else if (vertex_uvs) {
          for (int k = 0; k < corners; ++k) {
            out->corner_uvs[begin + k] = out->corner_vertices[begin + k];
          }
        }
        out->EndFace();
      }
    }
  }
  return Status::Ok();
}

Status WritePly(const std::string& path, const TriMesh& mesh) {
  // OpenMesh's writers index vertices by position in the arrays: garbage-collect deleted elements
  // on a copy first.
  bool has_deleted = false;
  if (mesh.has_vertex_status() || mesh.has_face_status()) {
    has_deleted =
        mesh.n_vertices() !=
            static_cast<size_t>(std::distance(mesh.vertices_begin(), mesh.vertices_end())) ||
        mesh.n_faces() != static_cast<size_t>(std::distance(mesh.faces_begin(), mesh.faces_end()));
  }
  TriMesh compacted;
  const TriMesh* source = &mesh;
  if (has_deleted) {
    compacted = mesh;
    compacted.garbage_collection();
    source = &compacted;
  }
  return WriteAtomically(path, [&](const std::string& tmp) -> Status {
    ScopedOpenMeshQuiet quiet;
    const OpenMesh::IO::Options options(OpenMesh::IO::Options::Binary | OpenMesh::IO::Options::LSB);
    if (!OpenMesh::IO::write_mesh(*source, tmp, options)) {
      return Status::Error(path + ": write failed");
    }
    return Status::Ok();
  });
}

}  // namespace mesh_internal
}  // namespace sft
