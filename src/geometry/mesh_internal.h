// Shared by the mesh file code of src/geometry/mesh.h: mesh.cc (dispatch, building the TriMesh),
// mesh_obj.cc, mesh_off.cc and mesh_ply.cc (one format each). Not part of the API.
#ifndef SFT_GEOMETRY_MESH_INTERNAL_H_
#define SFT_GEOMETRY_MESH_INTERNAL_H_

#include <OpenMesh/Core/System/omstream.hh>
#include <cerrno>
#include <cstdio>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "src/core/file_util.h"
#include "src/core/status.h"
#include "src/geometry/mesh.h"

namespace sft {
namespace mesh_internal {

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

// ---- Text helpers (mesh.cc) ---------------------------------------------------------------------

bool IsSpace(char c);
// Splits a line (without its '\n') into whitespace-separated tokens, dropping a '#' comment.
void Tokenize(std::string_view line, std::vector<std::string_view>* tokens);
// Parses a whole token as a double (accepts "nan"/"inf": the caller checks finiteness).
bool ParseDouble(std::string_view token, double* value);
bool ParseInt(std::string_view token, long long* value);
// Appends the shortest decimal text that reads back to exactly `value` (std::to_chars).
void AppendDouble(double value, std::string* out);
// "PATH: line N".
std::string LinePrefix(const std::string& path, int line);
// 1-based (OBJ) or 0-based (OFF) indices of the mesh's non-deleted vertices, in order.
std::vector<int> CompactVertexIndices(const TriMesh& mesh, int first, int* count);

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

// ---- One format each ----------------------------------------------------------------------------

// Parsers of the whole file `text`; `path` prefixes the messages.
Status ParseObj(const std::string& path, const std::string& text, ParsedMesh* out);
Status ParseOff(const std::string& path, const std::string& text, ParsedMesh* out);
Status ParsePly(const std::string& path, const std::string& text, ParsedMesh* out);
// Writers (atomic: a temporary file renamed to `path`).
Status WriteObj(const std::string& path, const TriMesh& mesh);
Status WriteOff(const std::string& path, const TriMesh& mesh);
Status WritePly(const std::string& path, const TriMesh& mesh);

}  // namespace mesh_internal
}  // namespace sft

#endif  // SFT_GEOMETRY_MESH_INTERNAL_H_
