// The file writers of `sft export` (docs/export.md): OBJ + MTL + PNG textures, glTF 2.0 binary,
// PLY with vertex colours. Every file is written atomically (temporary file + rename).
//
// Positions come in the export frame already (export.h chooses it). Faces keep the mesh's order
// and corner order (counter-clockwise = front). No normals are written: sft renders with the
// geometric (flat) normal, and glTF clients must then compute flat normals (glTF 2.0 §3.7.2.1);
// OBJ importers shade such faces flat.
#ifndef SFT_EXPORT_EXPORT_FORMATS_H_
#define SFT_EXPORT_EXPORT_FORMATS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/atlas/bake.h"
#include "src/atlas/uv_atlas.h"
#include "src/core/status.h"
#include "src/geometry/material.h"

namespace sft {

// Fixed file names inside the export folder.
constexpr char kObjFile[] = "model.obj";
constexpr char kMtlFile[] = "model.mtl";
constexpr char kAlbedoPngFile[] = "model_albedo.png";        // sRGB, 8-bit RGB.
constexpr char kRoughnessPngFile[] = "model_roughness.png";  // linear, 8-bit grey.
constexpr char kGlbFile[] = "model.glb";
constexpr char kPlyFile[] = "model.ply";
constexpr char kSummaryFile[] = "export.json";

// The mesh with its vertices split at chart seams: one vertex per (mesh vertex, chart) pair, so
// that each vertex has one UV (glTF has no per-corner attributes).
struct SeamSplitMesh {
  std::vector<int> source_vertex;   // the mesh vertex of each split vertex.
  std::vector<Eigen::Vector2d> uv;  // its atlas UV (v up).
  std::vector<Eigen::Vector3i> faces;
};
SeamSplitMesh SplitAtSeams(const std::vector<Eigen::Vector3i>& faces, const UvAtlas& atlas);

// DIR/model.obj (v, vt, f v/vt; `mtllib model.mtl`, `usemtl`), DIR/model.mtl (Kd 1 1 1 with
// map_Kd model_albedo.png; Pr 1 with map_Pr model_roughness.png; Ks from the specular weight),
// and the two PNGs.
Status WriteObjExport(const std::string& dir, const std::vector<Eigen::Vector3d>& positions,
                      const std::vector<Eigen::Vector3i>& faces, const UvAtlas& atlas,
                      const BakedMaterial& baked, const Material& material);

// A glTF 2.0 binary with one mesh, one metallic-roughness material and both textures embedded
// (docs/export.md, "glTF material"). `positions` are already Y-up.
Status WriteGlbExport(const std::string& path, const std::vector<Eigen::Vector3d>& positions,
                      const std::vector<Eigen::Vector3i>& faces, const UvAtlas& atlas,
                      const BakedMaterial& baked, const Material& material);

// Binary little-endian PLY: vertices x y z (float) and red green blue (uchar, sRGB) — the mean of
// the albedo at the vertex over the faces around it — and the faces.
Status WriteColoredPly(const std::string& path, const std::vector<Eigen::Vector3d>& positions,
                       const std::vector<Eigen::Vector3i>& faces, const Material& material);

}  // namespace sft

#endif  // SFT_EXPORT_EXPORT_FORMATS_H_
