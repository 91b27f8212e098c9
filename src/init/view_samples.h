// Oriented surface samples seen from camera views (the first stage of surface resampling,
// resample.h): one ray per pixel block of every view, the first hit's position and the geometric
// normal of the hit face turned towards the camera; then thinning to one sample per grid cell and
// normal direction so that the Poisson solve (poisson_grid.h) costs what the target resolution
// needs rather than what the number of views gives.
//
// Why the normal faces the camera. A surface point that a camera sees from outside the object has
// the outside of the object on the camera's side, whatever the winding of the face that was hit:
// a first hit on a back face is a face of a fold or tangle whose winding disagrees with the
// surface it belongs to. The camera-facing normal is therefore the outward normal of the visible
// surface, which is what Poisson reconstruction (Kazhdan et al. 2006) needs: it integrates the
// normals as the gradient of the inside/outside indicator, so a flipped normal would carve a
// pocket where the surface is. Trusting the winding instead would copy the fold into the result.
//
// Units: positions in the scene's units; normals unit length. Pixel conventions as in
// src/render/camera.h (pixel (x, y) covers [x, x+1] × [y, y+1]).
#ifndef SFT_INIT_VIEW_SAMPLES_H_
#define SFT_INIT_VIEW_SAMPLES_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {

struct OrientedPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, outward (towards the camera).
};

struct ViewSamplesReport {
  int64_t rays = 0;            // camera rays cast (pixel blocks with a valid ray).
  int64_t hits = 0;            // rays that hit a non-degenerate face.
  int64_t back_face_hits = 0;  // of those, first hits on a face whose winding faces away.
  int views_with_hits = 0;     // views that saw the mesh at least once.
};

// Casts one ray through the centre of every pixel_stride × pixel_stride block of pixels of every
// view (blocks cut by the image border included, through the centre of their inside part) against
// `scene`, in parallel over views and rows (TBB). Hits on degenerate faces (zero normal) are
// skipped. The samples are ordered by view, row and column, whatever the thread count.
void CastViewSamples(const RenderScene& scene, const std::vector<ViewSetup>& views,
                     int pixel_stride, std::vector<OrientedPoint>* samples,
                     ViewSamplesReport* report);

// Keeps one sample per cubic cell of side `cell` (scene units, > 0) and per dominant normal
// direction (±x, ±y, ±z): the sample closest to the cell's centre, earliest on ties. Keying on
// the normal's direction keeps both sides of a sheet thinner than a cell, which one sample per
// cell would merge into one side. The result is ordered by first occurrence in `samples`.
std::vector<OrientedPoint> ThinSamples(const std::vector<OrientedPoint>& samples, double cell);

}  // namespace sft

#endif  // SFT_INIT_VIEW_SAMPLES_H_
