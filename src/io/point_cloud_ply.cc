#include "src/io/point_cloud_ply.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "src/core/file_util.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the PLY reader assumes a little-endian host");

namespace sft {
namespace {

enum class Type { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool TypeFromName(const std::string& name, Type* type, int* size) {
  struct Entry {
    const char* a;
    const char* b;
    Type type;
    int size;
  };
  static const Entry kTypes[] = {
      {"char", "int8", Type::kInt8, 1},        {"uchar", "uint8", Type::kUint8, 1},
      {"short", "int16", Type::kInt16, 2},     {"ushort", "uint16", Type::kUint16, 2},
      {"int", "int32", Type::kInt32, 4},       {"uint", "uint32", Type::kUint32, 4},
      {"float", "float32", Type::kFloat32, 4}, {"double", "float64", Type::kFloat64, 8}};
  for (const Entry& e : kTypes) {
    if (name == e.a || name == e.b) {
      *type = e.type;
      *size = e.size;
      return true;
    }
  }
  return false;
}

double Decode(const char* p, Type type) {
  switch (type) {
    case Type::kInt8:
      return static_cast<int8_t>(*p);
    case Type::kUint8:
      return static_cast<uint8_t>(*p);
    case Type::kInt16: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case Type::kUint16: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case Type::kInt32: {
      int32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case Type::kUint32: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case Type::kFloat32: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case Type::kFloat64: {
      double v;
      std::memcpy(&v, p, 8);
      return v;
    }
  }
  return 0;
}

struct Property {
  std::string name;
  Type type = Type::kFloat32;
  int size = 4;
  int offset = 0;  // in a binary row.
};

// Column of property `name`, or -1.
int Column(const std::vector<Property>& props, const char* name) {
  for (size_t i = 0; i < props.size(); ++i) {
    if (props[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// Splits a buffer into lines (LF or CRLF), counting them.
class Lines {
 public:
  explicit Lines(const std::string& data) : data_(data) {}
  bool Next(std::string* line) {
    if (pos_ >= data_.size()) return false;
    size_t end = data_.find('\n', pos_);
    if (end == std::string::npos) end = data_.size();
    *line = data_.substr(pos_, end - pos_);
    if (!line->empty() && line->back() == '\r') line->pop_back();
    pos_ = end + 1;
    ++number_;
    return true;
  }
  size_t position() const { return std::min(pos_, data_.size()); }
  int number() const { return number_; }

 private:
  const std::string& data_;
  size_t pos_ = 0;
  int number_ = 0;
};

struct Header {
  bool binary = false;
  uint64_t count = 0;           // vertices.
  std::vector<Property> props;  // of the vertex element.
};

// Parses the header after the "ply" line, up to and including end_header.
Status ParseHeader(Lines* lines, const std::string& file, Header* header) {
  auto fail = [&](const std::string& m) { return Status::Error(file + ": " + m); };
  bool have_format = false, in_vertex = false, vertex_seen = false;
  bool& binary = header->binary;
  uint64_t& count = header->count;
  std::vector<Property>& props = header->props;
  std::string line;
  for (;;) {
    if (!lines->Next(&line)) return fail("header ends without end_header");
    std::istringstream in(line);
    std::string word;
    in >> word;
    const std::string where = "header line " + std::to_string(lines->number()) + ": ";
    if (word == "end_header") break;
    if (word == "comment" || word == "obj_info" || word.empty()) continue;
    if (word == "format") {
      std::string format;
      in >> format;
      if (format == "ascii") {
        binary = false;
      } else if (format == "binary_little_endian") {
        binary = true;
      } else {
        return fail(where + "unsupported format \"" + format.substr(0, 32) + "\"");
      }
      have_format = true;
    } else if (word == "element") {
      std::string name, count_text;
      in >> name >> count_text;
      in_vertex = name == "vertex";
      if (in_vertex) {
        char* end = nullptr;
        const unsigned long long n = std::strtoull(count_text.c_str(), &end, 10);
        if (count_text.empty() || *end != '\0' || count_text[0] == '-') {
          return fail(where + "invalid vertex count \"" + count_text.substr(0, 32) + "\"");
        }
        count = n;
        vertex_seen = true;
      } else if (!vertex_seen) {
        return fail(where + "element \"" + name.substr(0, 32) + "\" before \"vertex\"");
      }
    } else if (word == "property") {
      std::string type_name, name;
      in >> type_name >> name;
      if (!in_vertex) continue;  // properties of later elements are not read.
      if (type_name == "list") return fail(where + "list property in the vertex element");
      Property p;
      p.name = name;
      if (!TypeFromName(type_name, &p.type, &p.size)) {
        return fail(where + "unknown property type \"" + type_name.substr(0, 32) + "\"");
      }
      p.offset = props.empty() ? 0 : props.back().offset + props.back().size;
      props.push_back(p);
    } else {
      return fail(where + "unexpected \"" + word.substr(0, 32) + "\"");
    }
  }
  if (!have_format) return fail("header has no format line");
  if (!vertex_seen) return fail("no vertex element");
  return Status::Ok();
}

}  // namespace

Status ParsePointCloudPly(const std::string& data, const std::string& file, PointCloud* cloud) {
  *cloud = PointCloud();
  auto fail = [&](const std::string& m) { return Status::Error(file + ": " + m); };
  Lines lines(data);
  std::string line;
  if (!lines.Next(&line) || line != "ply") return fail("not a PLY file (no \"ply\" first line)");
  Header header;
  SFT_RETURN_IF_ERROR(ParseHeader(&lines, file, &header));
  const bool binary = header.binary;
  const uint64_t count = header.count;
  const std::vector<Property>& props = header.props;
  const size_t pos = lines.position();
  const int x = Column(props, "x"), y = Column(props, "y"), z = Column(props, "z");
  if (x < 0 || y < 0 || z < 0) return fail("vertex element lacks x, y or z");
  const int nx = Column(props, "nx"), ny = Column(props, "ny"), nz = Column(props, "nz");
  const int r = Column(props, "red"), g = Column(props, "green"), b = Column(props, "blue");
  const bool has_normals = nx >= 0 && ny >= 0 && nz >= 0;
  const bool has_colors = r >= 0 && g >= 0 && b >= 0;
  const size_t remaining = data.size() - pos;
  const size_t row = props.back().offset + props.back().size;
  // Each vertex takes `row` bytes in binary and at least 2 characters per value in ascii.
  const size_t min_bytes = binary ? row : 2 * props.size();
  if (count > remaining / min_bytes) {
    return fail(std::to_string(count) + " vertices announced but only " +
                std::to_string(remaining) + " bytes follow the header");
  }
  cloud->positions.resize(count);
  if (has_normals) cloud->normals.resize(count);
  if (has_colors) cloud->colors.resize(count);
  std::vector<double> values(props.size());
  for (uint64_t i = 0; i < count; ++i) {
    if (binary) {
      const char* p = data.data() + pos + i * row;
      for (size_t k = 0; k < props.size(); ++k)
        values[k] = Decode(p + props[k].offset, props[k].type);
    } else {
      if (!lines.Next(&line)) return fail("vertex " + std::to_string(i) + ": file ends early");
      std::istringstream in(line);
      for (size_t k = 0; k < props.size(); ++k) {
        std::string token;
        in >> token;
        char* end = nullptr;
        values[k] = std::strtod(token.c_str(), &end);
        if (token.empty() || *end != '\0') {
          return fail("line " + std::to_string(lines.number()) + ": expected " +
                      std::to_string(props.size()) + " numbers");
        }
      }
    }
    cloud->positions[i] = Eigen::Vector3d(values[x], values[y], values[z]);
    if (!cloud->positions[i].allFinite()) {
      return fail("vertex " + std::to_string(i) + ": non-finite coordinate");
    }
    if (has_normals) cloud->normals[i] = Eigen::Vector3d(values[nx], values[ny], values[nz]);
    if (has_colors) {
      for (int c = 0; c < 3; ++c) {
        const double v = values[c == 0 ? r : c == 1 ? g : b];
        cloud->colors[i][c] =
            static_cast<uint8_t>(std::isfinite(v) ? std::clamp(v, 0.0, 255.0) : 0);
      }
    }
  }
  return Status::Ok();
}

Status ReadPointCloudPly(const std::string& path, PointCloud* cloud) {
  std::string data;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &data));
  return ParsePointCloudPly(data, path, cloud);
}

Status WritePointCloudPly(const std::string& path, const PointCloud& cloud) {
  const size_t n = cloud.positions.size();
  const bool has_normals = !cloud.normals.empty(), has_colors = !cloud.colors.empty();
  if ((has_normals && cloud.normals.size() != n) || (has_colors && cloud.colors.size() != n)) {
    return Status::Error(path + ": normals or colours do not match the positions");
  }
  std::string out = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(n) +
                    "\nproperty double x\nproperty double y\nproperty double z\n";
  if (has_normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (has_colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "end_header\n";
  auto append = [&out](const void* p, size_t size) {
    out.append(static_cast<const char*>(p), size);
  };
  for (size_t i = 0; i < n; ++i) {
    append(cloud.positions[i].data(), 24);
    if (has_normals) {
      const Eigen::Vector3f normal = cloud.normals[i].cast<float>();
      append(normal.data(), 12);
    }
    if (has_colors) append(cloud.colors[i].data(), 3);
  }
  return WriteAtomically(path, [&out](const std::string& tmp) {
    std::ofstream file(tmp, std::ios::binary);
    file.write(out.data(), static_cast<std::streamsize>(out.size()));
    file.close();
    if (!file) return Status::Error(tmp + ": cannot write");
    return Status::Ok();
  });
}

}  // namespace sft
