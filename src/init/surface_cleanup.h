// Turning an extracted triangle soup into one closed 2-manifold of a given size (docs/init.md):
// largest connected component, pinched vertices split, outward orientation, quadric decimation.
#ifndef SFT_INIT_SURFACE_CLEANUP_H_
#define SFT_INIT_SURFACE_CLEANUP_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/mesh.h"

namespace sft {

struct SurfaceCleanupReport {
  int input_triangles = 0;
  int degenerate_triangles = 0;  // triangles with a repeated vertex, dropped.
  int components = 0;            // edge-connected components of the input.
  int dropped_triangles = 0;     // triangles of the smaller components, dropped.
  int split_vertices = 0;        // vertices where several fans touched, given one copy per fan.
  bool flipped = false;          // the kept component enclosed negative volume and was reversed.
};

// Keeps the largest edge-connected component of the triangles (by triangle count), splits
// vertices shared by several fans of triangles (two sheets touching at a point) into one vertex
// per fan, orients the surface outwards (positive enclosed volume), and builds the mesh. Error
// when the kept component has an edge without exactly two triangles (open or non-manifold), which
// a closed level set's extraction does not produce.
Status BuildClosedSurface(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector3i>& triangles, TriMesh* mesh,
                          SurfaceCleanupReport* report);

// What DecimateMesh refuses besides collapses that break the topology.
struct DecimationGuards {
  // A collapse that turns a face normal by more than this is refused (OpenMesh
  // ModNormalFlippingT); degrees, in (0, 180].
  double max_normal_deviation_degrees = 60.0;
  // A collapse that leaves a face whose longest edge over its height exceeds this is refused unless
  // it improves on the worst face it replaces (OpenMesh ModAspectRatioT, binary mode); 0 turns the
  // guard off, otherwise at least 1.2 (an equilateral triangle has 2/√3 ≈ 1.155).
  double max_aspect_ratio = 0.0;

  bool Check(std::string* why) const;
};

// Quadric-error decimation (Garland & Heckbert 1997; OpenMesh Decimater with ModQuadricT as the
// priority and the guards above as binary modules) down to at most `target_faces` faces where
// legal collapses allow. Halfedge collapses: every remaining vertex keeps its position. Collapses
// keep a closed manifold closed and manifold. `guards` must pass Check.
void DecimateMesh(int target_faces, TriMesh* mesh,
                  const DecimationGuards& guards = DecimationGuards());

// True when every edge has exactly two faces and every vertex's faces form one fan (a closed
// 2-manifold without pinched vertices); otherwise false with what is wrong in *why.
bool IsClosedManifold(const TriMesh& mesh, std::string* why);

// Enclosed volume (divergence theorem; positive for outward orientation).
double EnclosedVolume(const TriMesh& mesh);

}  // namespace sft

#endif  // SFT_INIT_SURFACE_CLEANUP_H_
