// Where the object is, for importers of calibrated captures that have no sparse points (NeRF,
// IDR, Middlebury; docs/import.md "Calibrated formats: normalisation"). The result is an
// axis-aligned box in the capture's own frame, which the importer maps to the dataset's world
// (centred at the origin, diagonal 1).
//
// 1. A search frame: the cameras of an object capture look at the object, so the point nearest to
//    all optical axes (least squares) is taken as a centre and the median camera distance from it
//    as a unit. Axes that are (nearly) parallel, or a centre behind most cameras, are an error:
//    the views do not surround an object.
// 2. With a mask for every view: the visual hull (src/init/visual_hull.h, the same carving as `sft
//    init`) over [-1, 1]³ of the search frame, i.e. a cube of ± the median camera distance around
//    the centre, at `resolution` voxels along its carving box's longest side; the object's box is
//    the bounding box of the voxels inside the hull.
// 3. Without masks: a sphere the format gives (IDR's scale_mat: its unit sphere holds the object)
//    when there is one; else the object is assumed to fill the central `axis_cone` of the images:
//    a sphere at the centre whose radius is the median over the views of distance × axis_cone ×
//    the half field of view's tangent (the smaller of x and y). The box is the sphere's.
#ifndef SFT_CAPTURE_OBJECT_BOX_H_
#define SFT_CAPTURE_OBJECT_BOX_H_

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/render/camera.h"

namespace sft {

// One view as the box search sees it.
struct BoxView {
  std::string name;  // for messages.
  Camera camera;
  Rigid3d cam_from_world;  // in the capture's frame.
  Image mask;              // 1 channel 0/1 at the camera's size; empty when there is none.
};

struct ObjectSphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;  // > 0.
};

struct ObjectBoxOptions {
  int resolution = 64;     // carving voxels along the carving box's longest side, [16, 256].
  double axis_cone = 0.5;  // without masks or sphere: the object's share of the image, (0, 1].
  bool quiet = false;      // no progress line.

  bool Check(std::string* why) const;
};

struct ObjectBox {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();  // capture frame.
  Eigen::Vector3d hi = Eigen::Vector3d::Zero();
  // "visual hull of the masks", "sphere of the camera file (scale_mat)" or "optical axes
  // (assumed to fill the central half of the images)".
  std::string method;
  Eigen::Vector3d search_centre = Eigen::Vector3d::Zero();  // step 1's centre.
  double search_unit = 0;                                   // step 1's median camera distance.
  // With masks: the hull reaches the border of the search cube (the masks or the cameras are
  // probably wrong: the object cannot be as large as the camera distance).
  bool touches_search_border = false;
};

// Finds the object's box (see the file comment). `sphere` is the format's bounding sphere, if it
// has one. Errors: options out of range, views that do not converge on an object, an empty hull.
Status FindObjectBox(const std::vector<BoxView>& views, const std::optional<ObjectSphere>& sphere,
                     const ObjectBoxOptions& options, ObjectBox* box);

}  // namespace sft

#endif  // SFT_CAPTURE_OBJECT_BOX_H_
