// The cameras of the IDR / NeuS datasets (DTU, BlendedMVS in their layout): cameras.npz holds, per
// image i (the i-th image of the image folder in sorted order), world_mat_i = [K·[R|t]; 0 0 0 1]
// (4×4, or its top 3×4), the projection of the dataset's world frame, and scale_mat_i, the
// similarity whose image of the unit sphere holds the object (the same for every image; IDR
// renders in that sphere's frame). camera_mat_i and *_inv members are ignored. Pure conversion of
// parsed arrays (npz.h), for the fuzz target.
#ifndef SFT_IO_IDR_CAMERAS_H_
#define SFT_IO_IDR_CAMERAS_H_

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/io/npy.h"
#include "src/io/pinhole_matrices.h"

namespace sft {

struct IdrCameras {
  std::vector<PinholeCalibration> views;  // from world_mat_0, world_mat_1, ... in order.
  bool has_sphere = false;                // scale_mat_0 was present.
  Eigen::Vector3d sphere_centre = Eigen::Vector3d::Zero();  // scale_mat_0's translation (world).
  double sphere_radius = 0;                                 // scale_mat_0's scale (world units).
};

// Converts the arrays of a cameras.npz: world_mat_0 .. world_mat_{n-1} must all be present (n ≥
// 1, no gap), of shape (4, 4) or (3, 4), and decompose into K, R, t (DecomposeProjectionMatrix);
// scale_mat_0, when present, must be (4, 4) of the form [s·I c; 0 1] with s > 0. Errors name
// `file` and the array ("cameras.npz: world_mat_3: shape (3, 3), expected (4, 4) or (3, 4)").
Status IdrCamerasFromArrays(const std::map<std::string, NpyArray>& arrays, const std::string& file,
                            IdrCameras* cameras);

}  // namespace sft

#endif  // SFT_IO_IDR_CAMERAS_H_
