// Mesh files. Reading parses OBJ, PLY (ascii, binary little/big endian) and OFF with a validating
// parser of our own and builds the OpenMesh TriMesh with OpenMesh's own add_vertex/add_face (the
// same non-manifold handling as OpenMesh's importer: a face that cannot be added is given private
// copies of its vertices). We do not hand files to OpenMesh's readers because, measured on
// OpenMesh 9 (Debian 12):
//   - they skip faces with out-of-range indices silently;
//   - the OBJ/OFF/PLY readers parse coordinates as float (a double mesh written with 17 digits
//     does not read back to the same values);
//   - per-corner OBJ UVs are only right for triangles: for polygons and for non-manifold faces
//     (whose vertices get duplicated) the importer walks the wrong halfedges, and corners without
//     a `vt` keep uninitialized memory.
// Writing: PLY (binary little endian, float32 vertices) with OpenMesh's writer; OBJ and OFF by hand
// with shortest round-trip decimals (OpenMesh's OBJ writer prints to stdout, its OFF writer rounds
// to float), so that OBJ and OFF round trips are exact.
#include "src/geometry/mesh.h"

#include <glog/logging.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include "src/core/file_util.h"
#include "src/geometry/polygon.h"

namespace sft {
namespace {

// A face whose area is at most this fraction of the squared bounding-box diagonal counts as
// degenerate (zero area up to rounding of coordinates; 1e-12 is far above double rounding noise
// of ~1e-16 and far below the area of any real triangle of a mesh with < 1e10 faces).
constexpr double kDegenerateRelativeArea = 1e-12;

// What the format parsers produce: positions, a pool of UVs, and polygons as corner lists.
struct ParsedMesh {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector2d> uvs;
  std::vector<int> face_offsets{0};  // face f's corners are [face_offsets[f], face_offsets[f+1]).
  std::vector<int> corner_vertices;  // 0-based vertex index per corner.
  std::vector<int> corner_uvs;       // index into `uvs` per corner, or -1.
  std::vector<int> face_lines;       // 1-based line of each face in the file; empty for PLY.

  int num_faces() const { return static_cast<int>(face_offsets.size()) - 1; }
  void EndFace() { face_offsets.push_back(static_cast<int>(corner_vertices.size())); }
};

// Silences OpenMesh's error stream (add_face prints "complex edge" for every non-manifold face,
// which we handle and summarize ourselves) for the lifetime of the object; re-entrant and
// thread-safe across concurrent readers.
class ScopedOpenMeshQuiet {
 public:
  ScopedOpenMeshQuiet() {
    std::lock_guard<std::mutex> lock(Mutex());
    if (Depth()++ == 0) {
      SavedEnabled() = omerr().is_enabled();
      omerr().disable();
    }
  }
  ~ScopedOpenMeshQuiet() {
    std::lock_guard<std::mutex> lock(Mutex());
    if (--Depth() == 0 && SavedEnabled()) omerr().enable();
  }

 private:
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  static int& Depth() {
    static int depth = 0;
    return depth;
  }
  static bool& SavedEnabled() {
    static bool saved = true;
    return saved;
  }
};

// ---- Text helpers -------------------------------------------------------------------------------

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// Splits a line (without its '\n') into whitespace-separated tokens, dropping a '#' comment.
void Tokenize(std::string_view line, std::vector<std::string_view>* tokens) {
  tokens->clear();
  const size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsSpace(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !IsSpace(line[i])) ++i;
    if (i > start) tokens->push_back(line.substr(start, i - start));
  }
}

// Parses a whole token as a double (accepts "nan"/"inf": the caller checks finiteness, so that the
// error says "non-finite" rather than "malformed"). std::from_chars: locale-independent and fast.
bool ParseDouble(std::string_view token, double* value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const std::from_chars_result result = std::from_chars(token.data(), end, *value);
  if (result.ec == std::errc::result_out_of_range && result.ptr == end) {
    // Overflow or underflow: strtod gives ±inf or the nearest tiny value / 0, as wanted.
    const std::string copy(token);
    *value = std::strtod(copy.c_str(), nullptr);
    return true;
  }
  return result.ec == std::errc() && result.ptr == end;
}

bool ParseInt(std::string_view token, long long* value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const std::from_chars_result result = std::from_chars(token.data(), end, *value);
  return result.ec == std::errc() && result.ptr == end;
}

// Appends the shortest decimal text that reads back to exactly `value` (std::to_chars).
void AppendDouble(double value, std::string* out) {
  char buffer[32];
  const std::to_chars_result result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

// Iterates over the lines of a text buffer, numbering them from 1.
class LineReader {
 public:
  explicit LineReader(const std::string& text) : text_(text) {}
  bool Next(std::string_view* line) {
    if (pos_ >= text_.size()) return false;
    size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) end = text_.size();
    *line = std::string_view(text_).substr(pos_, end - pos_);
    pos_ = end + 1;
    ++line_number_;
    return true;
  }
  int line_number() const { return line_number_; }

 private:
  const std::string& text_;
  size_t pos_ = 0;
  int line_number_ = 0;
};

std::string LinePrefix(const std::string& path, int line) {
  return path + ": line " + std::to_string(line);
}

// ---- OBJ ----------------------------------------------------------------------------------------

Status ParseObj(const std::string& path, const std::string& text, ParsedMesh* out) {
  LineReader reader(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  int num_normals = 0;
  // Positive indices may refer to vertices defined later in the file (OpenMesh's reader allows
  // it too), so they are range-checked at the end; out->face_lines remembers where each face
  // came from.
  std::vector<int>& face_lines = out->face_lines;
  struct PendingNormal {
    long long index;
    int line;
  };
  std::vector<PendingNormal> positive_normals;
  std::vector<int> positive_uv_corners;  // corners whose uv index is a positive (deferred) one.

  while (reader.Next(&line)) {
    Tokenize(line, &tokens);
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    const int ln = reader.line_number();
    if (key == "v") {
      if (tokens.size() < 4) return Status::Error(LinePrefix(path, ln) + ": vertex needs x y z");
      Eigen::Vector3d p;
      for (int c = 0; c < 3; ++c) {
        if (!ParseDouble(tokens[1 + c], &p[c])) {
          return Status::Error(LinePrefix(path, ln) + ": malformed vertex coordinate '" +
                               std::string(tokens[1 + c]) + "'");
        }
      }
      if (!p.allFinite()) {
        return Status::Error(LinePrefix(path, ln) + ": non-finite vertex coordinate");
      }
      out->positions.push_back(p);
    } else if (key == "vt") {
      if (tokens.size() < 2) return Status::Error(LinePrefix(path, ln) + ": vt needs u [v]");
      Eigen::Vector2d uv(0.0, 0.0);
      for (int c = 0; c < 2 && 1 + c < static_cast<int>(tokens.size()); ++c) {
        if (!ParseDouble(tokens[1 + c], &uv[c])) {
          return Status::Error(LinePrefix(path, ln) + ": malformed texture coordinate '" +
                               std::string(tokens[1 + c]) + "'");
        }
      }
      if (!uv.allFinite()) {
        return Status::Error(LinePrefix(path, ln) + ": non-finite texture coordinate");
      }
      out->uvs.push_back(uv);
    } else if (key == "vn") {
      ++num_normals;
    } else if (key == "f") {
      if (tokens.size() < 4) {
        return Status::Error(LinePrefix(path, ln) + ": face with fewer than 3 vertices");
      }
      for (size_t t = 1; t < tokens.size(); ++t) {
        // v, v/vt, v//vn or v/vt/vn.
        std::string_view parts[3];
        int num_parts = 0;
        std::string_view rest = tokens[t];
        while (true) {
          const size_t slash = rest.find('/');
          if (num_parts == 3) {
            return Status::Error(LinePrefix(path, ln) + ": malformed face corner '" +
                                 std::string(tokens[t]) + "'");
          }
          parts[num_parts++] = rest.substr(0, slash);
          if (slash == std::string_view::npos) break;
          rest = rest.substr(slash + 1);
        }
        // Resolves a 1-based (or negative, relative) index against `count` elements so far.
        auto resolve = [&](std::string_view s, int count, const char* what, long long* index,
                           bool* deferred) -> Status {
          long long value = 0;
          if (!ParseInt(s, &value)) {
            return Status::Error(LinePrefix(path, ln) + ": malformed " + what + " index '" +
                                 std::string(s) + "'");
          }
          if (value == 0) {
            return Status::Error(LinePrefix(path, ln) + ": " + what +
                                 " index 0 (OBJ indices start at 1)");
          }
          *deferred = value > 0;
          *index = value > 0 ? value - 1 : count + value;
          if (*index < 0) {
            return Status::Error(LinePrefix(path, ln) + ": " + what + " index " +
                                 std::to_string(value) + " out of range (" + std::to_string(count) +
                                 " defined before it)");
          }
          return Status::Ok();
        };
        long long vi = 0;
        bool deferred = false;
        SFT_RETURN_IF_ERROR(
            resolve(parts[0], static_cast<int>(out->positions.size()), "vertex", &vi, &deferred));
        if (vi > std::numeric_limits<int>::max()) {
          return Status::Error(LinePrefix(path, ln) + ": vertex index out of range");
        }
        out->corner_vertices.push_back(static_cast<int>(vi));
        int uv_index = -1;
        if (num_parts >= 2 && !parts[1].empty()) {
          long long ti = 0;
          SFT_RETURN_IF_ERROR(resolve(parts[1], static_cast<int>(out->uvs.size()),
                                      "texture coordinate", &ti, &deferred));
          if (ti > std::numeric_limits<int>::max()) {
            return Status::Error(LinePrefix(path, ln) + ": texture coordinate index out of range");
          }
          uv_index = static_cast<int>(ti);
          if (deferred) positive_uv_corners.push_back(static_cast<int>(out->corner_uvs.size()));
        }
        out->corner_uvs.push_back(uv_index);
        if (num_parts == 3 && !parts[2].empty()) {
          long long ni = 0;
          SFT_RETURN_IF_ERROR(resolve(parts[2], num_normals, "normal", &ni, &deferred));
          if (deferred) positive_normals.push_back({ni, ln});
        }
      }
      out->EndFace();
      face_lines.push_back(ln);
    }
    // Everything else (o, g, s, usemtl, mtllib, l, p, vp, ...) does not affect the mesh.
  }

  // Deferred range checks against the final counts.
  const int num_vertices = static_cast<int>(out->positions.size());
  for (int f = 0; f < out->num_faces(); ++f) {
    for (int c = out->face_offsets[f]; c < out->face_offsets[f + 1]; ++c) {
      const int v = out->corner_vertices[c];
      if (v >= num_vertices) {
        return Status::Error(LinePrefix(path, face_lines[f]) + ": vertex index " +
                             std::to_string(v + 1) + " out of range (" +
                             std::to_string(num_vertices) + " vertices)");
      }
      if (out->corner_uvs[c] >= static_cast<int>(out->uvs.size())) {
        return Status::Error(LinePrefix(path, face_lines[f]) + ": texture coordinate index " +
                             std::to_string(out->corner_uvs[c] + 1) + " out of range (" +
                             std::to_string(out->uvs.size()) + " texture coordinates)");
      }
    }
  }
  for (const PendingNormal& n : positive_normals) {
    if (n.index >= num_normals) {
      return Status::Error(LinePrefix(path, n.line) + ": normal index " +
                           std::to_string(n.index + 1) + " out of range (" +
                           std::to_string(num_normals) + " normals)");
    }
  }
  return Status::Ok();
}

// ---- OFF ----------------------------------------------------------------------------------------

Status ParseOff(const std::string& path, const std::string& text, ParsedMesh* out) {
  LineReader reader(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  // Header keyword: [ST][C][N]OFF. 4OFF (homogeneous), nOFF (n-dimensional) and binary OFF are
  // not supported.
  while (reader.Next(&line)) {
    Tokenize(line, &tokens);
    if (!tokens.empty()) break;
  }
  if (tokens.empty()) return Status::Error(path + ": empty file (no faces)");
  std::string_view keyword = tokens[0];
  const bool known = keyword.size() >= 3 && keyword.substr(keyword.size() - 3) == "OFF";
  std::string_view prefix = known ? keyword.substr(0, keyword.size() - 3) : keyword;
  if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
  if (!prefix.empty() && prefix[0] == 'C') prefix.remove_prefix(1);
  if (!prefix.empty() && prefix[0] == 'N') prefix.remove_prefix(1);
  if (!known || !prefix.empty()) {
    return Status::Error(path + ": line " + std::to_string(reader.line_number()) +
                         ": expected an OFF header (OFF, COFF, NOFF, STOFF...), got '" +
                         std::string(keyword) + "'");
  }
  size_t next = 1;
  if (tokens.size() > 1 && tokens[1] == "BINARY") {
    return Status::Error(path + ": binary OFF is not supported (use PLY)");
  }
  if (tokens.size() <= next) {
    while (reader.Next(&line)) {
      Tokenize(line, &tokens);
      if (!tokens.empty()) break;
    }
    next = 0;
  }
  long long num_vertices = -1, num_faces = -1;
  if (tokens.size() < next + 2 || !ParseInt(tokens[next], &num_vertices) ||
      !ParseInt(tokens[next + 1], &num_faces) || num_vertices < 0 || num_faces < 0 ||
      num_vertices > std::numeric_limits<int>::max() ||
      num_faces > std::numeric_limits<int>::max()) {
    return Status::Error(LinePrefix(path, reader.line_number()) +
                         ": expected vertex and face counts after the OFF keyword");
  }
  while (static_cast<long long>(out->positions.size()) < num_vertices) {
    if (!reader.Next(&line)) {
      return Status::Error(path + ": truncated: header promises " + std::to_string(num_vertices) +
                           " vertices, file has " + std::to_string(out->positions.size()));
    }
    Tokenize(line, &tokens);
    if (tokens.empty()) continue;
    const int ln = reader.line_number();
    if (tokens.size() < 3) return Status::Error(LinePrefix(path, ln) + ": vertex needs x y z");
    Eigen::Vector3d p;
    for (int c = 0; c < 3; ++c) {
      if (!ParseDouble(tokens[c], &p[c])) {
        return Status::Error(LinePrefix(path, ln) + ": malformed vertex coordinate '" +
                             std::string(tokens[c]) + "'");
      }
    }
    if (!p.allFinite()) {
      return Status::Error(LinePrefix(path, ln) + ": non-finite vertex coordinate");
    }
    out->positions.push_back(p);
  }
  while (out->num_faces() < num_faces) {
    if (!reader.Next(&line)) {
      return Status::Error(path + ": truncated: header promises " + std::to_string(num_faces) +
                           " faces, file has " + std::to_string(out->num_faces()));
    }
    Tokenize(line, &tokens);
    if (tokens.empty()) continue;
    const int ln = reader.line_number();
    long long n = 0;
    if (!ParseInt(tokens[0], &n) || n < 3) {
      return Status::Error(LinePrefix(path, ln) + ": face needs a vertex count of at least 3");
    }
    if (static_cast<long long>(tokens.size()) < 1 + n) {
      return Status::Error(LinePrefix(path, ln) + ": face has fewer indices than its count " +
                           std::to_string(n));
    }
    for (long long k = 0; k < n; ++k) {
      long long v = 0;
      if (!ParseInt(tokens[1 + k], &v)) {
        return Status::Error(LinePrefix(path, ln) + ": malformed vertex index '" +
                             std::string(tokens[1 + k]) + "'");
      }
      if (v < 0 || v >= num_vertices) {
        return Status::Error(LinePrefix(path, ln) + ": vertex index " + std::to_string(v) +
                             " out of range (" + std::to_string(num_vertices) + " vertices)");
      }
      out->corner_vertices.push_back(static_cast<int>(v));
      out->corner_uvs.push_back(-1);
    }
    out->EndFace();  // Tokens after the indices (face colours) are ignored.
    out->face_lines.push_back(ln);
  }
  return Status::Ok();
}

// ---- PLY ----------------------------------------------------------------------------------------

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

// ---- Building the TriMesh -----------------------------------------------------------------------

Status BuildMesh(const std::string& path, const ParsedMesh& parsed, TriMesh* mesh,
                 MeshReport* report) {
  if (parsed.num_faces() == 0) return Status::Error(path + ": no faces");
  bool all_uvs = true, any_uvs = false;
  for (int uv : parsed.corner_uvs) {
    all_uvs = all_uvs && uv >= 0;
    any_uvs = any_uvs || uv >= 0;
  }
  if (any_uvs && !all_uvs) {
    LOG(WARNING) << path << ": only some faces have texture coordinates; ignoring them all";
  }
  const bool with_uvs = any_uvs && all_uvs;

  *mesh = TriMesh();
  if (with_uvs) mesh->request_halfedge_texcoords2D();
  std::vector<TriMesh::VertexHandle> handles;
  handles.reserve(parsed.positions.size());
  for (const Eigen::Vector3d& p : parsed.positions) {
    handles.push_back(mesh->add_vertex(TriMesh::Point(p.x(), p.y(), p.z())));
  }

  int repeated_vertex_faces = 0, non_manifold_faces = 0;
  std::vector<Eigen::Vector3d> polygon;
  std::vector<std::array<int, 3>> triangles;
  {
    ScopedOpenMeshQuiet quiet;
    for (int f = 0; f < parsed.num_faces(); ++f) {
      const int begin = parsed.face_offsets[f], end = parsed.face_offsets[f + 1];
      // A face that repeats a vertex cannot be represented in a halfedge mesh: count it as
      // degenerate and leave it out (OpenMesh's importer drops it too).
      bool repeated = false;
      for (int a = begin; a < end && !repeated; ++a) {
        for (int b = a + 1; b < end; ++b) {
          if (parsed.corner_vertices[a] == parsed.corner_vertices[b]) {
            repeated = true;
            break;
          }
        }
      }
      if (repeated) {
        ++repeated_vertex_faces;
        continue;
      }
      // Polygons: ear clipping in their plane (a fan when strictly convex); refused when not
      // planar or self-intersecting.
      polygon.clear();
      for (int c = begin; c < end; ++c) {
        polygon.push_back(parsed.positions[parsed.corner_vertices[c]]);
      }
      const Status triangulated = TriangulatePolygon(polygon, &triangles);
      if (!triangulated.ok()) {
        std::string where = path + ": face " + std::to_string(f);
        if (f < static_cast<int>(parsed.face_lines.size())) {
          where += " (line " + std::to_string(parsed.face_lines[f]) + ")";
        }
        return triangulated.Prefixed(where);
      }
      for (const std::array<int, 3>& triangle : triangles) {
        const int corners[3] = {begin + triangle[0], begin + triangle[1], begin + triangle[2]};
        TriMesh::VertexHandle vh[3];
        for (int c = 0; c < 3; ++c) vh[c] = handles[parsed.corner_vertices[corners[c]]];
        TriMesh::FaceHandle fh = mesh->add_face(vh[0], vh[1], vh[2]);
        if (!fh.is_valid()) {
          // Non-manifold: give the face private copies of its vertices.
          ++non_manifold_faces;
          for (int c = 0; c < 3; ++c) vh[c] = mesh->add_vertex(TriMesh::Point(mesh->point(vh[c])));
          fh = mesh->add_face(vh[0], vh[1], vh[2]);
          CHECK(fh.is_valid()) << "adding an isolated triangle cannot fail";
        }
        // Keep the face's vertex order (fv iteration starts at the first corner), since the mesh
        // colors layout depends on it.
        for (TriMesh::HalfedgeHandle h : mesh->fh_range(fh)) {
          if (mesh->to_vertex_handle(h) == vh[0]) {
            mesh->set_halfedge_handle(fh, h);
            break;
          }
        }
        if (with_uvs) {
          // A halfedge's texcoord is the UV of its to-vertex in its face.
          for (TriMesh::HalfedgeHandle h : mesh->fh_range(fh)) {
            const TriMesh::VertexHandle to = mesh->to_vertex_handle(h);
            for (int c = 0; c < 3; ++c) {
              if (to == vh[c]) {
                const Eigen::Vector2d& uv = parsed.uvs[parsed.corner_uvs[corners[c]]];
                mesh->set_texcoord2D(h, TriMesh::TexCoord2D(uv.x(), uv.y()));
              }
            }
          }
        }
      }
    }
  }
  if (with_uvs) {
    // Boundary halfedges belong to no face and got no UV: give them a defined value.
    for (TriMesh::HalfedgeHandle h : mesh->halfedges()) {
      if (mesh->is_boundary(h)) mesh->set_texcoord2D(h, TriMesh::TexCoord2D(0.0, 0.0));
    }
  }
  if (mesh->n_faces() == 0) {
    return Status::Error(path + ": no faces (all " + std::to_string(repeated_vertex_faces) +
                         " faces repeat a vertex)");
  }
  if (non_manifold_faces > 0) {
    LOG(WARNING) << path << ": " << non_manifold_faces
                 << " non-manifold faces were given their own copies of their vertices";
  }

  MeshReport local;
  local.num_vertices = static_cast<int>(mesh->n_vertices());
  local.num_faces = static_cast<int>(mesh->n_faces());
  local.has_texcoords = with_uvs;
  local.num_degenerate_faces = repeated_vertex_faces;
  Eigen::Vector3d lo, hi;
  MeshBounds(*mesh, &lo, &hi);
  const double diagonal2 = (hi - lo).squaredNorm();
  for (TriMesh::FaceHandle fh : mesh->faces()) {
    Eigen::Vector3d p[3];
    int c = 0;
    for (TriMesh::VertexHandle vh : mesh->fv_range(fh)) {
      const TriMesh::Point& q = mesh->point(vh);
      p[c++] = Eigen::Vector3d(q[0], q[1], q[2]);
    }
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (!(area > kDegenerateRelativeArea * diagonal2)) ++local.num_degenerate_faces;
  }
  for (TriMesh::VertexHandle vh : mesh->vertices()) {
    if (mesh->is_isolated(vh)) ++local.num_isolated_vertices;
  }
  if (report != nullptr) *report = local;
  return Status::Ok();
}

// ---- Writing ------------------------------------------------------------------------------------

// Text output through a buffer flushed in 1 MB chunks.
class TextFileWriter {
 public:
  explicit TextFileWriter(const std::string& path) {
    errno = 0;
    file_ = std::fopen(path.c_str(), "wb");
    if (file_ == nullptr) error_ = errno;
  }
  ~TextFileWriter() {
    if (file_ != nullptr) std::fclose(file_);
  }
  bool is_open() const { return file_ != nullptr; }
  std::string& buffer() { return buffer_; }
  void MaybeFlush() {
    if (buffer_.size() > (1 << 20)) Flush();
  }
  // Flushes and closes; false on any write error.
  bool Close() {
    Flush();
    const bool ok = std::ferror(file_) == 0;
    errno = 0;
    const bool closed = std::fclose(file_) == 0;
    if (!closed && error_ == 0) error_ = errno;
    file_ = nullptr;
    return ok && closed;
  }
  // The reason of the first failure (strerror of the errno captured right after the failing call).
  std::string error() const { return ErrnoText(error_); }

 private:
  void Flush() {
    if (!buffer_.empty()) {
      errno = 0;
      if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size() && error_ == 0) {
        error_ = errno;
      }
    }
    buffer_.clear();
  }
  std::FILE* file_ = nullptr;
  std::string buffer_;
  int error_ = 0;  // errno of the first failed call, 0 if none (or none given).
};

// 1-based (OBJ) or 0-based (OFF) indices of the mesh's non-deleted vertices, in order.
std::vector<int> CompactVertexIndices(const TriMesh& mesh, int first, int* count) {
  std::vector<int> compact(mesh.n_vertices(), -1);
  int next = first;
  for (TriMesh::VertexHandle vh : mesh.vertices()) compact[vh.idx()] = next++;
  *count = next - first;
  return compact;
}

Status WriteObj(const std::string& path, const TriMesh& mesh) {
  return WriteAtomically(path, [&](const std::string& tmp) -> Status {
    TextFileWriter out(tmp);
    if (!out.is_open()) {
      return Status::Error(path + ": cannot open for writing (" + out.error() + ")");
    }
    std::string& text = out.buffer();
    int num_vertices = 0;
    const std::vector<int> compact = CompactVertexIndices(mesh, 1, &num_vertices);
    text += "# sft mesh\n";
    for (TriMesh::VertexHandle vh : mesh.vertices()) {
      const TriMesh::Point& p = mesh.point(vh);
      text += 'v';
      for (int c = 0; c < 3; ++c) {
        text += ' ';
        AppendDouble(p[c], &text);
      }
      text += '\n';
      out.MaybeFlush();
    }
    // Corner UVs: one vt per distinct value (exact match), in order of first use. FaceCornerUvs
    // lists all faces by index, deleted ones included; they are skipped below like the faces.
    const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
    std::vector<int> corner_uv_index;
    if (!uvs.empty()) {
      struct KeyHash {
        size_t operator()(const std::pair<uint64_t, uint64_t>& k) const {
          return std::hash<uint64_t>()(k.first * 0x9E3779B97F4A7C15ull ^ k.second);
        }
      };
      std::unordered_map<std::pair<uint64_t, uint64_t>, int, KeyHash> index;
      corner_uv_index.reserve(uvs.size());
      for (const Eigen::Vector2d& uv : uvs) {
        std::pair<uint64_t, uint64_t> key;
        std::memcpy(&key.first, &uv.x(), 8);
        std::memcpy(&key.second, &uv.y(), 8);
        auto it = index.find(key);
        if (it == index.end()) {
          it = index.emplace(key, static_cast<int>(index.size()) + 1).first;
          text += "vt ";
          AppendDouble(uv.x(), &text);
          text += ' ';
          AppendDouble(uv.y(), &text);
          text += '\n';
          out.MaybeFlush();
        }
        corner_uv_index.push_back(it->second);
      }
    }
    for (TriMesh::FaceHandle fh : mesh.faces()) {
      text += 'f';
      int corner = 3 * fh.idx();
      for (TriMesh::HalfedgeHandle h : mesh.fh_range(fh)) {
        text += ' ';
        text += std::to_string(compact[mesh.to_vertex_handle(h).idx()]);
        if (!corner_uv_index.empty()) {
          text += '/';
          text += std::to_string(corner_uv_index[corner++]);
        }
      }
      text += '\n';
      out.MaybeFlush();
    }
    if (!out.Close()) return Status::Error(path + ": write failed (" + out.error() + ")");
    return Status::Ok();
  });
}

// OFF by hand as well: OpenMesh's OFF writer rounds coordinates to float.
Status WriteOff(const std::string& path, const TriMesh& mesh) {
  return WriteAtomically(path, [&](const std::string& tmp) -> Status {
    TextFileWriter out(tmp);
    if (!out.is_open()) {
      return Status::Error(path + ": cannot open for writing (" + out.error() + ")");
    }
    std::string& text = out.buffer();
    int num_vertices = 0;
    const std::vector<int> compact = CompactVertexIndices(mesh, 0, &num_vertices);
    size_t num_faces = 0;
    for (TriMesh::FaceHandle fh : mesh.faces()) num_faces += fh.is_valid() ? 1 : 0;
    text += "OFF\n" + std::to_string(num_vertices) + " " + std::to_string(num_faces) + " 0\n";
    for (TriMesh::VertexHandle vh : mesh.vertices()) {
      const TriMesh::Point& p = mesh.point(vh);
      for (int c = 0; c < 3; ++c) {
        if (c > 0) text += ' ';
        AppendDouble(p[c], &text);
      }
      text += '\n';
      out.MaybeFlush();
    }
    for (TriMesh::FaceHandle fh : mesh.faces()) {
      text += '3';
      for (TriMesh::HalfedgeHandle h : mesh.fh_range(fh)) {
        text += ' ';
        text += std::to_string(compact[mesh.to_vertex_handle(h).idx()]);
      }
      text += '\n';
      out.MaybeFlush();
    }
    if (!out.Close()) return Status::Error(path + ": write failed (" + out.error() + ")");
    return Status::Ok();
  });
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

}  // namespace

Status ReadMesh(const std::string& path, TriMesh* mesh, MeshReport* report) {
  const std::string ext = FileExtension(path);
  if (ext != "obj" && ext != "ply" && ext != "off") {
    return Status::Error(path + ": unknown mesh extension '" + ext + "' (expected obj, ply, off)");
  }
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
  return ParseMesh(text, path, mesh, report);
}

Status ParseMesh(std::string text, const std::string& path, TriMesh* mesh, MeshReport* report) {
  const std::string ext = FileExtension(path);
  if (ext != "obj" && ext != "ply" && ext != "off") {
    return Status::Error(path + ": unknown mesh extension '" + ext + "' (expected obj, ply, off)");
  }
  StripUtf8Bom(&text);
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) {
    return Status::Error(path + ": empty file (no faces)");
  }
  ParsedMesh parsed;
  if (ext == "obj") {
    SFT_RETURN_IF_ERROR(ParseObj(path, text, &parsed));
  } else if (ext == "off") {
    SFT_RETURN_IF_ERROR(ParseOff(path, text, &parsed));
  } else {
    SFT_RETURN_IF_ERROR(ParsePly(path, text, &parsed));
  }
  TriMesh result;
  SFT_RETURN_IF_ERROR(BuildMesh(path, parsed, &result, report));
  *mesh = std::move(result);
  return Status::Ok();
}

Status WriteMesh(const std::string& path, const TriMesh& mesh) {
  const std::string ext = FileExtension(path);
  if (ext == "obj") return WriteObj(path, mesh);
  if (ext == "ply") return WritePly(path, mesh);
  if (ext == "off") return WriteOff(path, mesh);
  return Status::Error(path + ": unknown mesh extension '" + ext + "' (expected obj, ply, off)");
}

void MeshToArrays(const TriMesh& mesh, std::vector<Eigen::Vector3d>* positions,
                  std::vector<Eigen::Vector3i>* faces) {
  if (positions != nullptr) {
    positions->resize(mesh.n_vertices());
    for (size_t i = 0; i < mesh.n_vertices(); ++i) {
      const TriMesh::Point& p = mesh.point(TriMesh::VertexHandle(static_cast<int>(i)));
      (*positions)[i] = Eigen::Vector3d(p[0], p[1], p[2]);
    }
  }
  if (faces != nullptr) {
    faces->resize(mesh.n_faces());
    for (size_t f = 0; f < mesh.n_faces(); ++f) {
      const TriMesh::FaceHandle fh(static_cast<int>(f));
      int c = 0;
      Eigen::Vector3i face(-1, -1, -1);
      for (TriMesh::HalfedgeHandle h : mesh.fh_range(fh)) {
        if (c < 3) face[c] = mesh.to_vertex_handle(h).idx();
        ++c;
      }
      (*faces)[f] = face;
    }
  }
}

std::vector<Eigen::Vector2d> FaceCornerUvs(const TriMesh& mesh) {
  std::vector<Eigen::Vector2d> uvs;
  if (!mesh.has_halfedge_texcoords2D()) return uvs;
  uvs.reserve(3 * mesh.n_faces());
  for (size_t f = 0; f < mesh.n_faces(); ++f) {
    const TriMesh::FaceHandle fh(static_cast<int>(f));
    int c = 0;
    for (TriMesh::HalfedgeHandle h : mesh.fh_range(fh)) {
      if (c++ >= 3) break;
      const TriMesh::TexCoord2D& t = mesh.texcoord2D(h);
      uvs.emplace_back(t[0], t[1]);
    }
  }
  return uvs;
}

void MeshBounds(const TriMesh& mesh, Eigen::Vector3d* lo, Eigen::Vector3d* hi) {
  Eigen::Vector3d l = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d h = -l;
  bool any = false;
  for (TriMesh::VertexHandle vh : mesh.vertices()) {
    if (mesh.is_isolated(vh)) continue;
    const TriMesh::Point& p = mesh.point(vh);
    const Eigen::Vector3d q(p[0], p[1], p[2]);
    l = l.cwiseMin(q);
    h = h.cwiseMax(q);
    any = true;
  }
  if (!any) l = h = Eigen::Vector3d::Zero();
  if (lo != nullptr) *lo = l;
  if (hi != nullptr) *hi = h;
}

}  // namespace sft
