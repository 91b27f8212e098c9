// A start mesh from stereo (`sft init --stereo`, reconstruct's `"carve": {"stereo": true}`): the
// dense points of stereo_points.h, rebuilt into one closed surface by Poisson reconstruction and
// intersected with the visual hull of the masks (resample.h's steps 2-5). The hull bounds what the
// stereo may add (nothing outside any silhouette); the stereo gives back what the hull cannot see:
// concavities, the space between legs, a neck.
//
// Where stereo finds nothing (a uniform, evenly lit patch; a part seen by one view only), Poisson
// closes the gap smoothly between the points around it and the hull cuts what bulges past the
// silhouettes: the result there is no better than the hull, and can be worse where the points
// around the gap are wrong.
#ifndef SFT_INIT_STEREO_MESH_H_
#define SFT_INIT_STEREO_MESH_H_

#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/mesh.h"
#include "src/init/initial_mesh.h"
#include "src/init/resample.h"
#include "src/init/stereo_points.h"
#include "src/init/visual_hull.h"
#include "src/io/dataset.h"

namespace sft {

struct StereoMeshReport {
  StereoReport stereo;
  ResampleReport surface;     // thinning, Poisson, trimming, clean-up, decimation.
  double load_seconds = 0.0;  // reading the images and masks.
  double total_seconds = 0.0;
};

// Reads the listed views' images (linear) and masks (when they have one) for stereo, in parallel.
// Errors name the file (unreadable, wrong size).
Status LoadStereoViews(const Dataset& dataset, const std::vector<int>& indices,
                       std::vector<StereoView>* views);

// The stereo surface of the views `indices` of `dataset` (options.stereo_options), trimmed to the
// hull of `hull_views` (options.hull's min_view_fraction), with `hull_mesh` (the hull carved from
// them) giving the object's box, and its area the Poisson spacing: the mean edge of a mesh of
// options.faces equilateral triangles, which is also the result's face budget. *mesh is replaced
// only on success (it may be `hull_mesh`). Errors: invalid options; stereo's and the surface's
// errors; no stereo points.
Status MakeStereoMesh(const Dataset& dataset, const std::vector<int>& indices,
                      const std::vector<CarvingView>& hull_views, const TriMesh& hull_mesh,
                      const InitialMeshOptions& options, TriMesh* mesh, StereoMeshReport* report);

}  // namespace sft

#endif  // SFT_INIT_STEREO_MESH_H_
