// Aligning a 360° light probe to a dataset (docs/import.md "Probe alignment"): the rotation
// world_from_env that takes the probe's env frame (docs/dataset.md, src/render/environment.h) into
// the dataset's world frame, which for an imported capture is COLMAP's arbitrary frame.
//
// Method: the probe is cut into perspective crops (virtual pinhole views on a Fibonacci sphere of
// directions, field of view and pixel size like the dataset's cameras, limited by the probe's own
// resolution). SIFT features (OpenCV features2d) of the crops are matched against those of the
// frames' background (outside the dilated masks when the views have masks), with Lowe's ratio
// test. Each match is a pair of unit directions: the crop pixel's ray in the env frame and the
// frame pixel's ray in the world frame (camera model unprojection incl. distortion, then
// cam_from_world's rotation; the environment is at infinity, so positions do not matter). A
// RANSAC over 2-match minimal sets (Kabsch/Wahba on two direction pairs) finds the rotation with
// the most matches within `inlier_angle_deg`; Kabsch on all inliers then refines it. Images are
// compared on log luminance, which makes the probe's unknown intensity scale an additive offset
// that SIFT's gradient-based descriptors ignore.
//
// Limits: the frames' background must show the same distant surroundings as the probe (parallax
// from nearby objects shows up as residual angle); the object itself is excluded only by masks;
// repeated structure or a probe taken elsewhere gives few consistent matches, which is reported as
// an error (fewer than `min_inliers`), never as a rotation.
#ifndef SFT_CAPTURE_PROBE_ALIGNMENT_H_
#define SFT_CAPTURE_PROBE_ALIGNMENT_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "src/core/status.h"
#include "src/io/dataset.h"

namespace sft {

struct ProbeAlignmentOptions {
  int max_views = 24;             // frames used (evenly spaced over the views), [1, 10000].
  int crops = 0;                  // probe crops; 0 = enough to cover the sphere, else [6, 500].
  double crop_fov_deg = 0.0;      // crop field of view; 0 = the cameras' mean, else [20, 120].
  double ratio = 0.8;             // Lowe's ratio test threshold, (0, 1].
  double inlier_angle_deg = 1.5;  // RANSAC inlier threshold between directions, (0, 20].
  int ransac_iterations = 2000;   // RANSAC trials, [1, 1e6].
  int min_inliers = 15;           // fewer inliers is an error (probe does not match), >= 3.
  int mask_dilation_px = 4;       // masks grown by this before excluding the object, [0, 100].
  uint64_t seed = 1;              // RANSAC random seed.
  bool quiet = false;             // no progress line.

  bool Check(std::string* why) const;
};

struct ProbeAlignmentResult {
  Eigen::Matrix3d world_from_env = Eigen::Matrix3d::Identity();
  int views_used = 0;              // frames whose features were matched.
  int crops = 0;                   // probe crops rendered.
  int matches = 0;                 // ratio-test matches (direction pairs).
  int inliers = 0;                 // matches within inlier_angle_deg of the final rotation.
  double median_residual_deg = 0;  // median angle between R·env and world over the inliers.
  double rotation_angle_deg = 0;   // angle of world_from_env (for the summary).
};

// Finds world_from_env for environment light `light_index` of `dataset` (its stored
// world_from_env is ignored). Errors: no environment light at that index, unreadable images, no
// features, or fewer than min_inliers consistent matches ("the probe does not match the frames").
Status AlignProbe(const Dataset& dataset, int light_index, const ProbeAlignmentOptions& options,
                  ProbeAlignmentResult* result);

// The "lighting" text recorded in scene.json for an aligned probe.
std::string AlignedProbeLighting(const ProbeAlignmentResult& result);

}  // namespace sft

#endif  // SFT_CAPTURE_PROBE_ALIGNMENT_H_
