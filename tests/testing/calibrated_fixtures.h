// Calibrated captures written by tests from a dataset made by `sft synth` (whose cameras and
// poses are the truth): the same views as a NeRF transforms.json, an IDR cameras.npz (with
// images and masks in IDR's folders) and a Middlebury _par.txt, for the importers' tests.
#ifndef SFT_TESTS_TESTING_CALIBRATED_FIXTURES_H_
#define SFT_TESTS_TESTING_CALIBRATED_FIXTURES_H_

#include <Eigen/Core>
#include <string>

#include "src/io/dataset.h"

namespace sft {
namespace testing {

// The PINHOLE intrinsics of `camera` as K in sft's pixel convention plus `offset` on cx, cy (−0.5
// gives the convention whose pixel centres are integers, as Middlebury and IDR files use).
Eigen::Matrix3d IntrinsicsOf(const Camera& camera, double offset);

// DIR/images/transforms.json: one frame per view of `dataset` (file_path "NNN" without extension,
// relative to DIR/images), per-frame fl_x, fl_y, cx, cy, w, h; returns its path.
std::string WriteNerfTransforms(const Dataset& dataset);

// DIR/images/par.txt in Middlebury's format for every view of `dataset` plus one entry whose image
// does not exist ("missing.png"); `rotated_view` (≥ 0) is replaced by a copy of its image rotated
// by 90° clockwise in the image plane ("rotated.exr", written next to the images) with the camera
// and pose that describe it. Returns the path.
std::string WriteMiddleburyPar(const Dataset& dataset, int rotated_view);

// DIR/idr/cameras.npz (world_mat_i = λᵢ·[K[R|t]; 0 0 0 1] with λᵢ of both signs, scale_mat_0 =
// a sphere of radius `sphere_radius` at the origin), DIR/idr/image/aNNN.exr and
// DIR/idr/mask/mNNN.png (copies of the dataset's images and masks, named differently so that only
// their sorted order pairs them). Returns the folder DIR/idr.
std::string WriteIdrFolder(const Dataset& dataset, double sphere_radius);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_CALIBRATED_FIXTURES_H_
