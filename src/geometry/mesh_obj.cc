// OBJ files for src/geometry/mesh.h: the validating parser and the exact (shortest round-trip
// decimal) writer; see mesh.cc for why neither is OpenMesh's.
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

// Parse state beyond ParsedMesh. Positive indices may refer to elements defined later in the file
// (OpenMesh's reader allows it too), so they are range-checked at the end.
struct ObjState {
  struct PendingNormal {
    long long index;
    int line;
  };
  int num_normals = 0;
  std::vector<PendingNormal> positive_normals;  // normal indices to check at the end.
};

// "v x y z" (errors name PATH and the line).
Status ParseObjVertex(const std::vector<std::string_view>& tokens, const std::string& path,
                      int line, ParsedMesh* out) {
  if (tokens.size() < 4) return Status::Error(LinePrefix(path, line) + ": vertex needs x y z");
  Eigen::Vector3d p;
  for (int c = 0; c < 3; ++c) {
    if (!ParseDouble(tokens[1 + c], &p[c])) {
      return Status::Error(LinePrefix(path, line) + ": malformed vertex coordinate '" +
                           std::string(tokens[1 + c]) + "'");
    }
  }
  if (!p.allFinite()) {
    return Status::Error(LinePrefix(path, line) + ": non-finite vertex coordinate");
  }
  out->positions.push_back(p);
  return Status::Ok();
}

// "vt u [v]".
Status ParseObjUv(const std::vector<std::string_view>& tokens, const std::string& path, int line,
                  ParsedMesh* out) {
  if (tokens.size() < 2) return Status::Error(LinePrefix(path, line) + ": vt needs u [v]");
  Eigen::Vector2d uv(0.0, 0.0);
  for (int c = 0; c < 2 && 1 + c < static_cast<int>(tokens.size()); ++c) {
    if (!ParseDouble(tokens[1 + c], &uv[c])) {
      return Status::Error(LinePrefix(path, line) + ": malformed texture coordinate '" +
                           std::string(tokens[1 + c]) + "'");
    }
  }
  if (!uv.allFinite()) {
    return Status::Error(LinePrefix(path, line) + ": non-finite texture coordinate");
  }
  out->uvs.push_back(uv);
  return Status::Ok();
}

// Resolves a 1-based (or negative, relative) index against `count` elements so far; `deferred`
// tells a positive index (checked against the final count later).
Status ResolveObjIndex(std::string_view s, int count, const char* what, const std::string& path,
                       int line, long long* index, bool* deferred) {
  long long value = 0;
  if (!ParseInt(s, &value)) {
    return Status::Error(LinePrefix(path, line) + ": malformed " + what + " index '" +
                         std::string(s) + "'");
  }
  if (value == 0) {
    return Status::Error(LinePrefix(path, line) + ": " + what +
                         " index 0 (OBJ indices start at 1)");
  }
  *deferred = value > 0;
  *index = value > 0 ? value - 1 : count + value;
  if (*index < 0) {
    return Status::Error(LinePrefix(path, line) + ": " + what + " index " + std::to_string(value) +
                         " out of range (" + std::to_string(count) + " defined before it)");
  }
  return Status::Ok();
}

// One face corner: v, v/vt, v//vn or v/vt/vn.
Status ParseObjCorner(std::string_view token, const std::string& path, int line, ObjState* state,
                      ParsedMesh* out) {
  std::string_view parts[3];
  int num_parts = 0;
  std::string_view rest = token;
  while (true) {
    const size_t slash = rest.find('/');
    if (num_parts == 3) {
      return Status::Error(LinePrefix(path, line) + ": malformed face corner '" +
                           std::string(token) + "'");
    }
    parts[num_parts++] = rest.substr(0, slash);
    if (slash == std::string_view::npos) break;
    rest = rest.substr(slash + 1);
  }
  long long vi = 0;
  bool deferred = false;
  SFT_RETURN_IF_ERROR(ResolveObjIndex(parts[0], static_cast<int>(out->positions.size()), "vertex",
                                      path, line, &vi, &deferred));
  if (vi > std::numeric_limits<int>::max()) {
    return Status::Error(LinePrefix(path, line) + ": vertex index out of range");
  }
  out->corner_vertices.push_back(static_cast<int>(vi));
  int uv_index = -1;
  if (num_parts >= 2 && !parts[1].empty()) {
    long long ti = 0;
    SFT_RETURN_IF_ERROR(ResolveObjIndex(parts[1], static_cast<int>(out->uvs.size()),
                                        "texture coordinate", path, line, &ti, &deferred));
    if (ti > std::numeric_limits<int>::max()) {
      return Status::Error(LinePrefix(path, line) + ": texture coordinate index out of range");
    }
    uv_index = static_cast<int>(ti);
  }
  out->corner_uvs.push_back(uv_index);
  if (num_parts == 3 && !parts[2].empty()) {
    long long ni = 0;
    SFT_RETURN_IF_ERROR(
        ResolveObjIndex(parts[2], state->num_normals, "normal", path, line, &ni, &deferred));
    if (deferred) state->positive_normals.push_back({ni, line});
  }
  return Status::Ok();
}

// The deferred range checks against the final counts.
Status CheckObjIndices(const std::string& path, const ObjState& state, const ParsedMesh& mesh) {
  const int num_vertices = static_cast<int>(mesh.positions.size());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int c = mesh.face_offsets[f]; c < mesh.face_offsets[f + 1]; ++c) {
      const int v = mesh.corner_vertices[c];
      if (v >= num_vertices) {
        return Status::Error(LinePrefix(path, mesh.face_lines[f]) + ": vertex index " +
                             std::to_string(v + 1) + " out of range (" +
                             std::to_string(num_vertices) + " vertices)");
      }
      if (mesh.corner_uvs[c] >= static_cast<int>(mesh.uvs.size())) {
        return Status::Error(LinePrefix(path, mesh.face_lines[f]) + ": texture coordinate index " +
                             std::to_string(mesh.corner_uvs[c] + 1) + " out of range (" +
                             std::to_string(mesh.uvs.size()) + " texture coordinates)");
      }
    }
  }
  for (const ObjState::PendingNormal& n : state.positive_normals) {
    if (n.index >= state.num_normals) {
      return Status::Error(LinePrefix(path, n.line) + ": normal index " +
                           std::to_string(n.index + 1) + " out of range (" +
                           std::to_string(state.num_normals) + " normals)");
    }
  }
  return Status::Ok();
}

}  // namespace

Status ParseObj(const std::string& path, const std::string& text, ParsedMesh* out) {
  LineReader reader(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  ObjState state;
  while (reader.Next(&line)) {
    Tokenize(line, &tokens);
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    const int ln = reader.line_number();
    if (key == "v") {
      SFT_RETURN_IF_ERROR(ParseObjVertex(tokens, path, ln, out));
    } else if (key == "vt") {
      SFT_RETURN_IF_ERROR(ParseObjUv(tokens, path, ln, out));
    } else if (key == "vn") {
      ++state.num_normals;
    } else if (key == "f") {
      if (tokens.size() < 4) {
        return Status::Error(LinePrefix(path, ln) + ": face with fewer than 3 vertices");
      }
      for (size_t t = 1; t < tokens.size(); ++t) {
        SFT_RETURN_IF_ERROR(ParseObjCorner(tokens[t], path, ln, &state, out));
      }
      out->EndFace();
      out->face_lines.push_back(ln);  // where each face came from, for the deferred checks.
    }
    // Everything else (o, g, s, usemtl, mtllib, l, p, vp, ...) does not affect the mesh.
  }
  return CheckObjIndices(path, state, *out);
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

}  // namespace mesh_internal
}  // namespace sft
