// Surface resampling: a new mesh of the surface that the views see, rebuilt from samples of it
// (the research report's periodic "resampling of the surface by ray casting from the views,
// followed by Poisson reconstruction"). It removes what an optimized mesh accumulates and local
// remeshing cannot undo: folds, tangles, inverted triangles and inner sheets, none of which a
// camera sees from outside.
//
// Pipeline.
//  1. Samples (view_samples.h): one ray per pixel_stride² block of pixels of every view; the first
//     hit's position and the hit face's geometric normal turned towards the camera. A first hit
//     on a back face (a face of a fold, wound the wrong way) still yields the outward normal of
//     the surface the camera sees, which is what Poisson needs (view_samples.h says why).
//  2. Thinning to one sample per cell of side h and per dominant normal direction, h =
//     spacing_factor × the mean edge length of a mesh of `faces` equilateral triangles with the
//     input's area: the solve then costs what the output's resolution needs.
//  3. Poisson reconstruction (Kazhdan, Bolitho and Hoppe 2006) with CGAL, sampled as a signed
//     field on a grid of voxel size h (poisson_grid.h) over the samples' bounding box grown by
//     kGridMarginFraction of its diagonal (at least kGridMarginVoxels voxels). Outside the grid the
//     field is "outside", so a reconstruction reaching past the margin is cut flat there.
//  4. Trimming to the visual hull. Poisson closes the parts no view sees (the underside of an
//     object on a table, deep concavities) with a smooth, often bloated surface. When carving
//     views are given, the masks' visual hull is carved (visual_hull.h) at about the grid's voxel
//     size and the field becomes max(Poisson, hull): the signed field of the intersection of the
//     two solids. Trimming in the field rather than on the mesh (clipping faces, pulling vertices
//     back into the masks, filling holes) is what keeps the result ONE closed manifold by
//     construction: the intersection's boundary is a level set like any other, extracted by the
//     visual hull's OpenVDB extraction, with no hole to fill and no fold created by moved
//     vertices. Near silhouettes, where the true surface touches the hull, the cut is within the
//     hull's half voxel of the surface.
//  5. Clean-up and decimation (surface_cleanup.h): the largest component (trimming can cut off
//     thin parts), pinched vertices split, outward orientation, quadric decimation to `faces`.
//
// Limits. The result only knows what the views see: a concavity that no ray reaches is closed
// over; features thinner than about h are lost (Poisson smooths at the sample spacing); surface
// detail is that of the grid and of the samples: where the pixel footprint at the surface
// (depth / focal length × pixel_stride) is coarser than h, cells stay empty and Poisson
// interpolates between the samples as it does across any gap.
// The grid is dense: its longest side is at most kMaxGridSide voxels (h grows when needed).
//
// Cost. CGAL's refinement and solve dominate and grow faster than linearly with the samples;
// halving spacing_factor quadruples the samples and the extracted faces (and so the decimation's
// work). The default spacing puts about one sample per output vertex.
#ifndef SFT_INIT_RESAMPLE_H_
#define SFT_INIT_RESAMPLE_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/mesh.h"
#include "src/init/surface_cleanup.h"
#include "src/init/view_samples.h"
#include "src/init/visual_hull.h"
#include "src/render/render.h"

namespace sft {

struct ResampleOptions {
  // Cast one ray per pixel_stride × pixel_stride block of each view's pixels, [1, 64].
  int pixel_stride = 1;
  // Faces of the result: an upper bound that quadric decimation reaches where legal collapses
  // allow; 0 = the input's face count. 0 or [kMinFaces, kMaxFaces].
  int faces = 0;
  // Sample and grid spacing h relative to the mean edge length of the target mesh (`faces`
  // equilateral triangles covering the input's area); smaller = finer field, slower solve,
  // [kMinSpacingFactor, kMaxSpacingFactor].
  double spacing_factor = 1.0;
  // Intersect the Poisson solid with the visual hull of the carving views (when given).
  bool trim_to_hull = true;
  // Visual hull: a point must be seen by at least this fraction of the carving views, (0, 1]
  // (VisualHullOptions::min_view_fraction).
  double hull_min_view_fraction = 0.25;

  static constexpr int kMaxPixelStride = 64;
  static constexpr int kMinFaces = 100;
  static constexpr int kMaxFaces = 50000000;
  static constexpr double kMinSpacingFactor = 0.05;
  static constexpr double kMaxSpacingFactor = 16.0;

  // False with the option in *why ("pixel_stride: must be in [1, 64], got 0").
  bool Check(std::string* why) const;
};

// The mean edge length of a mesh of `faces` equilateral triangles covering `area` (the spacing the
// resampling's thinning and grid take for a target face count).
double EquilateralEdgeLength(double area, int faces);

// The grid's margin around the samples' bounding box: this fraction of its diagonal, and at least
// kGridMarginVoxels voxels.
constexpr double kGridMarginFraction = 0.05;
constexpr int kGridMarginVoxels = 4;
// Voxels along the grid's longest side, at most.
constexpr int kMaxGridSide = 400;

struct ResampleReport {
  int64_t rays = 0;            // camera rays cast.
  int64_t hits = 0;            // rays that hit the mesh (samples before thinning).
  int64_t back_face_hits = 0;  // of those, first hits on back faces (folds, inverted faces).
  int views_with_hits = 0;
  int points = 0;        // samples after thinning, given to the Poisson solve.
  double spacing = 0.0;  // h: thinning cell and voxel size (scene units).
  Eigen::Vector3i grid = Eigen::Vector3i::Zero();  // voxels of the field's grid.
  int triangulation_vertices = 0;  // CGAL's Delaunay triangulation (samples + Steiner points).
  int hull_views = 0;              // carving views used for trimming (0 = no trimming).
  int64_t trimmed_voxels = 0;      // voxels inside the Poisson solid but outside the hull.
  int poisson_vertices = 0;        // extracted surface (after trimming), before clean-up.
  int poisson_faces = 0;
  int components_removed = 0;  // components of the extracted surface other than the kept one.
  SurfaceCleanupReport cleanup;
  int vertices_after = 0;  // the result.
  int faces_after = 0;
  double cast_seconds = 0.0;     // ray casting and thinning.
  double poisson_seconds = 0.0;  // CGAL's refinement and solve, and the grid evaluation;
  double solve_seconds = 0.0;    // of which the refinement and solve.
  double trim_seconds = 0.0;     // carving the hull and intersecting.
  double extract_seconds = 0.0;  // OpenVDB extraction and clean-up.
  double decimate_seconds = 0.0;
  double total_seconds = 0.0;
};

// Resamples `mesh` as seen from `views` (their cameras and poses; lights are not used), trimmed
// to the visual hull of `hull` when it is non-null and non-empty and options.trim_to_hull. `out`
// receives one closed, outward-oriented 2-manifold (it may be the same object as `mesh`).
// Errors (no exception escapes): invalid options; a mesh without faces; no views; no ray
// hitting the mesh ("no view sees the mesh"); too few samples or samples spanning no volume; a
// failed Poisson solve; a failed carving; an empty or unextractable surface.
Status ResampleSurface(const TriMesh& mesh, const std::vector<ViewSetup>& views,
                       const std::vector<CarvingView>* hull, const ResampleOptions& options,
                       TriMesh* out, ResampleReport* report);

// Steps 2-5 above on given oriented samples (e.g. stereo points, stereo_points.h): thinning and the
// grid at `spacing` (scene units, > 0; it grows when the grid would pass kMaxGridSide), Poisson,
// trimming to the hull of `hull` when non-null and non-empty and options.trim_to_hull, clean-up
// and decimation to options.faces (which must be set here). pixel_stride and spacing_factor are
// not used. Errors as ResampleSurface's, and fewer than 4 samples.
Status SurfaceFromSamples(std::vector<OrientedPoint> samples, double spacing,
                          const std::vector<CarvingView>* hull, const ResampleOptions& options,
                          TriMesh* out, ResampleReport* report);

}  // namespace sft

#endif  // SFT_INIT_RESAMPLE_H_
