#include "src/io/colmap_model.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "src/core/file_util.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the COLMAP binary reader assumes a little-endian host");

namespace sft {
namespace {

struct ModelInfo {
  int id;
  const char* name;
  int num_params;
};
// COLMAP 3.8's camera models (src/base/camera_models.h): id, name, parameter count.
constexpr ModelInfo kModels[] = {
    {0, "SIMPLE_PINHOLE", 3},
    {1, "PINHOLE", 4},
    {2, "SIMPLE_RADIAL", 4},
    {3, "RADIAL", 5},
    {4, "OPENCV", 8},
    {5, "OPENCV_FISHEYE", 8},
    {6, "FULL_OPENCV", 12},
    {7, "FOV", 5},
    {8, "SIMPLE_RADIAL_FISHEYE", 4},
    {9, "RADIAL_FISHEYE", 5},
    {10, "THIN_PRISM_FISHEYE", 12},
};

constexpr uint64_t kInvalidPoint3DId = std::numeric_limits<uint64_t>::max();

// ---- text ----

// Splits `data` into lines (LF or CRLF) and whitespace-separated tokens, tracking line numbers.
class TextLines {
 public:
  explicit TextLines(const std::string& data) : data_(data) {}
  // The next line's tokens (possibly none); false at the end of the data.
  bool Next(std::vector<std::string>* tokens, std::string* raw = nullptr) {
    if (pos_ >= data_.size()) return false;
    size_t end = data_.find('\n', pos_);
    if (end == std::string::npos) end = data_.size();
    std::string line = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    tokens->clear();
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      size_t j = i;
      while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
      if (j > i) tokens->push_back(line.substr(i, j - i));
      i = j;
    }
    if (raw != nullptr) *raw = line;
    return true;
  }
  // The next record line: skips blank lines and '#' comments.
  bool NextRecord(std::vector<std::string>* tokens, std::string* raw = nullptr) {
    while (Next(tokens, raw)) {
      if (!tokens->empty() && (*tokens)[0][0] != '#') return true;
    }
    return false;
  }
  int line_number() const { return line_number_; }

 private:
  const std::string& data_;
  size_t pos_ = 0;
  int line_number_ = 0;
};

// The text of `line` after its first `fields` whitespace-separated fields, trimmed.
std::string RestOfLine(const std::string& line, int fields) {
  auto space = [&](size_t i) { return std::isspace(static_cast<unsigned char>(line[i])) != 0; };
  size_t i = 0;
  for (int f = 0; f <= fields; ++f) {
    while (i < line.size() && space(i)) ++i;
    if (f == fields) break;
    while (i < line.size() && !space(i)) ++i;
  }
  size_t end = line.size();
  while (end > i && space(end - 1)) --end;
  return line.substr(i, end - i);
}

std::string Shorten(const std::string& token) {
  return token.size() > 32 ? token.substr(0, 29) + "..." : token;
}

bool ParseDouble(const std::string& token, double* value) {
  errno = 0;
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  return end == token.c_str() + token.size() && !token.empty() && std::isfinite(*value);
}

bool ParseInt(const std::string& token, int64_t lo, int64_t hi, int64_t* value) {
  if (token.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(token.c_str(), &end, 10);
  if (errno != 0 || end != token.c_str() + token.size() || v < lo || v > hi) return false;
  *value = v;
  return true;
}

class LineError {
 public:
  LineError(const std::string& file, const TextLines& lines) : file_(file), lines_(lines) {}
  Status operator()(const std::string& message) const {
    return Status::Error(file_ + ": line " + std::to_string(lines_.line_number()) + ": " + message);
  }
  Status Number(const char* what, const std::string& token) const {
    return (*this)(std::string("expected ") + what + ", got \"" + Shorten(token) + "\"");
  }

 private:
  const std::string& file_;
  const TextLines& lines_;
};

constexpr int64_t kMaxU32 = std::numeric_limits<uint32_t>::max();
constexpr int64_t kMaxI64 = std::numeric_limits<int64_t>::max();

Status ParseCameraParams(const std::vector<std::string>& t, size_t first, const LineError& err,
                         std::vector<double>* params) {
  for (size_t i = first; i < t.size(); ++i) {
    double v;
    if (!ParseDouble(t[i], &v)) return err.Number("a finite camera parameter", t[i]);
    params->push_back(v);
  }
  return Status::Ok();
}

Status CheckQuaternion(const double q[4], Eigen::Quaterniond* rotation, std::string* why) {
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(norm > 1e-12) || !std::isfinite(norm)) {
    *why = "rotation quaternion has zero or non-finite length";
    return Status::Error(*why);
  }
  *rotation = Eigen::Quaterniond(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
  return Status::Ok();
}

// ---- binary ----

class Reader {
 public:
  explicit Reader(const std::string& data) : data_(data) {}
  template <typename T>
  bool Read(T* value) {
    if (data_.size() - pos_ < sizeof(T)) return false;
    std::memcpy(value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  bool ReadDoubles(double* values, int n) {
    for (int i = 0; i < n; ++i) {
      if (!Read(&values[i])) return false;
    }
    return true;
  }
  // A NUL-terminated string; false when no NUL follows.
  bool ReadCString(std::string* s) {
    const size_t end = data_.find('\0', pos_);
    if (end == std::string::npos) return false;
    *s = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return true;
  }
  size_t remaining() const { return data_.size() - pos_; }
  size_t position() const { return pos_; }
  bool at_end() const { return pos_ == data_.size(); }

 private:
  const std::string& data_;
  size_t pos_ = 0;
};

Status Truncated(const std::string& file, const std::string& what, const Reader& reader) {
  return Status::Error(file + ": truncated or corrupt at byte " +
                       std::to_string(reader.position()) + " (" + what + ")");
}

// Reads a record count and checks that `min_record_bytes` per record fit in the rest of the file.
Status ReadCount(Reader* reader, const std::string& file, const char* what, size_t min_record_bytes,
                 uint64_t* count) {
  if (!reader->Read(count)) return Truncated(file, std::string("number of ") + what, *reader);
  if (*count > reader->remaining() / min_record_bytes) {
    return Status::Error(file + ": " + std::to_string(*count) + " " + what + " announced at byte " +
                         std::to_string(reader->position() - 8) + " but only " +
                         std::to_string(reader->remaining()) + " bytes follow");
  }
  return Status::Ok();
}

bool AllFinite(const double* values, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

}  // namespace

bool ColmapModelFromId(int model_id, std::string* name, int* num_params) {
  for (const ModelInfo& m : kModels) {
    if (m.id == model_id) {
      *name = m.name;
      *num_params = m.num_params;
      return true;
    }
  }
  return false;
}

bool ColmapModelNumParams(const std::string& name, int* num_params) {
  for (const ModelInfo& m : kModels) {
    if (name == m.name) {
      *num_params = m.num_params;
      return true;
    }
  }
  return false;
}

Status ParseColmapCamerasText(const std::string& data, const std::string& file,
                              std::vector<ColmapCamera>* out) {
  out->clear();
  TextLines lines(data);
  LineError err(file, lines);
  std::vector<std::string> t;
  std::unordered_set<uint32_t> ids;
  while (lines.NextRecord(&t)) {
    if (t.size() < 4) {
      return err("expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS..., got " +
                 std::to_string(t.size()) + " fields");
    }
    ColmapCamera camera;
    int64_t v;
    if (!ParseInt(t[0], 0, kMaxU32 - 1, &v)) return err.Number("a camera id", t[0]);
    camera.id = static_cast<uint32_t>(v);
    camera.model = t[1];
    int num_params = 0;
    if (!ColmapModelNumParams(camera.model, &num_params)) {
      return err("camera " + t[0] + ": unknown camera model \"" + Shorten(camera.model) + "\"");
    }
    if (!ParseInt(t[2], 1, kMaxI64, &v)) return err.Number("a positive width", t[2]);
    camera.width = static_cast<uint64_t>(v);
    if (!ParseInt(t[3], 1, kMaxI64, &v)) return err.Number("a positive height", t[3]);
    camera.height = static_cast<uint64_t>(v);
    SFT_RETURN_IF_ERROR(ParseCameraParams(t, 4, err, &camera.params));
    if (static_cast<int>(camera.params.size()) != num_params) {
      return err("camera " + t[0] + ": " + camera.model + " needs " + std::to_string(num_params) +
                 " parameters, got " + std::to_string(camera.params.size()));
    }
    if (!ids.insert(camera.id).second) return err("duplicate camera id " + t[0]);
    out->push_back(std::move(camera));
  }
  return Status::Ok();
}

Status ParseColmapImagesText(const std::string& data, const std::string& file,
                             std::vector<ColmapImage>* out) {
  out->clear();
  TextLines lines(data);
  LineError err(file, lines);
  std::vector<std::string> t;
  std::string raw;
  std::unordered_set<uint32_t> ids;
  while (lines.NextRecord(&t, &raw)) {
    if (t.size() < 10) {
      return err("expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, got " +
                 std::to_string(t.size()) + " fields");
    }
    ColmapImage image;
    int64_t v;
    if (!ParseInt(t[0], 0, kMaxU32 - 1, &v)) return err.Number("an image id", t[0]);
    image.id = static_cast<uint32_t>(v);
    double q[4];
    for (int i = 0; i < 4; ++i) {
      if (!ParseDouble(t[1 + i], &q[i])) return err.Number("a finite quaternion entry", t[1 + i]);
    }
    std::string why;
    if (!CheckQuaternion(q, &image.cam_from_world_rotation, &why).ok()) {
      return err("image " + t[0] + ": " + why);
    }
    for (int i = 0; i < 3; ++i) {
      if (!ParseDouble(t[5 + i], &image.cam_from_world_translation[i])) {
        return err.Number("a finite translation entry", t[5 + i]);
      }
    }
    if (!ParseInt(t[8], 0, kMaxU32 - 1, &v)) return err.Number("a camera id", t[8]);
    image.camera_id = static_cast<uint32_t>(v);
    // The name is the rest of the line after CAMERA_ID (so names with spaces survive).
    image.name = RestOfLine(raw, 9);
    if (!ids.insert(image.id).second) return err("duplicate image id " + t[0]);
    // The 2D points line follows directly (it may be empty; a file may end without it).
    if (lines.Next(&t)) {
      if (t.size() % 3 != 0) {
        return err("image " + std::to_string(image.id) + ": expected X Y POINT3D_ID triples, got " +
                   std::to_string(t.size()) + " fields");
      }
      image.points2d.reserve(t.size() / 3);
      image.point3d_ids.reserve(t.size() / 3);
      for (size_t i = 0; i < t.size(); i += 3) {
        Eigen::Vector2d xy;
        if (!ParseDouble(t[i], &xy.x())) return err.Number("a finite x", t[i]);
        if (!ParseDouble(t[i + 1], &xy.y())) return err.Number("a finite y", t[i + 1]);
        if (!ParseInt(t[i + 2], -1, kMaxI64, &v)) return err.Number("a POINT3D_ID", t[i + 2]);
        image.points2d.push_back(xy);
        image.point3d_ids.push_back(v);
      }
    }
    out->push_back(std::move(image));
  }
  return Status::Ok();
}

Status ParseColmapPointsText(const std::string& data, const std::string& file,
                             std::vector<ColmapPoint3D>* out) {
  out->clear();
  TextLines lines(data);
  LineError err(file, lines);
  std::vector<std::string> t;
  std::unordered_set<uint64_t> ids;
  while (lines.NextRecord(&t)) {
    if (t.size() < 8 || (t.size() - 8) % 2 != 0) {
      return err("expected POINT3D_ID X Y Z R G B ERROR (IMAGE_ID POINT2D_IDX)..., got " +
                 std::to_string(t.size()) + " fields");
    }
    ColmapPoint3D point;
    int64_t v;
    if (!ParseInt(t[0], 0, kMaxI64, &v)) return err.Number("a point id", t[0]);
    point.id = static_cast<uint64_t>(v);
    for (int i = 0; i < 3; ++i) {
      if (!ParseDouble(t[1 + i], &point.xyz[i])) return err.Number("a finite coordinate", t[1 + i]);
    }
    for (int i = 0; i < 3; ++i) {
      if (!ParseInt(t[4 + i], 0, 255, &v)) return err.Number("a colour in [0, 255]", t[4 + i]);
      point.rgb[i] = static_cast<uint8_t>(v);
    }
    if (!ParseDouble(t[7], &point.error)) return err.Number("a finite error", t[7]);
    point.track.reserve((t.size() - 8) / 2);
    for (size_t i = 8; i < t.size(); i += 2) {
      ColmapTrackElement e;
      if (!ParseInt(t[i], 0, kMaxU32 - 1, &v)) return err.Number("an image id", t[i]);
      e.image_id = static_cast<uint32_t>(v);
      if (!ParseInt(t[i + 1], 0, kMaxU32, &v)) return err.Number("a point index", t[i + 1]);
      e.point2d_index = static_cast<uint32_t>(v);
      point.track.push_back(e);
    }
    if (!ids.insert(point.id).second) return err("duplicate point id " + t[0]);
    out->push_back(std::move(point));
  }
  return Status::Ok();
}

Status ParseColmapCamerasBinary(const std::string& data, const std::string& file,
                                std::vector<ColmapCamera>* out) {
  out->clear();
  Reader reader(data);
  uint64_t count;
  SFT_RETURN_IF_ERROR(ReadCount(&reader, file, "cameras", 24, &count));
  std::unordered_set<uint32_t> ids;
  out->reserve(count);
  for (uint64_t c = 0; c < count; ++c) {
    const std::string where = "camera " + std::to_string(c) + " of " + std::to_string(count);
    ColmapCamera camera;
    int32_t model_id;
    if (!reader.Read(&camera.id) || !reader.Read(&model_id) || !reader.Read(&camera.width) ||
        !reader.Read(&camera.height)) {
      return Truncated(file, where, reader);
    }
    const std::string name = file + ": camera " + std::to_string(camera.id);
    int num_params = 0;
    if (!ColmapModelFromId(model_id, &camera.model, &num_params)) {
      return Status::Error(name + ": unknown camera model id " + std::to_string(model_id));
    }
    if (camera.width == 0 || camera.height == 0 || camera.width > uint64_t{kMaxI64} ||
        camera.height > uint64_t{kMaxI64}) {
      return Status::Error(name + ": invalid size " + std::to_string(camera.width) + "x" +
                           std::to_string(camera.height));
    }
    camera.params.resize(num_params);
    if (!reader.ReadDoubles(camera.params.data(), num_params)) {
      return Truncated(file, where + " parameters", reader);
    }
    if (!AllFinite(camera.params.data(), num_params)) {
      return Status::Error(name + ": non-finite parameter");
    }
    if (!ids.insert(camera.id).second) return Status::Error(name + ": duplicate camera id");
    out->push_back(std::move(camera));
  }
  if (!reader.at_end()) {
    return Status::Error(file + ": " + std::to_string(reader.remaining()) +
                         " unexpected bytes after the last camera");
  }
  return Status::Ok();
}

Status ParseColmapImagesBinary(const std::string& data, const std::string& file,
                               std::vector<ColmapImage>* out) {
  out->clear();
  Reader reader(data);
  uint64_t count;
  // id, qvec, tvec, camera_id, NUL, num_points2D.
  SFT_RETURN_IF_ERROR(ReadCount(&reader, file, "images", 4 + 56 + 4 + 1 + 8, &count));
  std::unordered_set<uint32_t> ids;
  out->reserve(count);
  for (uint64_t k = 0; k < count; ++k) {
    const std::string where = "image " + std::to_string(k) + " of " + std::to_string(count);
    ColmapImage image;
    double q[4], t[3];
    if (!reader.Read(&image.id) || !reader.ReadDoubles(q, 4) || !reader.ReadDoubles(t, 3) ||
        !reader.Read(&image.camera_id) || !reader.ReadCString(&image.name)) {
      return Truncated(file, where, reader);
    }
    const std::string name = file + ": image " + std::to_string(image.id);
    std::string why;
    if (!AllFinite(q, 4) || !CheckQuaternion(q, &image.cam_from_world_rotation, &why).ok()) {
      return Status::Error(name + ": rotation quaternion has zero or non-finite length");
    }
    if (!AllFinite(t, 3)) return Status::Error(name + ": non-finite translation");
    image.cam_from_world_translation = Eigen::Vector3d(t[0], t[1], t[2]);
    uint64_t num_points;
    SFT_RETURN_IF_ERROR(ReadCount(&reader, file, "2D points", 24, &num_points));
    image.points2d.resize(num_points);
    image.point3d_ids.resize(num_points);
    for (uint64_t i = 0; i < num_points; ++i) {
      uint64_t id;
      if (!reader.ReadDoubles(image.points2d[i].data(), 2) || !reader.Read(&id)) {
        return Truncated(file, where + " 2D points", reader);
      }
      if (!AllFinite(image.points2d[i].data(), 2)) {
        return Status::Error(name + ": non-finite 2D point " + std::to_string(i));
      }
      if (id != kInvalidPoint3DId && id > uint64_t{kMaxI64}) {
        return Status::Error(name + ": 2D point " + std::to_string(i) + ": invalid point3D id");
      }
      image.point3d_ids[i] = id == kInvalidPoint3DId ? -1 : static_cast<int64_t>(id);
    }
    if (!ids.insert(image.id).second) return Status::Error(name + ": duplicate image id");
    out->push_back(std::move(image));
  }
  if (!reader.at_end()) {
    return Status::Error(file + ": " + std::to_string(reader.remaining()) +
                         " unexpected bytes after the last image");
  }
  return Status::Ok();
}

Status ParseColmapPointsBinary(const std::string& data, const std::string& file,
                               std::vector<ColmapPoint3D>* out) {
  out->clear();
  Reader reader(data);
  uint64_t count;
  // id, xyz, rgb, error, track_length.
  SFT_RETURN_IF_ERROR(ReadCount(&reader, file, "points", 8 + 24 + 3 + 8 + 8, &count));
  std::unordered_set<uint64_t> ids;
  out->reserve(count);
  for (uint64_t k = 0; k < count; ++k) {
    const std::string where = "point " + std::to_string(k) + " of " + std::to_string(count);
    ColmapPoint3D point;
    if (!reader.Read(&point.id) || !reader.ReadDoubles(point.xyz.data(), 3) ||
        !reader.Read(&point.rgb[0]) || !reader.Read(&point.rgb[1]) || !reader.Read(&point.rgb[2]) ||
        !reader.Read(&point.error)) {
      return Truncated(file, where, reader);
    }
    const std::string name = file + ": point " + std::to_string(point.id);
    if (!AllFinite(point.xyz.data(), 3) || !std::isfinite(point.error)) {
      return Status::Error(name + ": non-finite coordinate or error");
    }
    uint64_t length;
    SFT_RETURN_IF_ERROR(ReadCount(&reader, file, "track elements", 8, &length));
    point.track.resize(length);
    for (uint64_t i = 0; i < length; ++i) {
      if (!reader.Read(&point.track[i].image_id) || !reader.Read(&point.track[i].point2d_index)) {
        return Truncated(file, where + " track", reader);
      }
    }
    if (!ids.insert(point.id).second) return Status::Error(name + ": duplicate point id");
    out->push_back(std::move(point));
  }
  if (!reader.at_end()) {
    return Status::Error(file + ": " + std::to_string(reader.remaining()) +
                         " unexpected bytes after the last point");
  }
  return Status::Ok();
}

Status CheckColmapModel(const ColmapModel& model, const std::string& dir) {
  std::unordered_set<uint32_t> camera_ids;
  for (const ColmapCamera& c : model.cameras) camera_ids.insert(c.id);
  std::unordered_map<uint32_t, size_t> image_points;
  for (const ColmapImage& image : model.images) {
    const std::string name = dir + ": image " + std::to_string(image.id);
    if (camera_ids.count(image.camera_id) == 0) {
      return Status::Error(name + ": camera " + std::to_string(image.camera_id) +
                           " is not in the cameras file");
    }
    if (image.name.empty()) return Status::Error(name + ": empty image name");
    image_points[image.id] = image.points2d.size();
  }
  for (const ColmapPoint3D& point : model.points) {
    for (const ColmapTrackElement& e : point.track) {
      const auto it = image_points.find(e.image_id);
      if (it == image_points.end()) {
        return Status::Error(dir + ": point " + std::to_string(point.id) + ": track names image " +
                             std::to_string(e.image_id) + ", which is not in the images file");
      }
      if (e.point2d_index >= it->second) {
        return Status::Error(dir + ": point " + std::to_string(point.id) +
                             ": track names 2D point " + std::to_string(e.point2d_index) +
                             " of image " + std::to_string(e.image_id) + ", which has " +
                             std::to_string(it->second));
      }
    }
  }
  return Status::Ok();
}

Status ReadColmapModel(const std::string& dir, ColmapModel* model, std::string* format) {
  *model = ColmapModel();
  const char* kNames[] = {"cameras", "images", "points3D"};
  bool binary = true, text = true;
  for (const char* n : kNames) {
    binary = binary && FileExists(JoinPath(dir, std::string(n) + ".bin"));
    text = text && FileExists(JoinPath(dir, std::string(n) + ".txt"));
  }
  if (!binary && !text) {
    return Status::Error(dir +
                         ": no COLMAP sparse model (needs cameras, images and points3D as .bin "
                         "or .txt)");
  }
  const std::string ext = binary ? ".bin" : ".txt";
  if (format != nullptr) *format = binary ? "binary" : "text";
  std::string data;
  const std::string cameras = JoinPath(dir, "cameras" + ext);
  const std::string images = JoinPath(dir, "images" + ext);
  const std::string points = JoinPath(dir, "points3D" + ext);
  SFT_RETURN_IF_ERROR(ReadTextFile(cameras, &data));
  SFT_RETURN_IF_ERROR(binary ? ParseColmapCamerasBinary(data, cameras, &model->cameras)
                             : ParseColmapCamerasText(data, cameras, &model->cameras));
  SFT_RETURN_IF_ERROR(ReadTextFile(images, &data));
  SFT_RETURN_IF_ERROR(binary ? ParseColmapImagesBinary(data, images, &model->images)
                             : ParseColmapImagesText(data, images, &model->images));
  SFT_RETURN_IF_ERROR(ReadTextFile(points, &data));
  SFT_RETURN_IF_ERROR(binary ? ParseColmapPointsBinary(data, points, &model->points)
                             : ParseColmapPointsText(data, points, &model->points));
  return CheckColmapModel(*model, dir);
}

}  // namespace sft
