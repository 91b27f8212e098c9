// The plane an imported object stands on (a table top, the floor) or in front of (a wall), found
// among the sparse points so that it is not taken for the object (docs/import.md "Normalisation").
// SfM needs near-field texture for parallax, so a textured support is the usual capture, and its
// points, seen near every optical axis around the object, would otherwise define the object's box
// and seed the automatic masks.
//
// Method: RANSAC over 3-point samples for the plane with the most points within `distance` ×
// the median viewing distance (camera centre to the median sparse point), then a least-squares
// refit (PCA) on those points. It counts as a support when it holds at least `min_fraction` of
// the points and at least `camera_fraction` of the camera centres lie on one side of it, more
// than the band away; the normal then points to that side. Points within the band or on the far
// side are "off the object".
//
// Limits: an object that is itself mostly one plane (a book, a painting) with few points around
// it can be taken for the support; a support with too little texture has too few points to be
// found (then nothing changes).
#ifndef SFT_CAPTURE_SUPPORT_PLANE_H_
#define SFT_CAPTURE_SUPPORT_PLANE_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace sft {

struct SupportPlaneOptions {
  bool enabled = true;           // look for a support plane at all.
  double distance = 0.02;        // band half-width / median viewing distance, (0, 0.2].
  double min_fraction = 0.2;     // fewest points on the plane, fraction of all, (0, 1].
  double camera_fraction = 0.9;  // fewest cameras on its positive side, fraction, (0.5, 1].
  int iterations = 1000;         // RANSAC trials, [1, 1e6].
  uint64_t seed = 1;             // RANSAC random seed.
  // With a probe: the plane, when found, is a black floor under the object that the probe does
  // not show (the probe's LightSpec::ground_normal = the plane's normal): for a probe taken away
  // from the object's support, e.g. a studio or sky panorama. Off for a probe taken where the
  // object stands, whose lower half already shows the support.
  bool hides_probe = false;

  bool Check(std::string* why) const;
};

struct SupportPlane {
  bool found = false;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, towards the cameras.
  double offset = 0;   // signed distance of p: normal·p + offset (> 0 on the cameras' side).
  double band = 0;     // points with signed distance <= band are off the object.
  int inliers = 0;     // points within ±band.
  int off_object = 0;  // points within the band or beyond the plane.

  double SignedDistance(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
  bool OffObject(const Eigen::Vector3d& p) const { return found && SignedDistance(p) <= band; }
};

// Looks for the support plane of `points` seen from `camera_centres` (same frame). Returns a
// plane with found = false when there is none (too few points, no dominant plane, cameras on
// both sides, or options.enabled false).
SupportPlane FindSupportPlane(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Eigen::Vector3d>& camera_centres,
                              const SupportPlaneOptions& options);

// The support as a disc for `--probe-ground`: its centre is `object_centre` projected onto the
// plane, its radius the `quantile` of the in-plane distances from that centre of the points
// within the plane's band (the support's texture as far as SfM triangulated it). A table top
// ends where its points end; a floor's points spread as far as the views see it. False when the
// plane was not found or holds no point.
bool FindSupportDisc(const SupportPlane& plane, const std::vector<Eigen::Vector3d>& points,
                     const Eigen::Vector3d& object_centre, double quantile, Eigen::Vector3d* centre,
                     double* radius);

}  // namespace sft

#endif  // SFT_CAPTURE_SUPPORT_PLANE_H_
