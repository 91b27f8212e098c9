// Automatic object masks (`--masks auto` of `sft import colmap`; docs/import.md "Automatic
// masks"): each view is segmented with OpenCV's GrabCut, seeded by the projections of the sparse
// points near the object. After the import's normalisation the object's box is centred on the
// origin with a unit diagonal, so the seeds are the sparse points within `seed_radius` of the
// origin that lie in front of the camera and inside the image.
//
// Seeding per view (GrabCut labels): a disc of `seed_disc_px` around each seed is definite
// foreground; the seeds' convex hull is probable foreground; a ring around the hull of
// `ring_fraction` × the hull's size is probable background; everything beyond it and a border strip
// of `border_px` is definite background. GrabCut (colour GMMs + graph cut) then runs
// `iterations` times on the view's image tone-mapped to 8-bit sRGB, and the connected component
// holding most seeds is kept, holes filled.
//
// Background consistency (src/capture/background_consistency.h), when the views can be compared: a
// pixel whose colour matches what the other views see of the background behind it (on the support
// plane, or far away) is definite background; one in the ring around the seeds' hull whose colour
// does not match is probable foreground. So the feet of an object, whose sparse points the support
// plane's band removes, are not lost to the ring, and the floor between the legs is not kept
// because it lies inside the seeds' hull.
//
// Limits: seeds that fall on background (a sparse point in the box that belongs to the table or
// the wall) become definite foreground; parts of the object with no sparse points and colours like
// the background are lost; an object larger than ring_fraction beyond its points' hull is cut.
#ifndef SFT_CAPTURE_AUTO_MASKS_H_
#define SFT_CAPTURE_AUTO_MASKS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/capture/background_consistency.h"
#include "src/capture/support_plane.h"
#include "src/core/image.h"
#include "src/core/status.h"
#include "src/io/dataset.h"

namespace sft {

struct AutoMaskOptions {
  double seed_radius = 0.55;    // sparse points within this distance of the origin seed, (0, 10].
  int seed_disc_px = 2;         // definite-foreground disc radius around a seed, [0, 50] pixels.
  double ring_fraction = 0.25;  // probable-background ring / hull size, [0, 2].
  int border_px = 3;            // definite-background border strip, [0, 1000] pixels.
  int iterations = 5;           // GrabCut iterations, [1, 50].
  int min_seeds = 8;            // fewer seeds in a view is an error, >= 3.
  bool quiet = false;           // no progress line.
  // Background consistency's thresholds on its distance (display values, max over channels):
  // below `background_distance` definite background; in the ring around the seeds' hull, above
  // `object_distance` (at least background_distance) probable foreground. background_distance 0
  // turns consistency off.
  double background_distance = 0.06;         // [0, 1].
  double object_distance = 0.15;             // [0, 1].
  BackgroundConsistencyOptions consistency;  // how the distances are computed.
  // Segmentations with consistency, [1, 4]: each after the first computes the distances again
  // with the previous masks as visibility (a background sample that another view's mask covers
  // is left out; src/capture/background_consistency.h).
  int passes = 3;

  bool Check(std::string* why) const;
};

// Segments view `index` of `dataset` (world frame normalised, docs/import.md) using the world
// points `sparse` and the view's background distances (BackgroundDistances; nullptr = none);
// `mask` becomes a 1-channel image of 0/1 of the camera's size.
Status AutoMask(const Dataset& dataset, int index, const std::vector<Eigen::Vector3d>& sparse,
                const AutoMaskOptions& options, const Image* background_distance, Image* mask);

// Segments every view, with background consistency against `plane` (the support plane in the
// dataset's world frame; nullptr = none) unless options.background_distance is 0 or there is one
// view, and writes ROOT/masks/STEM.png (0/255) for each, setting views[i].mask,
// where ROOT is dataset->root and STEM the view image's path below images/ without extension.
// The caller writes scene.json.
Status WriteAutoMasks(Dataset* dataset, const std::vector<Eigen::Vector3d>& sparse,
                      const SupportPlane* plane, const AutoMaskOptions& options);

// Intersection over union of two 0/1 masks of the same size (1 when both are empty).
double MaskIoU(const Image& a, const Image& b);

}  // namespace sft

#endif  // SFT_CAPTURE_AUTO_MASKS_H_
