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
