// Middlebury multi-view stereo camera files (X_par.txt, vision.middlebury.edu/mview/data): the
// first line is the number of images, then one line per image
//   imgname.png k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3
// with the projection matrix P = K·[R|t] (world to image, p_cam = R·X + t; the image origin at the
// top left, x to the right, y down). Pure parsing (core and Eigen only, for the fuzz target).
#ifndef SFT_IO_MIDDLEBURY_PAR_H_
#define SFT_IO_MIDDLEBURY_PAR_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/io/pinhole_matrices.h"
#include "src/render/camera.h"

namespace sft {

struct MiddleburyEntry {
  std::string image;  // the image's name, relative to the file's folder (no "..", not absolute).
  Eigen::Matrix3d intrinsics = Eigen::Matrix3d::Identity();  // K as written.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();    // R as written (checked later).
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();     // t.
  int line = 0;                                              // 1-based line in the file.
};

// More entries than this in the count line is an error (the full Middlebury sets have 363).
constexpr int kMaxMiddleburyEntries = 1000000;

// Parses the file's contents; `file` prefixes the errors ("dino_par.txt: line 5: expected 22
// fields (name, K, R, t), got 21"). Blank lines are skipped; the count must equal the number of
// entries; numbers must be finite; names must be relative paths without "..".
Status ParseMiddleburyPar(const std::string& text, const std::string& file,
                          std::vector<MiddleburyEntry>* entries);

// The camera of one entry: PINHOLE, `width` × `height`, the file's pixel centres at integer
// coordinates (so cx, cy + 0.5 in sft's convention). Errors name the file, line and image: a K
// that is not a pinhole without skew.
Status MiddleburyCamera(const MiddleburyEntry& entry, const std::string& file, int width,
                        int height, Camera* camera);

// The cam_from_world of one entry (p_cam = R·X + t). Error naming the file, line and image when R
// is not a rotation.
Status MiddleburyPose(const MiddleburyEntry& entry, const std::string& file,
                      Rigid3d* cam_from_world);

}  // namespace sft

#endif  // SFT_IO_MIDDLEBURY_PAR_H_
