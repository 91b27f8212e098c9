// Where the object is in an imported sparse reconstruction, for the normalisation that `sft
// synth` applies (centred on the bounding-box centre, bounding-box diagonal 1). docs/import.md
// describes the method and its limits.
//
// With masks: a sparse point belongs to the object when it projects inside the mask in most
// (more than half) of the views that observe it; the box is the exact bounds of those points.
// Without masks: a view sees a point "near its optical axis" when the point lies in front of the
// camera and its normalised image coordinates (x/z, y/z) fall inside the ellipse whose semi-axes
// are `axis_cone` times the half-image's extent (w/(2 fx), h/(2 fy)); a point belongs to the
// object when at least half of its observing views see it that way, unless it lies on or beyond
// the support plane (src/capture/support_plane.h: a table top or floor under the object, whose
// points every view also sees near its axis); the box runs from the `percentile`-th to the (100 −
// percentile)-th percentile of those points on each axis, so stray points do not stretch it.
#ifndef SFT_CAPTURE_IMPORT_NORMALIZATION_H_
#define SFT_CAPTURE_IMPORT_NORMALIZATION_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "src/capture/support_plane.h"
#include "src/core/status.h"
#include "src/io/colmap_model.h"
#include "src/render/camera.h"

namespace sft {

// A binary mask: inside[y * width + x] != 0 where the pixel shows the object.
struct MaskBits {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> inside;
};

// One registered view of the model, as the normalisation sees it.
struct ObservingView {
  Camera camera;
  Rigid3d cam_from_world;          // in the model's frame.
  const MaskBits* mask = nullptr;  // null without masks.
};

struct NormalizationOptions {
  // Without masks: the cone around each optical axis, as a fraction of the half-image, (0, 1].
  double axis_cone = 0.5;
  // Without masks: the robust box's lower percentile per axis, [0, 50).
  double percentile = 2.0;
  // Fewest object points accepted, >= 1.
  int min_points = 8;
  // Without masks: the support plane whose points are not the object.
  SupportPlaneOptions plane;

  // Errors name the command-line flags of `sft import colmap` (--axis-cone, --percentile).
  bool Check(std::string* why) const;
};

struct NormalizationResult {
  std::string method;                                // "masks" or "optical_axes".
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // box centre in the model's frame.
  double diagonal = 0;                               // box diagonal in the model's units (> 0).
  int points_total = 0;                              // sparse points with a non-empty track.
  int points_used = 0;                               // object points that define the box.
  std::vector<bool> used;                            // parallel to model.points.
  SupportPlane plane;  // without masks: the support plane, in the model's frame (or not found).
};

// `views` maps COLMAP image ids to views; track elements of other images are ignored. Errors:
// fewer than min_points object points, or a box with zero diagonal.
Status ComputeNormalization(const ColmapModel& model,
                            const std::unordered_map<uint32_t, ObservingView>& views,
                            const NormalizationOptions& options, NormalizationResult* result);

}  // namespace sft

#endif  // SFT_CAPTURE_IMPORT_NORMALIZATION_H_
