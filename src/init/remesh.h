// Remeshing at a target edge length, for the topology changes between reconstruction stages.
//
// Two methods:
//  - kAdaptive, the Shape-from-Tracing report's "adaptive remeshing" (§3.3: "we periodically
//    perform subdivision and quadric simplification"): longest-edge bisection (OpenMesh
//    Subdivider::Uniform::LongestEdgeT) until no edge is longer than the target, then quadric
//    decimation (Garland & Heckbert 1997; OpenMesh Decimater, src/init/surface_cleanup.h) down to
//    the face count the target implies. Bisection inserts edge midpoints, so the subdivided
//    surface is the input surface (nothing is smoothed away), and the halfedge collapses keep
//    vertices where they are: every output vertex lies on the input surface. Vertices end up
//    dense where the surface bends and sparse where it is flat.
//  - kIsotropic: CGAL 5.5 Polygon_mesh_processing::isotropic_remeshing (Botsch & Kobbelt 2004:
//    split edges longer than 4/3·L, collapse edges shorter than 4/5·L, flip towards valence 6,
//    tangential relaxation, projection onto the input), giving near-uniform edges a little
//    shorter than L (mean about 0.93 L), hence about 15% more faces than A/(√3/4·L²); the output
//    is decimated to max_faces when it exceeds it.
//
// Both first repair the input (src/init/cgal_surface_mesh.h): vertices with equal coordinates
// are merged, faces with a repeated corner and repeated faces dropped, and vertices copied where
// the faces around a vertex or edge are not one disk (non-manifold vertices and edges); faces
// with collinear corners are then removed by edge flips and collapses. The output is oriented
// like the input and is a closed 2-manifold when the repaired input is closed (checked: an error
// otherwise).
//
// Face count implied by an edge length L over total area A: A / (√3/4·L²) (equilateral
// triangles). When it exceeds max_faces, L is raised until it does not
// (RemeshReport::edge_length_used), so that the bisected mesh stays within a few times max_faces.
// Cost: the adaptive method holds the bisected mesh (about 3x the target face count) and
// decimates it single-threaded (OpenMesh); the isotropic one is single-threaded too.
#ifndef SFT_INIT_REMESH_H_
#define SFT_INIT_REMESH_H_

#include <string>

#include "src/core/status.h"
#include "src/geometry/mesh.h"

namespace sft {

enum class RemeshMethod { kAdaptive, kIsotropic };

// "adaptive", "isotropic".
const char* RemeshMethodName(RemeshMethod method);
// False (and *method unchanged) for an unknown name.
bool RemeshMethodFromName(const std::string& name, RemeshMethod* method);

struct RemeshOptions {
  // Subdivision plus quadric decimation (adaptive density), or CGAL isotropic remeshing.
  RemeshMethod method = RemeshMethod::kAdaptive;
  // Target edge length; scene units, finite and > 0 (the caller derives it from the pixel
  // footprint). Raised when the face count it implies exceeds max_faces.
  double target_edge_length = 0.0;
  // Cap on the output's face count; in [4, 20'000'000].
  int max_faces = 200000;
  // Isotropic: remeshing iterations (split, collapse, flip, relax, project); in [1, 100].
  int iterations = 3;
  // Adaptive: edges are bisected until none is longer than this times the (used) target edge
  // length; in [0.25, 1]. Smaller gives decimation more vertices to choose from, at a cost of
  // about ratio⁻² in time and memory.
  double subdivision_ratio = 1.0;
  // Decimation (adaptive; isotropic only when over max_faces) refuses collapses that turn a face
  // normal by more than this; degrees, in (0, 180].
  double max_normal_deviation_degrees = 60.0;
  // Decimation refuses collapses that leave a face whose longest edge over its height exceeds
  // this (unless the collapse improves the worst face around it); 0 = off, else >= 1.2.
  double max_aspect_ratio = 5.0;

  bool Check(std::string* why) const;
};

struct RemeshReport {
  int faces_before = 0;                 // faces of the input mesh.
  int faces_after = 0;                  // faces of the output.
  int vertices_after = 0;               // vertices of the output.
  int non_manifold_vertices_split = 0;  // vertex copies made by the repair (see above).
  int merged_vertices = 0;              // input vertices merged into one with equal coordinates.
  int dropped_faces = 0;                // faces dropped by the repair, and zero-area faces removed.
  int faces_subdivided = 0;             // adaptive: faces after bisection, before decimation.
  int target_faces = 0;                 // A / (√3/4·L²) at the used L, at most max_faces.
  double edge_length_used = 0.0;        // the target edge length after the max_faces cap.
  double mean_edge_length_after = 0.0;  // scene units.
  double min_edge_length_after = 0.0;   // scene units.
  double max_edge_length_after = 0.0;   // scene units.
  double seconds = 0.0;                 // wall-clock time of Remesh.
};

// Remeshes `mesh` into `*out` (which may not alias `mesh`). Errors (Status, never a crash or an
// exception): options failing Check, an empty mesh or one without a face with three distinct
// corners, a zero-area surface, a CGAL failure, or a closed input giving a non-closed output.
// `report` may be null.
Status Remesh(const TriMesh& mesh, const RemeshOptions& options, TriMesh* out,
              RemeshReport* report);

}  // namespace sft

#endif  // SFT_INIT_REMESH_H_
