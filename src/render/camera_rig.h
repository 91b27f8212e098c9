// Camera placement shared by `sft synth` and the benchmarks: cameras on a Fibonacci sphere around a
// target, looking at it, at the distance where the target's bounding sphere fills a given fraction
// of the half image.
#ifndef SFT_RENDER_CAMERA_RIG_H_
#define SFT_RENDER_CAMERA_RIG_H_

#include <Eigen/Core>

#include "src/render/camera.h"

namespace sft {

// cam_from_world for a camera at `center` looking at `target`, +y of the image pointing as close
// to world −up as possible (COLMAP: x right, y down, z forward). When the viewing direction is
// parallel to `up`, world +y is used instead.
Rigid3d LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
               const Eigen::Vector3d& up);

// Unit direction k of n (0 <= k < n) on a Fibonacci sphere around +z: z = 1 − (2k + 1)/n,
// azimuth k·π(3 − √5).
Eigen::Vector3d FibonacciSphereDirection(int k, int n);

// Distance from the centre of a sphere of `radius` at which a pinhole camera with field of view
// `fov_deg` (full angle, degrees) sees the sphere's radius as `fill` of the half image
// (radius / (fill · tan(fov/2))). Its focal length in pixels is OrbitFocal(resolution, fov_deg).
double OrbitDistance(double radius, double fov_deg, double fill);
double OrbitFocal(int resolution, double fov_deg);

}  // namespace sft

#endif  // SFT_RENDER_CAMERA_RIG_H_
