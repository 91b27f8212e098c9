#include "src/init/texel_transfer.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <exception>
#include <string>
#include <utility>
#include <vector>

namespace sft {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

// How far a texel centre is moved towards its face's centroid to choose among equally close old
// faces (see the header).
constexpr double kTieBreakStep = 1e-6;
constexpr int kMaxResolution = 1024;

Point ToPoint(const Eigen::Vector3d& p) { return Point(p.x(), p.y(), p.z()); }

// Barycentrics (weights of b and c) of the point of triangle abc closest to p, by the Voronoi
// regions of its vertices and edges (Ericson, Real-Time Collision Detection, 2005, §5.1.5).
Eigen::Vector2d ClosestBarycentrics(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a;
  const double d1 = ab.dot(p - a), d2 = ac.dot(p - a);
  if (d1 <= 0.0 && d2 <= 0.0) return {0.0, 0.0};
  const double d3 = ab.dot(p - b), d4 = ac.dot(p - b);
  if (d3 >= 0.0 && d4 <= d3) return {1.0, 0.0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return {d1 / (d1 - d3), 0.0};
  const double d5 = ab.dot(p - c), d6 = ac.dot(p - c);
  if (d6 >= 0.0 && d5 <= d6) return {0.0, 1.0};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return {0.0, d2 / (d2 - d6)};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {1.0 - w, w};
  }
  const double sum = va + vb + vc;
  return {vb / sum, vc / sum};
}

// The old surface: its triangles with area in an AABB tree, and which face each one is.
struct OldSurface {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  std::vector<Triangle> triangles;
  std::vector<int> face_of_triangle;
  Tree tree;
};

Status BuildOldSurface(const TriMesh& mesh, OldSurface* old) {
  MeshToArrays(mesh, &old->positions, &old->faces);
  for (int f = 0; f < static_cast<int>(old->faces.size()); ++f) {
    const Eigen::Vector3i& t = old->faces[f];
    Triangle triangle(ToPoint(old->positions[t[0]]), ToPoint(old->positions[t[1]]),
                      ToPoint(old->positions[t[2]]));
    if (triangle.is_degenerate()) continue;
    old->triangles.push_back(triangle);
    old->face_of_triangle.push_back(f);
  }
  if (old->triangles.empty()) return Status::Error("the old mesh has no face with area");
  try {
    old->tree.insert(old->triangles.cbegin(), old->triangles.cend());
    old->tree.build();
    old->tree.accelerate_distance_queries();
  } catch (const std::exception& e) {
    return Status::Error(std::string("CGAL AABB tree construction failed: ") + e.what());
  }
  return Status::Ok();
}

// Fills the texels of new faces [begin, end) of every `outs[n]` from `ins[n]`.
void TransferFaces(const OldSurface& old, const std::vector<Eigen::Vector3d>& positions,
                   const std::vector<Eigen::Vector3i>& faces, int begin, int end,
                   const std::vector<const MeshColors*>& ins,
                   const std::vector<MeshColors*>& outs) {
  const int r = outs[0]->resolution();
  const TriangleIterator first = old.triangles.cbegin();
  for (int f = begin; f < end; ++f) {
    const Eigen::Vector3d& p0 = positions[faces[f][0]];
    const Eigen::Vector3d e1 = positions[faces[f][1]] - p0, e2 = positions[faces[f][2]] - p0;
    const Eigen::Vector3d centroid = p0 + (e1 + e2) / 3.0;
    Tree::Point_and_primitive_id hint;
    bool have_hint = false;
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; j <= r - i; ++j) {
        const Eigen::Vector2d ab = MeshColors::TexelCenter(r, i, j);
        const Eigen::Vector3d x = p0 + ab.x() * e1 + ab.y() * e2;
        const Point query = ToPoint(x + kTieBreakStep * (centroid - x));
        hint = have_hint ? old.tree.closest_point_and_primitive(query, hint)
                         : old.tree.closest_point_and_primitive(query);
        have_hint = true;
        const int old_face = old.face_of_triangle[hint.second - first];
        const Eigen::Vector3i& t = old.faces[old_face];
        const Eigen::Vector2d old_ab =
            ClosestBarycentrics(x, old.positions[t[0]], old.positions[t[1]], old.positions[t[2]]);
        const int new_texel = f * MeshColors::TexelsPerFace(r) + MeshColors::LocalIndex(r, i, j);
        for (size_t n = 0; n < ins.size(); ++n) {
          const double* value = ins[n]->texel(ins[n]->TexelIndex(old_face, old_ab.x(), old_ab.y()));
          std::copy(value, value + ins[n]->channels(), outs[n]->texel(new_texel));
        }
      }
    }
  }
}

// Transfers every ins[n] (all on old_mesh) to outs[n] on new_mesh at new_resolution.
Status TransferAll(const TriMesh& old_mesh, const std::vector<const MeshColors*>& ins,
                   const TriMesh& new_mesh, int new_resolution,
                   const std::vector<MeshColors*>& outs) {
  if (new_resolution < 0 || new_resolution > kMaxResolution) {
    return Status::Error("texel transfer: resolution must be in [0, " +
                         std::to_string(kMaxResolution) + "], got " +
                         std::to_string(new_resolution));
  }
  if (old_mesh.n_faces() == 0) return Status::Error("texel transfer: the old mesh has no faces");
  if (new_mesh.n_faces() == 0) return Status::Error("texel transfer: the new mesh has no faces");
  for (const MeshColors* in : ins) {
    if (in->num_faces() != static_cast<int>(old_mesh.n_faces()) || in->channels() < 1) {
      return Status::Error("texel transfer: mesh colours for " + std::to_string(in->num_faces()) +
                           " faces and " + std::to_string(in->channels()) +
                           " channels on an old mesh of " + std::to_string(old_mesh.n_faces()) +
                           " faces");
    }
  }
  OldSurface old;
  SFT_RETURN_IF_ERROR(BuildOldSurface(old_mesh, &old).Prefixed("texel transfer"));
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(new_mesh, &positions, &faces);
  const int num_faces = static_cast<int>(faces.size());
  // Written to the outputs only at the end: an output may be one of the inputs.
  std::vector<MeshColors> results;
  std::vector<MeshColors*> result_pointers;
  results.reserve(ins.size());
  for (const MeshColors* in : ins) {
    results.emplace_back(num_faces, new_resolution, in->channels());
    result_pointers.push_back(&results.back());
  }
  try {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, num_faces, 64), [&](const tbb::blocked_range<int>& range) {
          TransferFaces(old, positions, faces, range.begin(), range.end(), ins, result_pointers);
        });
  } catch (const std::exception& e) {
    return Status::Error(std::string("texel transfer: CGAL closest-point query failed: ") +
                         e.what());
  }
  for (size_t n = 0; n < outs.size(); ++n) *outs[n] = std::move(results[n]);
  return Status::Ok();
}

}  // namespace

Status TransferMeshColors(const TriMesh& old_mesh, const MeshColors& old_colors,
                          const TriMesh& new_mesh, int new_resolution, MeshColors* out) {
  return TransferAll(old_mesh, {&old_colors}, new_mesh, new_resolution, {out});
}

Status TransferMaterial(const TriMesh& old_mesh, const Material& old_material,
                        const TriMesh& new_mesh, int new_resolution, Material* out) {
  Material result;
  result.specular = old_material.specular;
  result.fresnel = old_material.fresnel;
  SFT_RETURN_IF_ERROR(TransferAll(old_mesh, {&old_material.albedo, &old_material.roughness},
                                  new_mesh, new_resolution, {&result.albedo, &result.roughness}));
  *out = std::move(result);
  return Status::Ok();
}

}  // namespace sft
