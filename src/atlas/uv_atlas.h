// The UV atlas of a mesh: disk-like charts (charts.h), each given a conformal parameterisation
// (chart_parameterization.h, CGAL's LSCM), packed into one square texture (atlas_packing.h).
//
// A chart whose parameterisation fails (CGAL error, flipped or overlapping triangles) or whose L2
// stretch exceeds `max_stretch` is split — re-grown over its own faces with half the normal cone
// and at most half its faces — and the pieces are parameterised again, until every chart passes
// (a single triangle always does: it is laid out isometrically).
//
// Non-manifold and inconsistently oriented edges are cut (mesh_topology.h), so the charts on
// either side are parameterised apart. Degenerate faces (a repeated vertex or zero area) get all
// three corners at the centre of the atlas's top-left texel, which lies in the gutter.
#ifndef SFT_ATLAS_UV_ATLAS_H_
#define SFT_ATLAS_UV_ATLAS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/atlas/charts.h"
#include "src/core/status.h"

namespace sft {

struct UvAtlasOptions {
  int texture_size = 1024;   // atlas width = height; texels, [64, 16384].
  int gutter_texels = 4;     // least distance between charts and to the atlas edge; [1, 64].
  double max_stretch = 1.5;  // charts with a larger L2 stretch are split; [1.01, 100].
  ChartingOptions charting;  // the normal cone and chart sizes of the first charting.

  bool Check(std::string* why) const;
};

struct UvAtlas {
  int texture_size = 0;
  // Three per face, in face corner order: u to the right, v up, in [0, 1] (OBJ's convention).
  std::vector<Eigen::Vector2d> corner_uv;
  std::vector<int> chart_of_face;  // 0 .. num_charts − 1; −1 for degenerate faces.
  int num_charts = 0;
};

struct UvAtlasReport {
  int faces = 0;
  int charts = 0;
  int degenerate_faces = 0;          // given the gutter texel (see above).
  int nonmanifold_edges = 0;         // edges of three or more faces, cut.
  int inconsistent_edges = 0;        // edges whose two faces disagree on orientation, cut.
  int splits = 0;                    // charts split for failing or for stretch.
  int failed_parameterizations = 0;  // of which failed (CGAL error, flips, overlaps).
  double utilization = 0.0;          // Σ chart UV area / atlas area; (0, 1).
  double max_stretch = 0.0;          // largest chart L2 stretch (≥ 1).
  double mean_stretch = 0.0;         // area-weighted mean chart L2 stretch.
  double texels_per_unit = 0.0;      // texel density: texels per scene unit of length.
  double chart_seconds = 0.0;
  double parameterize_seconds = 0.0;  // including re-parameterising split charts.
  double pack_seconds = 0.0;
  double seconds = 0.0;
};

// Builds the atlas of the triangles `faces` over `positions`. Errors: a face index out of range,
// no non-degenerate face, charts that do not fit the texture (too small for their number).
Status BuildUvAtlas(const std::vector<Eigen::Vector3d>& positions,
                    const std::vector<Eigen::Vector3i>& faces, const UvAtlasOptions& options,
                    UvAtlas* atlas, UvAtlasReport* report);

}  // namespace sft

#endif  // SFT_ATLAS_UV_ATLAS_H_
