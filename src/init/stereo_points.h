// Dense oriented surface points from calibrated photographs: two-view stereo between each view and
// its nearest neighbours, by semi-global matching (Hirschmüller, "Stereo Processing by Semiglobal
// Matching and Mutual Information", PAMI 2008; OpenCV's StereoSGBM) on rectified pairs (OpenCV's
// stereoRectify, Bouguet's method), with a depth kept only where two pairs of the same view agree.
//
// Why. A visual hull cannot see concavities: a ring of silhouettes fills a dinosaur's neck, arms
// and the space between its legs, and the shading-driven stages only move a surface locally. Stereo
// sees what the photographs' texture and shading show from two nearby viewpoints. Where the object
// has neither (a uniform, evenly lit patch) the matching cost is flat and semi-global matching
// fills in from the neighbours; the cross-pair check removes what stays ambiguous.
//
// Per view a:
//  1. Partners: the views whose direction from the object's centre makes an angle with a's in
//     [min_angle_deg, max_angle_deg], the closest first, at most `pairs_per_view`.
//  2. Each pair (a, b) is rectified (the cameras' distortion removed with OpenCV's Brown model,
//     which is ours: SIMPLE_RADIAL, RADIAL and OPENCV map to k1, k2, p1, p2), turned so that its
//     epipolar lines are rows, and matched in 8-bit grey (the linear values sRGB-encoded, so that
//     dark surfaces keep their contrast). The disparity search covers the depths of the object's
//     box seen from a, and the images are padded so that no part of the object falls in
//     StereoSGBM's unsearched border.
//  3. Every pixel of a's mask looks its disparity up in the rectified grid (its rectified position
//     from OpenCV's undistortPoints; bilinear where the four neighbours agree within a pixel, else
//     the nearest) and becomes a depth along its own ray.
//  4. A pixel of a's mask (when a has one) keeps a depth when at least `min_agreeing_pairs` pairs
//     give depths within `consistency_pixels` of disparity of their median (measured on the
//     pair with the shortest baseline, whose depths are the least certain: z² / (f · baseline)
//     per pixel); the point is on a's ray through the pixel centre at the mean of those depths.
//  5. Normals from the depth map's central differences, turned towards the camera (the side the
//     camera sees is outside, as in view_samples.h).
//
// Units: positions in scene units, depths along the camera's z axis. Pixel (x, y) covers [x, x+1] ×
// [y, y+1] (src/render/camera.h); OpenCV's pixel centres are integers, so principal points move by
// ½ on the way in.
//
// Limits. Two-view stereo on a textureless, evenly lit surface has nothing to match; specular
// highlights move between views and give wrong depths, which the cross-pair check removes only
// when the pairs disagree. Views with lights that move with the camera change the shading between
// the views of a pair, which weakens the match.
#ifndef SFT_INIT_STEREO_POINTS_H_
#define SFT_INIT_STEREO_POINTS_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/init/view_samples.h"
#include "src/render/camera.h"

namespace sft {

struct StereoOptions {
  // Partners matched per view, [2, 8] (the cross-pair check needs two).
  int pairs_per_view = 2;
  // Angle (degrees) at the object's centre between the two views of a pair, seen from the centre:
  // small angles give ambiguous depths, large ones views too different to match, (0, 90].
  double min_angle_deg = 3.0;
  double max_angle_deg = 20.0;
  // Matching window side (pixels, odd), [3, 11].
  int block_size = 5;
  // Depth tolerance between the pairs of one view, in pixels of disparity of its shortest-baseline
  // pair: depths agree when they differ by less than the depth this many pixels of disparity span
  // there (z² / (f · baseline)), (0, 16].
  double consistency_pixels = 1.0;
  // Pairs of a view that must agree for a pixel to keep its depth (any of its pairs; the median
  // of their depths decides which agree), [2, pairs_per_view].
  int min_agreeing_pairs = 2;
  // Match at 2^-image_scale_log2 of the images' resolution (0 = full), [0, 4].
  int image_scale_log2 = 0;

  // False with the option in *why ("block_size: must be odd and in [3, 11], got 4").
  bool Check(std::string* why) const;
};

// One view: its camera and pose, its image (linear RGB or grey; any channel count ≥ 1, the camera's
// size) and its mask (1 channel, > 0.5 = object; empty = every pixel).
struct StereoView {
  std::string name;  // for messages.
  Camera camera;
  Rigid3d cam_from_world;
  Image image;
  Image mask;
};

struct StereoReport {
  int views = 0;               // views given.
  int pairs = 0;               // pairs matched.
  int views_without_pair = 0;  // views with fewer than min_agreeing_pairs partners in range.
  int64_t matched_pixels = 0;  // valid disparities inside the masks, over all pairs.
  int64_t points = 0;          // pixels that kept a depth (the result's size).
  double seconds = 0.0;
};

// Points of the surface seen by `views`, whose object lies in `object_box` (world frame; it bounds
// the disparity search). Runs the views in parallel (TBB), each with its pairs. Errors (no
// exception escapes): invalid options; fewer than 3 views; an invalid camera; a view whose image or
// mask does not have its camera's size; an empty box.
Status ComputeStereoPoints(const std::vector<StereoView>& views,
                           const Eigen::AlignedBox3d& object_box, const StereoOptions& options,
                           std::vector<OrientedPoint>* points, StereoReport* report);

}  // namespace sft

#endif  // SFT_INIT_STEREO_POINTS_H_
