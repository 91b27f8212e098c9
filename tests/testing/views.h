// Small scene-building helpers shared by the renderer's tests.
#ifndef SFT_TESTS_TESTING_VIEWS_H_
#define SFT_TESTS_TESTING_VIEWS_H_

#include <Eigen/Core>
#include <vector>

#include "src/render/render.h"

namespace sft {
namespace testing {

// A square pinhole view, res × res pixels, focal length `focal` in pixels and the principal point
// at the image centre, at `eye` looking at `target` with world `up`. No lights.
ViewSetup LookAtView(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, int res,
                     double focal, const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

// A camera at height h above the origin looking down −z (world), res × res pixels, focal length
// `focal` pixels: camera x = world +x, camera y = world −y.
ViewSetup TopDownView(double height, int res, double focal);

// The square [−half, half]² in the z = 0 plane as two triangles (normal +z).
std::vector<Eigen::Vector3d> QuadPositions(double half);
std::vector<Eigen::Vector3i> QuadFaces();

// Appends a white point light of `intensity` W/sr per channel at `position` (world).
void AddPointLight(const Eigen::Vector3d& position, double intensity, ViewSetup* view);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_VIEWS_H_
