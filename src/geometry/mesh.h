// The mesh type (OpenMesh TriMesh with double-precision points) and mesh files.
#ifndef SFT_GEOMETRY_MESH_H_
#define SFT_GEOMETRY_MESH_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

struct MeshTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
  typedef OpenMesh::Vec2d TexCoord2D;
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;

// What validation found besides hard errors.
struct MeshReport {
  int num_vertices = 0;
  int num_faces = 0;
  int num_degenerate_faces = 0;  // zero area (relative to the bounding box) or repeated vertex.
  int num_isolated_vertices = 0;
  bool has_texcoords = false;  // per-corner UVs were read (OBJ vt / PLY texcoord).
};

// Reads OBJ, PLY (ascii/binary) or OFF by extension. Polygons are triangulated by
// TriangulatePolygon (polygon.h: ear clipping in their plane); a non-planar, self-intersecting or
// over-large polygon is an error naming the file, the face index and (OBJ, OFF) its line. A
// leading UTF-8 byte-order mark is skipped. Per-corner UVs are
// read into halfedge texcoords when the file has them (report->has_texcoords). Errors (one line,
// naming the file): missing/unreadable file, unknown extension, no faces, non-finite coordinates,
// a face index out of range (detected before OpenMesh sees the file, since OpenMesh skips such
// faces silently). Degenerate faces are counted in `report`, not errors.
Status ReadMesh(const std::string& path, TriMesh* mesh, MeshReport* report = nullptr);
// The same from a file's contents held in memory: `path` selects the format by its extension and
// names the file in errors (ReadMesh reads the file and calls this).
Status ParseMesh(std::string text, const std::string& path, TriMesh* mesh,
                 MeshReport* report = nullptr);

// Writes OBJ, PLY (binary) or OFF by extension, atomically. OBJ includes per-corner UVs when the
// mesh has halfedge texcoords.
Status WriteMesh(const std::string& path, const TriMesh& mesh);

// Flat copies for renderers and solvers: positions (x, y, z per vertex) and faces (3 indices).
void MeshToArrays(const TriMesh& mesh, std::vector<Eigen::Vector3d>* positions,
                  std::vector<Eigen::Vector3i>* faces);

// Total area of the faces; scene units squared.
double SurfaceArea(const std::vector<Eigen::Vector3d>& positions,
                   const std::vector<Eigen::Vector3i>& faces);
double SurfaceArea(const TriMesh& mesh);

// Per-face corner UVs (3 per face, corner order = face vertex order); empty when the mesh has none.
std::vector<Eigen::Vector2d> FaceCornerUvs(const TriMesh& mesh);
// Sets the halfedge texcoords from per-face corner UVs (FaceCornerUvs' layout; 3 per face, CHECK).
void SetFaceCornerUvs(const std::vector<Eigen::Vector2d>& uvs, TriMesh* mesh);

// Axis-aligned bounds of the vertices that some face uses (isolated vertices are not part of the
// surface: a stray far-away `v` line must not move a normalization or a camera); both zero when
// there are none.
void MeshBounds(const TriMesh& mesh, Eigen::Vector3d* lo, Eigen::Vector3d* hi);

}  // namespace sft

#endif  // SFT_GEOMETRY_MESH_H_
