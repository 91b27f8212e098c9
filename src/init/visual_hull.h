// Visual-hull carving from masks (docs/init.md): the signed field whose negative part is the set of
// points that project inside the mask of every view that sees them.
//
// The field. Each view's mask becomes a signed distance map in pixels (negative inside, zero
// half-way between an object pixel's centre and a background pixel's centre; OpenCV's exact
// Euclidean distance transform). A point p seen by a view (in front of it, inside its image, and
// not past the fold of its distortion) gets from that view the map's bilinear value at p's
// projection (camera model with distortion, src/render/camera.h) times depth / focal length: the
// distance to the view's silhouette cone measured across the line of sight, in world units. The
// hull is the intersection of the cones, so the field is the maximum over the views that see p,
// clamped to ±kBandVoxels voxels. Its zero level set is the hull's surface exactly (up to the
// bilinear interpolation of the maps); away from it the values approximate a distance, which is
// what gives the extracted surface sub-voxel positions instead of voxel steps.
//
// Who carves. A view that does not see p says nothing about it. A point seen by fewer than
// `min_views` views is outside: a single cone is unbounded, so a point that only one or two views
// see is not evidence of the object (e.g. the far corners of the box). With `outlier_views` t > 0
// the field is the (t+1)-th largest value instead of the maximum: the t views that put p farthest
// outside are overruled (a robust visual hull; its zero level set is where all but t of the
// seeing views agree).
//
// The support. A capture's object usually stands on a plane (a table top, the floor; the dataset's
// `support_plane`, docs/dataset.md). With one, nothing below the plane is in the hull (the field is
// at least the point's depth below it), and a contact band of height `support_contact` above it
// takes the cross-section at the band's top down to the plane: a point in the band is inside when
// it or the point above it at the band's top is. Masks lose an object's lowest part more often than
// any other (dark feet or a base against their own contact shadow, thresholded or segmented as
// background); the band gives back what the silhouettes higher up already show, and costs, on an
// object that narrows towards the support (a sphere, a belly), at most the band's height of
// the cross-section's overhang.
//
// The carving box. A coarse pass (kCoarseResolution³ voxels) evaluates the same field over the
// generous box [-bounds, bounds]³ (datasets are normalised: the object is centred with a
// bounding-box diagonal of ~1). The box is the bounding box of the coarse voxels whose value is
// below half a coarse voxel diagonal (those that may touch the hull), grown by one coarse voxel
// and clipped to the generous box. The fine grid has `resolution` cubic voxels along the box's
// longest side.
#ifndef SFT_INIT_VISUAL_HULL_H_
#define SFT_INIT_VISUAL_HULL_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/progress.h"
#include "src/core/status.h"
#include "src/render/camera.h"

namespace sft {

struct VisualHullOptions {
  // Voxels along the longest side of the carving box, [16, 1024].
  int resolution = 128;
  // A point must be seen by at least this fraction of the views (rounded up, at least 2 and at
  // least outlier_views + 2, at most all views) to be part of the hull, (0, 1].
  double min_view_fraction = 0.25;
  // Half side of the generous box [-bounds, bounds]³ that is carved (scene units), > 0.
  double bounds = 1.0;
  // Views whose verdict "outside" a point may overrule, [0, kMaxOutlierViews]: a point stays in
  // the hull unless more than this many of the views that see it put it outside their masks. 0 is
  // the exact visual hull; 1 or 2 keep object parts that one or two wrong masks cut away (a
  // shadow thresholded as background, a GrabCut miss), at the price of what only that many views
  // would have carved.
  int outlier_views = 0;
  // The plane the object stands on (see the file comment); used when has_support.
  bool has_support = false;
  Eigen::Vector3d support_normal = Eigen::Vector3d::UnitZ();  // unit, towards the object.
  Eigen::Vector3d support_point = Eigen::Vector3d::Zero();    // a point of the plane.
  // Height of the contact band above the support (scene units), [0, bounds]; 0: no band (the
  // plane still cuts). Ignored without a support. The default was measured on the video road's
  // automatic masks (docs/init.md, "The support").
  double support_contact = 0.05;

  static constexpr int kMaxOutlierViews = 8;

  static constexpr int kMinResolution = 16;
  static constexpr int kMaxResolution = 1024;

  // False with the field in *why ("resolution: must be in [16, 1024], got 8").
  bool Check(std::string* why) const;
};

// Field values are clamped to ± this many fine voxels (the narrow band of the level set).
constexpr double kBandVoxels = 3.0;
// Voxels along each side of the coarse pass that finds the carving box.
constexpr int kCoarseResolution = 64;

// One view prepared for carving.
struct CarvingView {
  std::string name;  // for messages ("views[3] (masks/003.png)").
  Camera camera;
  Rigid3d cam_from_world;
  std::vector<float> distance;  // signed distance map in pixels, width × height, row-major.
  double world_per_pixel_at_unit_depth = 0.0;  // 1 / mean focal length.
  double max_radius = 0.0;  // Camera::MaxUndistortedRadius (normalized coordinates).
};

// Prepares a view from its 0/1 mask (1 channel, the camera's size). An all-background mask is an
// error naming the view: it says the object is nowhere, which would carve everything it sees.
Status MakeCarvingView(const std::string& name, const Camera& camera, const Rigid3d& cam_from_world,
                       const Image& mask, CarvingView* view);

// An axis-aligned grid of cubic voxels; voxel (i, j, k)'s centre is lo + (i + ½, j + ½, k + ½)·h.
struct VoxelBox {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();
  double voxel_size = 0.0;
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();

  int64_t NumVoxels() const { return int64_t{dims.x()} * dims.y() * dims.z(); }
  Eigen::Vector3d Centre(int i, int j, int k) const {
    return lo + voxel_size * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
  }
};

struct VisualHull {
  VoxelBox box;
  // Field values (scene units, negative inside), x fastest: index (k·ny + j)·nx + i.
  std::vector<float> field;
  double band = 0.0;      // |field| ≤ band (scene units).
  int min_views = 0;      // views that must see a point (from min_view_fraction).
  int inside_voxels = 0;  // voxels with a negative value.
};

// Bytes that carving at `resolution` needs for views with `view_pixels` pixels in all (an upper
// bound: the fine field as a cube of resolution³, its OpenVDB copy, the masks and distance maps).
uint64_t EstimateCarvingBytes(int64_t view_pixels, int resolution);

// Carves: coarse pass for the box, then the fine field (parallel over z slices with TBB; one
// progress unit per slice of both passes, total kCoarseResolution + resolution). Error when the
// hull is empty (masks and cameras agree on no point of the generous box).
Status CarveVisualHull(const std::vector<CarvingView>& views, const VisualHullOptions& options,
                       Progress* progress, VisualHull* hull);

// The field at `p` by trilinear interpolation of the voxel values; +band outside the box.
double SampleHull(const VisualHull& hull, const Eigen::Vector3d& p);

// The zero level set as triangles (OpenVDB's volumeToMesh on the field stored as an OpenVDB grid;
// quads split along their shorter diagonal), vertices in scene units. OpenVDB exceptions become
// an error Status.
Status ExtractHullSurface(const VisualHull& hull, std::vector<Eigen::Vector3d>* points,
                          std::vector<Eigen::Vector3i>* triangles);

}  // namespace sft

#endif  // SFT_INIT_VISUAL_HULL_H_
