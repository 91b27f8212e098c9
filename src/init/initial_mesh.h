// The initial mesh of a dataset (`sft init`, docs/init.md): visual-hull carving from every view's
// mask (visual_hull.h), surface extraction with OpenVDB, cleaning to one closed manifold and
// quadric decimation (surface_cleanup.h), and a check of the hull against sparse points.
//
// Sparse points (e.g. COLMAP's, in the dataset's world frame) are only compared with the hull,
// not used to change it: a point outside the hull by more than one voxel contradicts some mask
// (an outlier of the reconstruction, or a mask that cuts off part of the object) and is counted;
// a point deeper inside than kInsidePointVoxels voxels marks a concavity that silhouettes cannot
// see, and is counted too. Carving toward such points would need to know which views see them
// (COLMAP's tracks), which a bare point file does not say.
#ifndef SFT_INIT_INITIAL_MESH_H_
#define SFT_INIT_INITIAL_MESH_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/mesh.h"
#include "src/init/stereo_points.h"
#include "src/init/surface_cleanup.h"
#include "src/init/visual_hull.h"
#include "src/io/dataset.h"

namespace sft {

struct InitialMeshOptions {
  VisualHullOptions hull;  // resolution, view fraction, generous box.
  // Faces of the output mesh (upper bound; decimation stops where no legal collapse is left),
  // [kMinFaces, kMaxFaces].
  int faces = 10000;
  // Rebuild the hull from stereo points (stereo_mesh.h). MakeInitialMesh only carves; the callers
  // that read the images (`sft init`, reconstruct's carved start) run the stereo step after it.
  bool stereo = false;
  StereoOptions stereo_options;  // checked only when `stereo` is set.
  bool progress = true;          // print a progress line on stderr.

  static constexpr int kMinFaces = 100;
  static constexpr int kMaxFaces = 50000000;

  // False with the option in *why ("faces: must be in [100, 50000000], got 5").
  bool Check(std::string* why) const;
};

// A point is counted as "well inside" the hull when the field there is below minus this many
// voxels.
constexpr double kInsidePointVoxels = 2.0;

struct InitialMeshReport {
  VoxelBox box;                  // the carving grid.
  int min_views = 0;             // views that must see a voxel.
  int outlier_views = 0;         // views whose "outside" a voxel may overrule (VisualHullOptions).
  bool support = false;          // the hull was cut at a support plane (VisualHullOptions).
  double support_contact = 0.0;  // its contact band's height (scene units), 0 without a support.
  int inside_voxels = 0;         // voxels inside the hull.
  int extracted_triangles = 0;
  SurfaceCleanupReport cleanup;
  int faces = 0;                 // output faces.
  int vertices = 0;              // output vertices.
  int points = 0;                // sparse points checked.
  int points_outside = 0;        // farther than one voxel outside the hull.
  int points_outside_box = 0;    // of those, outside the carving box altogether.
  int points_inside = 0;         // deeper than kInsidePointVoxels voxels inside.
  double carve_seconds = 0.0;    // both passes of the field.
  double extract_seconds = 0.0;  // OpenVDB extraction and the clean-up.
  double decimate_seconds = 0.0;
  double total_seconds = 0.0;
};

// Loads every view's mask and prepares it for carving (in parallel). Errors: a view without a
// mask ("... sft init needs a mask for every view ..."), an unreadable or wrongly sized mask, an
// empty mask (naming the view).
Status LoadCarvingViews(const Dataset& dataset, std::vector<CarvingView>* views);
// The same for the listed dataset views only (in that order): the masks of the others are neither
// read nor checked.
Status LoadCarvingViews(const Dataset& dataset, const std::vector<int>& indices,
                        std::vector<CarvingView>* views);

// Sets `hull`'s support from the dataset's support_plane (no support when it has none).
void UseDatasetSupport(const Dataset& dataset, VisualHullOptions* hull);

// Carves, extracts, cleans and decimates; compares `sparse_points` (may be empty) with the hull.
Status MakeInitialMesh(const std::vector<CarvingView>& views, const InitialMeshOptions& options,
                       const std::vector<Eigen::Vector3d>& sparse_points, TriMesh* mesh,
                       InitialMeshReport* report);

}  // namespace sft

#endif  // SFT_INIT_INITIAL_MESH_H_
