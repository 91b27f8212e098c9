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
// This file: the text helpers, building the TriMesh from the parsed corner lists and the public
// functions; each format's parser and writer are in mesh_obj.cc, mesh_off.cc and mesh_ply.cc.
#include "src/geometry/mesh.h"

#include <glog/logging.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string_view>

#include "src/core/file_util.h"
#include "src/geometry/mesh_internal.h"
#include "src/geometry/polygon.h"

namespace sft {
namespace mesh_internal {

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

std::string LinePrefix(const std::string& path, int line) {
  return path + ": line " + std::to_string(line);
}

// 1-based (OBJ) or 0-based (OFF) indices of the mesh's non-deleted vertices, in order.
std::vector<int> CompactVertexIndices(const TriMesh& mesh, int first, int* count) {
  std::vector<int> compact(mesh.n_vertices(), -1);
  int next = first;
  for (TriMesh::VertexHandle vh : mesh.vertices()) compact[vh.idx()] = next++;
  *count = next - first;
  return compact;
}

}  // namespace mesh_internal

namespace {

using namespace mesh_internal;  // NOLINT: this file's own internals.

// A face whose area is at most this fraction of the squared bounding-box diagonal counts as
// degenerate (zero area up to rounding of coordinates; 1e-12 is far above double rounding noise
// of ~1e-16 and far below the area of any real triangle of a mesh with < 1e10 faces).
constexpr double kDegenerateRelativeArea = 1e-12;

// ---- Building the TriMesh -----------------------------------------------------------------------

// A face that repeats a vertex cannot be represented in a halfedge mesh.
bool RepeatsVertex(const ParsedMesh& parsed, int begin, int end) {
  for (int a = begin; a < end; ++a) {
    for (int b = a + 1; b < end; ++b) {
      if (parsed.corner_vertices[a] == parsed.corner_vertices[b]) return true;
    }
  }
  return false;
}

// Adds the triangle of parsed corners `corners` (with their UVs when `with_uvs`); a non-manifold
// one gets private copies of its vertices and counts in `non_manifold_faces`.
void AddTriangle(const ParsedMesh& parsed, const int corners[3],
                 const std::vector<TriMesh::VertexHandle>& handles, bool with_uvs, TriMesh* mesh,
                 int* non_manifold_faces) {
  TriMesh::VertexHandle vh[3];
  for (int c = 0; c < 3; ++c) vh[c] = handles[parsed.corner_vertices[corners[c]]];
  TriMesh::FaceHandle fh = mesh->add_face(vh[0], vh[1], vh[2]);
  if (!fh.is_valid()) {
    ++*non_manifold_faces;
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
  if (!with_uvs) return;
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

// Sizes, UVs, and the degenerate faces (`repeated_vertex_faces` left out, plus those of
// negligible area) and isolated vertices of a built mesh.
MeshReport SummarizeMesh(const TriMesh& mesh, bool with_uvs, int repeated_vertex_faces) {
  MeshReport report;
  report.num_vertices = static_cast<int>(mesh.n_vertices());
  report.num_faces = static_cast<int>(mesh.n_faces());
  report.has_texcoords = with_uvs;
  report.num_degenerate_faces = repeated_vertex_faces;
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const double diagonal2 = (hi - lo).squaredNorm();
  for (TriMesh::FaceHandle fh : mesh.faces()) {
    Eigen::Vector3d p[3];
    int c = 0;
    for (TriMesh::VertexHandle vh : mesh.fv_range(fh)) {
      const TriMesh::Point& q = mesh.point(vh);
      p[c++] = Eigen::Vector3d(q[0], q[1], q[2]);
    }
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    if (!(area > kDegenerateRelativeArea * diagonal2)) ++report.num_degenerate_faces;
  }
  for (TriMesh::VertexHandle vh : mesh.vertices()) {
    if (mesh.is_isolated(vh)) ++report.num_isolated_vertices;
  }
  return report;
}

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
      // Counted as degenerate and left out (OpenMesh's importer drops it too).
      if (RepeatsVertex(parsed, begin, end)) {
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
        AddTriangle(parsed, corners, handles, with_uvs, mesh, &non_manifold_faces);
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
  if (report != nullptr) *report = SummarizeMesh(*mesh, with_uvs, repeated_vertex_faces);
  return Status::Ok();
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

double SurfaceArea(const std::vector<Eigen::Vector3d>& positions,
                   const std::vector<Eigen::Vector3i>& faces) {
  double area = 0.0;
  for (const Eigen::Vector3i& f : faces) {
    area +=
        0.5 * (positions[f[1]] - positions[f[0]]).cross(positions[f[2]] - positions[f[0]]).norm();
  }
  return area;
}

double SurfaceArea(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  return SurfaceArea(positions, faces);
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

void SetFaceCornerUvs(const std::vector<Eigen::Vector2d>& uvs, TriMesh* mesh) {
  CHECK_EQ(uvs.size(), 3 * mesh->n_faces()) << "SetFaceCornerUvs: 3 UVs per face";
  mesh->request_halfedge_texcoords2D();
  for (size_t f = 0; f < mesh->n_faces(); ++f) {
    const TriMesh::FaceHandle fh(static_cast<int>(f));
    int c = 0;
    for (TriMesh::HalfedgeHandle h : mesh->fh_range(fh)) {
      if (c >= 3) break;
      const Eigen::Vector2d& uv = uvs[3 * f + c++];
      mesh->set_texcoord2D(h, TriMesh::TexCoord2D(uv.x(), uv.y()));
    }
  }
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
