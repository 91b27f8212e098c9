// Finding a lamp with no guess (docs/reconstruct.md, "A lamp with no guess"). Under unknown
// lighting a lamp near the object is fitted beside the environment map from a start within about
// 50° of its direction ("How far off a lamp's guess may be", docs/design-notes.md). A map fitted
// alone already shows where such a lamp is: it explains the lamp's light with a bright lobe of
// texels in the lamp's direction from the object. So `find_lamp` first fits the map alone
// (the environment stage as the run would), then starts a point lamp along that lobe's direction,
// at a distance the map cannot tell (EnvironmentEstimateOptions::lamp_distance), with the lobe's
// irradiance. The run then fits that lamp beside a fresh map exactly as a lamp the user guessed.
#ifndef SFT_OPTIM_LAMP_FINDER_H_
#define SFT_OPTIM_LAMP_FINDER_H_

#include <Eigen/Core>
#include <functional>
#include <string>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/reconstruct.h"

namespace sft {

// The id of the found lamp among the dataset's lights (estimated_lights.json, lights.json).
constexpr char kFoundLampId[] = "found_lamp";
// A map whose brightest texel is less than this many times its median luminance has no lobe
// that a lamp would explain better than the map (a room lit evenly, or by large windows).
constexpr double kMinLobeContrast = 3.0;

struct LampSearch {
  bool found = false;     // a lobe stood out (contrast >= kMinLobeContrast); `lamp` is then set.
  LightSpec lamp;         // a point light, id kFoundLampId, in the map's frame.
  double contrast = 0.0;  // brightest texel / median, by luminance.
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // the lobe's, in the map's frame (unit).
  int lobe_texels = 0;                                  // texels in the lobe.
  double seconds = 0.0;                                 // of the map-alone fit (FindLamp).

  // One console line: where the lamp starts and why, or why there is none.
  std::string Describe() const;
};

// The lamp a fitted map `texels` (RGB, equirectangular, env convention of src/render/
// environment.h, taken to the light's frame by `frame_from_env`) points to, for an object
// centred at `centre` (in that frame): the lobe is the 8-connected texels around the brightest
// one (u wraps) whose luminance exceeds the median by half the brightest's excess; its direction
// ω is their mean direction weighted by excess luminance × solid angle; the lamp sits at
// centre + distance·ω with intensity E·distance², where E (RGB) = Σ max(0, L − median)·Ω·max(0,
// d·ω) over the lobe is the irradiance the lobe adds on a surface facing it (a point light of
// intensity I gives I/distance² there). `distance` in scene units, > 0. Errors: a map with no
// texels or fewer than 3 channels.
Status LampFromEnvironment(const Image& texels, const Eigen::Matrix3d& frame_from_env,
                           LightFrame frame, const Eigen::Vector3d& centre, double distance,
                           LampSearch* search);

// The object's centre in the frame of a light fixed in `frame`: the centre of `mesh`'s bounding
// box, for a camera frame its mean position in the cameras of views `views` (empty = every view).
Eigen::Vector3d ObjectCentreInFrame(const TriMesh& mesh, const Dataset& dataset,
                                    const std::vector<int>& views, LightFrame frame);

// The search: fits the map alone (`fit`, the environment stage's options, with fit_lights and
// the light-place keys turned off) on `dataset` (prepared by PrepareUnknownLighting, with a
// fitted environment and no estimated lights) from `mesh` and `material`, then
// LampFromEnvironment at lamp_distance × the bounding box's half diagonal from its centre.
// `on_iteration` is called after every solver step; false stops the search with an error.
Status FindLamp(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                const ReconstructOptions& fit, double lamp_distance,
                const std::function<bool(const IterationRecord&)>& on_iteration,
                LampSearch* search);

}  // namespace sft

#endif  // SFT_OPTIM_LAMP_FINDER_H_
