// NeRF transforms.json files, in the conventions of the original NeRF's Blender scenes, instant-ngp
// and nerfstudio: "frames" lists {"file_path", "transform_matrix"} with the 4×4 camera-to-world
// matrix in OpenGL's camera convention (the camera looks down −z, +y up, +x right); the intrinsics
// are either "camera_angle_x" (horizontal field of view, radians; "camera_angle_y" optional) or
// "fl_x", "fl_y", "cx", "cy", "w", "h" (pixels), given at the top level or per frame (a frame's
// keys win), with optional OpenCV distortion "k1", "k2", "p1", "p2". Other keys (aabb_scale,
// applied_transform, mask_path, ...) are ignored. Pure parsing (JSON, Eigen), for the fuzz target.
//
// Conversion to sft (docs/dataset.md): camera_from_world = (C2W · diag(1, −1, −1, 1))⁻¹, i.e. the
// camera's y and z axes flipped into sft's (and OpenCV's) +z forward, +y down. Principal points
// are taken in sft's pixel convention (nerfstudio and instant-ngp shoot rays through pixel centres
// at +0.5, as sft does); without cx, cy the image centre (w/2, h/2).
#ifndef SFT_IO_NERF_TRANSFORMS_H_
#define SFT_IO_NERF_TRANSFORMS_H_

#include <optional>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/render/camera.h"

namespace sft {

// A frame's intrinsics as written (pixels and radians); what is absent stays empty.
struct NerfIntrinsics {
  std::optional<double> fl_x, fl_y, cx, cy;  // pixels.
  std::optional<double> angle_x, angle_y;    // camera_angle_x / _y: full field of view, radians.
  std::optional<int> w, h;                   // image size the intrinsics refer to, pixels.
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;     // OpenCV radial and tangential distortion.
};

struct NerfFrame {
  std::string file_path;  // as written: relative to the JSON file's folder, maybe no extension.
  NerfIntrinsics intrinsics;
  Rigid3d cam_from_world;  // in sft's camera convention.
};

// Parses transforms.json's contents; `file` prefixes the errors, which name the JSON path
// ("transforms.json: frames[3].transform_matrix: expected 4 rows of 4 numbers"). Checks: valid
// JSON, a non-empty "frames" array, each frame's file_path a relative path without "..", its
// transform_matrix 4×4 finite with last row (0, 0, 0, 1) and a rotation block, numbers where
// numbers belong, w and h positive integers, camera_model absent or OPENCV/PINHOLE/SIMPLE_PINHOLE,
// k3 and k4 absent or 0 (sft's OPENCV model has k1, k2, p1, p2 only).
Status ParseNerfTransforms(const std::string& text, const std::string& file,
                           std::vector<NerfFrame>* frames);

// The camera of a frame whose image is `width` × `height`: focal lengths from fl_x/fl_y (fy = fx
// when only one is given) or the angles, principal point cx, cy or the image centre; PINHOLE, or
// OPENCV with distortion. Errors (prefixed with `where`): no focal length, w/h given but different
// from the image's size.
Status NerfCamera(const NerfIntrinsics& intrinsics, int width, int height, const std::string& where,
                  Camera* camera);

}  // namespace sft

#endif  // SFT_IO_NERF_TRANSFORMS_H_
