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
namespace {

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

// The header: body format, elements with their properties, and where the body starts.
struct PlyHeader {
  PlyBodyReader::Format format = PlyBodyReader::Format::kAscii;
  std::vector<PlyElement> elements;
  size_t body_start = 0;
};

// Whitespace-separated tokens of a header line. Comments start with the keyword "comment", not
// '#', so nothing is stripped.
void TokenizeHeaderLine(std::string_view line, std::vector<std::string_view>* tokens) {
  tokens->clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsSpace(line[i])) ++i;
    const size_t s = i;
    while (i < line.size() && !IsSpace(line[i])) ++i;
    if (i > s) tokens->push_back(line.substr(s, i - s));
  }
}

Status ParsePlyProperty(const std::vector<std::string_view>& tokens, const std::string& where,
                        PlyProperty* property) {
  if (tokens.size() == 5 && tokens[1] == "list") {
    property->is_list = true;
    if (!ParsePlyType(tokens[2], &property->count_type) ||
        !ParsePlyType(tokens[3], &property->type) || property->count_type == PlyType::kFloat32 ||
        property->count_type == PlyType::kFloat64) {
      return Status::Error(where + ": malformed list property");
    }
    property->name = std::string(tokens[4]);
  } else if (tokens.size() == 3 && ParsePlyType(tokens[1], &property->type)) {
    property->name = std::string(tokens[2]);
  } else {
    return Status::Error(where + ": malformed property line");
  }
  return Status::Ok();
}

// A "format", "element" or "property" line (`where` = "PATH: line N").
Status ParsePlyHeaderLine(const std::vector<std::string_view>& tokens, const std::string& where,
                          PlyHeader* header, bool* have_format) {
  const std::string_view key = tokens[0];
  if (key == "format") {
    if (tokens.size() < 2) return Status::Error(where + ": malformed format");
    if (tokens[1] == "ascii") {
      header->format = PlyBodyReader::Format::kAscii;
    } else if (tokens[1] == "binary_little_endian") {
      header->format = PlyBodyReader::Format::kBinaryLittle;
    } else if (tokens[1] == "binary_big_endian") {
      header->format = PlyBodyReader::Format::kBinaryBig;
    } else {
      return Status::Error(where + ": unknown PLY format '" + std::string(tokens[1]) + "'");
    }
    *have_format = true;
  } else if (key == "element") {
    long long count = 0;
    if (tokens.size() != 3 || !ParseInt(tokens[2], &count) || count < 0 ||
        count > std::numeric_limits<int>::max()) {
      return Status::Error(where + ": malformed element line");
    }
    header->elements.push_back({std::string(tokens[1]), count, {}});
  } else if (key == "property") {
    if (header->elements.empty()) return Status::Error(where + ": property before any element");
    PlyProperty property;
    SFT_RETURN_IF_ERROR(ParsePlyProperty(tokens, where, &property));
    header->elements.back().properties.push_back(property);
  } else {
    return Status::Error(where + ": unknown PLY header line '" + std::string(key) + "'");
  }
  return Status::Ok();
}

// Lines up to "end_header".
Status ParsePlyHeader(const std::string& path, const std::string& text, PlyHeader* header) {
  LineReader reader(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  if (!reader.Next(&line) || (Tokenize(line, &tokens), tokens.size() != 1 || tokens[0] != "ply")) {
    return Status::Error(path + ": not a PLY file (first line must be 'ply')");
  }
  bool have_format = false, have_end = false;
  while (reader.Next(&line)) {
    TokenizeHeaderLine(line, &tokens);
    if (tokens.empty() || tokens[0] == "comment" || tokens[0] == "obj_info") continue;
    if (tokens[0] == "end_header") {
      have_end = true;
      header->body_start = static_cast<size_t>(line.data() + line.size() - text.data()) + 1;
      break;
    }
    SFT_RETURN_IF_ERROR(
        ParsePlyHeaderLine(tokens, LinePrefix(path, reader.line_number()), header, &have_format));
  }
  if (!have_format) return Status::Error(path + ": PLY header has no format line");
  if (!have_end) return Status::Error(path + ": PLY header has no end_header");
  if (header->body_start > text.size()) header->body_start = text.size();
  return Status::Ok();
}

// Which elements and properties carry what the mesh needs (property indices, -1 = absent).
struct PlyLayout {
  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  int px = -1, py = -1, pz = -1, pu = -1, pv = -1;
  int pindices = -1;   // the face's vertex index list.
  int ptexcoord = -1;  // MeshLab's per-corner UV list.
  bool vertex_uvs() const { return pu >= 0 && pv >= 0; }
};

int FindPlyProperty(const PlyElement& e, std::initializer_list<const char*> names, bool list) {
  for (const char* name : names) {
    for (size_t i = 0; i < e.properties.size(); ++i) {
      if (e.properties[i].name == name && e.properties[i].is_list == list) {
        return static_cast<int>(i);
      }
    }
  }
  return -1;
}

Status FindPlyLayout(const std::string& path, const PlyHeader& header, PlyLayout* layout) {
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex") layout->vertex = &e;
    if (e.name == "face") layout->face = &e;
  }
  if (layout->vertex == nullptr) return Status::Error(path + ": PLY has no vertex element");
  if (layout->face == nullptr || layout->face->count == 0) {
    return Status::Error(path + ": no faces");
  }
  const PlyElement& vertex = *layout->vertex;
  layout->px = FindPlyProperty(vertex, {"x"}, false);
  layout->py = FindPlyProperty(vertex, {"y"}, false);
  layout->pz = FindPlyProperty(vertex, {"z"}, false);
  if (layout->px < 0 || layout->py < 0 || layout->pz < 0) {
    return Status::Error(path + ": PLY vertex element lacks scalar x, y, z properties");
  }
  layout->pu = FindPlyProperty(vertex, {"u", "s", "texture_u", "texture_s"}, false);
  layout->pv = FindPlyProperty(vertex, {"v", "t", "texture_v", "texture_t"}, false);
  layout->pindices = FindPlyProperty(*layout->face, {"vertex_indices", "vertex_index"}, true);
  if (layout->pindices < 0) {
    return Status::Error(path + ": PLY face element lacks a vertex_indices list property");
  }
  layout->ptexcoord = FindPlyProperty(*layout->face, {"texcoord"}, true);
  return Status::Ok();
}

// Reads one property of an element instance: a scalar as values = {v}, a list as its items.
// False on truncated or malformed data (a list count that is negative, fractional or > 10⁶).
bool ReadPlyProperty(PlyBodyReader* body, const PlyProperty& prop, std::vector<double>* values) {
  if (!prop.is_list) {
    values->resize(1);
    return body->Read(prop.type, &(*values)[0]);
  }
  double count_value = 0.0;
  if (!body->Read(prop.count_type, &count_value)) return false;
  if (count_value < 0 || count_value != std::floor(count_value) || count_value > 1e6) {
    return false;
  }
  values->resize(static_cast<int>(count_value));
  for (double& v : *values) {
    if (!body->Read(prop.type, &v)) return false;
  }
  return true;
}

// One face being read: its corners go straight to `out`; its per-corner UVs (texcoord list) are
// appended to the UV pool and attached once the face is complete.
struct PlyFace {
  int uv_begin = 0;
  int uv_count = -1;  // -1: no texcoord list.
};

// A list property `pi` of face `n`: the vertex indices or the per-corner UVs.
Status ReadPlyFaceList(const std::string& path, long long n, int pi,
                       const std::vector<double>& values, const PlyLayout& layout, PlyFace* face,
                       ParsedMesh* out) {
  const int count = static_cast<int>(values.size());
  if (pi == layout.pindices) {
    if (count < 3) {
      return Status::Error(path + ": face " + std::to_string(n) + " has " + std::to_string(count) +
                           " vertices (at least 3 needed)");
    }
    const long long num_vertices = layout.vertex->count;
    for (const double v : values) {
      if (v != std::floor(v) || v < 0 || v >= static_cast<double>(num_vertices)) {
        return Status::Error(path + ": face " + std::to_string(n) + ": vertex index " +
                             std::to_string(static_cast<long long>(v)) + " out of range (" +
                             std::to_string(num_vertices) + " vertices)");
      }
      out->corner_vertices.push_back(static_cast<int>(v));
    }
  } else if (pi == layout.ptexcoord) {
    face->uv_begin = static_cast<int>(out->uvs.size());
    face->uv_count = count / 2;
    for (int k = 0; k + 1 < count; k += 2) {
      const Eigen::Vector2d uv(values[k], values[k + 1]);
      if (!uv.allFinite()) {
        return Status::Error(path + ": face " + std::to_string(n) +
                             ": non-finite texture coordinate");
      }
      out->uvs.push_back(uv);
    }
  }
  return Status::Ok();
}

// Ends a face: attaches its UVs (per corner, or the vertices' own) and closes it.
void EndPlyFace(const PlyLayout& layout, const PlyFace& face, ParsedMesh* out) {
  const int begin = out->face_offsets.back();
  const int corners = static_cast<int>(out->corner_vertices.size()) - begin;
  out->corner_uvs.resize(out->corner_vertices.size(), -1);
  if (layout.ptexcoord >= 0) {
    // A face whose UV count differs from its corner count gets none (and BuildMesh then drops
    // the UVs of the whole mesh with a warning).
    if (face.uv_count == corners) {
      for (int k = 0; k < corners; ++k) out->corner_uvs[begin + k] = face.uv_begin + k;
    }
  } else if (layout.vertex_uvs()) {
    for (int k = 0; k < corners; ++k) {
      out->corner_uvs[begin + k] = out->corner_vertices[begin + k];
    }
  }
  out->EndFace();
}

// Reads vertex `n` (its scalar properties; lists are read and ignored) into `out`.
Status ReadPlyVertex(const std::string& path, long long n, PlyBodyReader* body,
                     const PlyLayout& layout, std::vector<double>* values, ParsedMesh* out) {
  const PlyElement& e = *layout.vertex;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  for (size_t pi = 0; pi < e.properties.size(); ++pi) {
    const PlyProperty& prop = e.properties[pi];
    if (!ReadPlyProperty(body, prop, values)) {
      return Status::Error(path + ": truncated or malformed data in element '" + e.name + "' " +
                           std::to_string(n) + ", property '" + prop.name + "'");
    }
    if (prop.is_list) continue;
    const int i = static_cast<int>(pi);
    const double value = (*values)[0];
    if (i == layout.px) p.x() = value;
    if (i == layout.py) p.y() = value;
    if (i == layout.pz) p.z() = value;
    if (i == layout.pu) uv.x() = value;
    if (i == layout.pv) uv.y() = value;
  }
  if (!p.allFinite()) {
    return Status::Error(path + ": vertex " + std::to_string(n) + ": non-finite coordinate");
  }
  out->positions.push_back(p);
  if (layout.vertex_uvs()) {
    if (!uv.allFinite()) {
      return Status::Error(path + ": vertex " + std::to_string(n) +
                           ": non-finite texture coordinate");
    }
    if (layout.ptexcoord < 0) out->uvs.push_back(uv);
  }
  return Status::Ok();
}

// Reads instance `n` of element `e` other than the vertices: faces go to `out`, anything else is
// read and dropped.
Status ReadPlyOther(const std::string& path, const PlyElement& e, long long n, PlyBodyReader* body,
                    const PlyLayout& layout, std::vector<double>* values, ParsedMesh* out) {
  const bool is_face = &e == layout.face;
  PlyFace face;
  for (size_t pi = 0; pi < e.properties.size(); ++pi) {
    const PlyProperty& prop = e.properties[pi];
    if (!ReadPlyProperty(body, prop, values)) {
      return Status::Error(path + ": truncated or malformed data in element '" + e.name + "' " +
                           std::to_string(n) + ", property '" + prop.name + "'");
    }
    if (is_face && prop.is_list) {
      SFT_RETURN_IF_ERROR(
          ReadPlyFaceList(path, n, static_cast<int>(pi), *values, layout, &face, out));
    }
  }
  if (is_face) EndPlyFace(layout, face, out);
  return Status::Ok();
}

}  // namespace

Status ParsePly(const std::string& path, const std::string& text, ParsedMesh* out) {
  PlyHeader header;
  SFT_RETURN_IF_ERROR(ParsePlyHeader(path, text, &header));
  PlyLayout layout;
  SFT_RETURN_IF_ERROR(FindPlyLayout(path, header, &layout));
  PlyBodyReader body(text, header.body_start, header.format);
  std::vector<double> values;
  for (const PlyElement& e : header.elements) {
    // An element without properties occupies no bytes, whatever its count: skipping it keeps the
    // loop below bounded by the file's size (a count of 2^31 - 1 would otherwise spin for
    // minutes on nothing).
    if (e.properties.empty()) continue;
    for (long long n = 0; n < e.count; ++n) {
      if (&e == layout.vertex) {
        SFT_RETURN_IF_ERROR(ReadPlyVertex(path, n, &body, layout, &values, out));
      } else {
        SFT_RETURN_IF_ERROR(ReadPlyOther(path, e, n, &body, layout, &values, out));
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
