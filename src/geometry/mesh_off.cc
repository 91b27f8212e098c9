// OFF files for src/geometry/mesh.h: the validating parser and the exact writer (OpenMesh's OFF
// writer rounds coordinates to float); see mesh.cc.
#include <glog/logging.h>

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

// The header keyword [ST][C][N]OFF and the vertex and face counts (on the keyword's line or the
// next non-empty one). 4OFF (homogeneous), nOFF (n-dimensional) and binary OFF are not supported.
Status ParseOffHeader(const std::string& path, LineReader* reader, long long* num_vertices,
                      long long* num_faces) {
  std::string_view line;
  std::vector<std::string_view> tokens;
  while (reader->Next(&line)) {
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
    return Status::Error(path + ": line " + std::to_string(reader->line_number()) +
                         ": expected an OFF header (OFF, COFF, NOFF, STOFF...), got '" +
                         std::string(keyword) + "'");
  }
  size_t next = 1;
  if (tokens.size() > 1 && tokens[1] == "BINARY") {
    return Status::Error(path + ": binary OFF is not supported (use PLY)");
  }
  if (tokens.size() <= next) {
    while (reader->Next(&line)) {
      Tokenize(line, &tokens);
      if (!tokens.empty()) break;
    }
    next = 0;
  }
  if (tokens.size() < next + 2 || !ParseInt(tokens[next], num_vertices) ||
      !ParseInt(tokens[next + 1], num_faces) || *num_vertices < 0 || *num_faces < 0 ||
      *num_vertices > std::numeric_limits<int>::max() ||
      *num_faces > std::numeric_limits<int>::max()) {
    return Status::Error(LinePrefix(path, reader->line_number()) +
                         ": expected vertex and face counts after the OFF keyword");
  }
  return Status::Ok();
}

// A vertex line "x y z [...]" (errors name PATH and the line).
Status ParseOffVertex(const std::vector<std::string_view>& tokens, const std::string& path,
                      int line, ParsedMesh* out) {
  if (tokens.size() < 3) return Status::Error(LinePrefix(path, line) + ": vertex needs x y z");
  Eigen::Vector3d p;
  for (int c = 0; c < 3; ++c) {
    if (!ParseDouble(tokens[c], &p[c])) {
      return Status::Error(LinePrefix(path, line) + ": malformed vertex coordinate '" +
                           std::string(tokens[c]) + "'");
    }
  }
  if (!p.allFinite()) {
    return Status::Error(LinePrefix(path, line) + ": non-finite vertex coordinate");
  }
  out->positions.push_back(p);
  return Status::Ok();
}

// A face line "n v1 ... vn [colour]"; tokens after the indices (face colours) are ignored.
Status ParseOffFace(const std::vector<std::string_view>& tokens, const std::string& path, int line,
                    long long num_vertices, ParsedMesh* out) {
  long long n = 0;
  if (!ParseInt(tokens[0], &n) || n < 3) {
    return Status::Error(LinePrefix(path, line) + ": face needs a vertex count of at least 3");
  }
  if (static_cast<long long>(tokens.size()) < 1 + n) {
    return Status::Error(LinePrefix(path, line) + ": face has fewer indices than its count " +
                         std::to_string(n));
  }
  for (long long k = 0; k < n; ++k) {
    long long v = 0;
    if (!ParseInt(tokens[1 + k], &v)) {
      return Status::Error(LinePrefix(path, line) + ": malformed vertex index '" +
                           std::string(tokens[1 + k]) + "'");
    }
    if (v < 0 || v >= num_vertices) {
      return Status::Error(LinePrefix(path, line) + ": vertex index " + std::to_string(v) +
                           " out of range (" + std::to_string(num_vertices) + " vertices)");
    }
    out->corner_vertices.push_back(static_cast<int>(v));
    out->corner_uvs.push_back(-1);
  }
  out->EndFace();
  out->face_lines.push_back(line);
  return Status::Ok();
}

}  // namespace

Status ParseOff(const std::string& path, const std::string& text, ParsedMesh* out) {
  LineReader reader(text);
  long long num_vertices = -1, num_faces = -1;
  SFT_RETURN_IF_ERROR(ParseOffHeader(path, &reader, &num_vertices, &num_faces));
  std::string_view line;
  std::vector<std::string_view> tokens;
  while (static_cast<long long>(out->positions.size()) < num_vertices) {
    if (!reader.Next(&line)) {
      return Status::Error(path + ": truncated: header promises " + std::to_string(num_vertices) +
                           " vertices, file has " + std::to_string(out->positions.size()));
    }
    Tokenize(line, &tokens);
    if (tokens.empty()) continue;
    SFT_RETURN_IF_ERROR(ParseOffVertex(tokens, path, reader.line_number(), out));
  }
  while (out->num_faces() < num_faces) {
    if (!reader.Next(&line)) {
      return Status::Error(path + ": truncated: header promises " + std::to_string(num_faces) +
                           " faces, file has " + std::to_string(out->num_faces()));
    }
    Tokenize(line, &tokens);
    if (tokens.empty()) continue;
    SFT_RETURN_IF_ERROR(ParseOffFace(tokens, path, reader.line_number(), num_vertices, out));
  }
  return Status::Ok();
}

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

}  // namespace mesh_internal
}  // namespace sft
