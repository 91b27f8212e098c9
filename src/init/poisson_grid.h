// Poisson surface reconstruction (Kazhdan, Bolitho and Hoppe 2006, "Poisson Surface
// Reconstruction", SGP) of oriented samples, sampled on a voxel grid as a signed field.
//
// The library. CGAL 5.5's Poisson_reconstruction_function: Delaunay refinement of the samples,
// then the Poisson equation Δf = ∇·N solved (Eigen's conjugate gradient) for a function that is
// piecewise linear on the tetrahedra, shifted so that the median of f over the samples is zero
// and f < 0 inside. CGAL's own contouring (make_surface_mesh, a second Delaunay refinement) is
// not used: the field is evaluated at the voxel centres instead, so that the caller can intersect
// it with other fields (the visual hull, resample.h) and extract one closed level set with the
// same OpenVDB extraction as the visual hull. COLMAP's `poisson_mesher` (Kazhdan's screened
// Poisson code) was the alternative; through files and a subprocess it took about as long on the
// same samples (tens of thousands of points: seconds of CPU for both) and returns a mesh rather
// than a field, so it could not be intersected with the hull before extraction.
//
// Scale. CGAL's f is an indicator-like function whose slope across the surface depends on the
// sample density. It is divided by its median derivative along the sample normals, so that near
// the surface the field approximates the signed distance in scene units (and can be combined with
// the hull's distance field by max()); far from the samples it is not a distance.
//
// Threads: the solve is single-threaded (CGAL, Eigen); the grid evaluation runs over z slices
// with TBB, each slice walking the triangulation with its own hint (Triangulation_3::locate is
// read-only; the barycentric coordinates are computed here, not through CGAL's shared cache).
#ifndef SFT_INIT_POISSON_GRID_H_
#define SFT_INIT_POISSON_GRID_H_

#include <vector>

#include "src/core/status.h"
#include "src/init/view_samples.h"
#include "src/init/visual_hull.h"

namespace sft {

// Fewer samples than this are refused (CGAL's spacing estimate alone uses 6 neighbours; a few
// dozen points define no surface worth resampling).
constexpr int kMinPoissonSamples = 64;

struct PoissonGridReport {
  int triangulation_vertices = 0;  // samples plus CGAL's Steiner points.
  double slope = 0.0;              // median derivative of CGAL's f along the normals (1/unit).
  double solve_seconds = 0.0;      // Delaunay refinement and the linear solve.
  double evaluate_seconds = 0.0;   // the field at the voxel centres.
};

// The normalized Poisson field at the centres of `box`'s voxels, clamped to ±band (scene units,
// negative inside), x fastest: index (k·ny + j)·nx + i, as VisualHull::field. Errors: fewer than
// kMinPoissonSamples samples; samples that do not span a volume (flat within half a voxel); a
// failed solve or a field that does not increase along the normals; CGAL exceptions.
Status EvaluatePoissonGrid(const std::vector<OrientedPoint>& samples, const VoxelBox& box,
                           double band, std::vector<float>* field, PoissonGridReport* report);

}  // namespace sft

#endif  // SFT_INIT_POISSON_GRID_H_
