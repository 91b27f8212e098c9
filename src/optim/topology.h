// Topology changes of the schedule: adaptive or isotropic remeshing to an edge length set by the
// images' pixel footprint, and resampling of the surface (ray casting from the views, Poisson
// reconstruction, trimmed to the visual hull) — the research report's periodic remeshing and
// resampling, which let a carved hull gain detail and remove folds and tangles. The material's
// mesh-colour texels are carried to the new surface by re-projection (closest point on the old
// surface). The algorithms live in src/init (remesh.h, resample.h, texel_transfer.h); this file
// decides when and with which parameters they run.
#ifndef SFT_OPTIM_TOPOLOGY_H_
#define SFT_OPTIM_TOPOLOGY_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"

namespace sft {

enum class TopologyChange { kRemesh, kResample };

struct TopologyOptions {
  // Remeshing before the stage: "none", "adaptive" (subdivision + quadric simplification, the
  // report's) or "isotropic" (Botsch–Kobbelt, CGAL).
  std::string remesh = "none";
  // Target edge length of remeshing, in pixels of the stage's image scale: the mean over the
  // fitted views of the surface's pixel footprint times this; (0, 64].
  double remesh_edge_pixels = 1.0;
  bool resample = false;  // resample the surface before the stage (after remeshing).
  // After an outer iteration, resample when folded plus self-intersecting faces exceed this
  // fraction of the faces; [0, 1], 0 = never.
  double resample_fold_fraction = 0.01;
  // After an outer iteration with a geometry phase that leaves self-intersecting faces (and no
  // resampling), smooth the surface around them until none is left (src/init/untangle.h).
  bool untangle = true;
  int max_faces = 200000;  // cap on the faces a topology change may produce, [100, 5e6].

  bool Check(std::string* why) const;
};

// The mean size, in scene units, of one pixel of the views `view_indices` at 2^-image_scale_log2
// of their resolution, at the distance of the mesh's centroid from each camera: what an edge of
// `pixels` pixels measures on the surface.
double PixelFootprint(const TriMesh& mesh, const Dataset& dataset,
                      const std::vector<int>& view_indices, int image_scale_log2);

// StageOptions::texel_resolution's "auto": see ResolveTexelResolution.
constexpr int kTexelResolutionAuto = -1;
constexpr int kMaxAutoTexelResolution = 8;

// The mesh-colours resolution a stage uses: `requested` when > 0; the current one (`current`)
// when 0; for kTexelResolutionAuto the r in [1, kMaxAutoTexelResolution] whose texel spacing
// (mean edge length / r) is closest to the pixel footprint at 2^-image_scale_log2 of the
// dataset's resolution: finer texels than pixels cannot be told apart by the images, coarser
// ones cannot hold what the images show.
int ResolveTexelResolution(int requested, int current, const TriMesh& mesh, const Dataset& dataset,
                           const std::vector<int>& view_indices, int image_scale_log2);

// Applies `change` to `mesh` and carries `material` across (texel resolution resolved by
// ResolveTexelResolution on the new mesh). `views` are the fitted views (ray casting, footprint);
// the masks of every dataset view but the `held_out` ones (never read) bound resampling (visual
// hull) when each of those views has one. `record` receives what was done (kind, faces before
// and after, seconds, the parts' reports).
Status ApplyTopologyChange(TopologyChange change, const TopologyOptions& options,
                           const Dataset& dataset, const std::vector<int>& view_indices,
                           int image_scale_log2, int texel_resolution, TriMesh* mesh,
                           Material* material, nlohmann::json* record,
                           const std::vector<int>& held_out = {});

// The material at another mesh-colours resolution on the same mesh (values read at the new
// texels' representative points).
Material ResampleMaterial(const Material& material, int texel_resolution);

}  // namespace sft

#endif  // SFT_OPTIM_TOPOLOGY_H_
