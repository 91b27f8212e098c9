// Unknown lighting as parameters (docs/reconstruct.md, "Unknown lighting"): when no view of a
// dataset records its lights (real captures without a probe), the fit estimates a world-fixed
// environment — a low-resolution equirectangular map (src/render/environment.h) whose texels are
// RGB radiance parameters (ParameterKind::kEnvironment) — jointly with the material, under a
// smoothness prior (cost_functions/environment_smoothness.h).
//
// The gauge. Albedo × radiance is ambiguous per channel (exactly so for one bounce: any factor
// moves between them), so the start fixes it: every texel starts at the mean photograph over the
// masks divided by `assumed_albedo` (a diffuse surface of albedo a under uniform radiance L
// reflects a·L), and the solvers, which take no step along an exact null direction, keep it.
// Albedo is therefore known up to one scale per channel: score it after the best per-channel
// scale (`sft eval` does when the run estimated its lighting).
//
// Beside the map, point and directional lights of roughly known place (a lamp on a gantry, a
// flash, the sun) can be estimated too (`estimate_lights`): they join every view's lights and the
// environment stage fits their intensity and position or direction with the map.
//
// The map lives in memory as the dataset light kFittedEnvironmentId (LightSpec::pixels); the run
// folder keeps it as kFittedEnvironmentFile, and the estimated lights' start specs as
// kEstimatedLightsFile (their fitted values are in lights.json, as for any dataset light).
#ifndef SFT_OPTIM_FITTED_ENVIRONMENT_H_
#define SFT_OPTIM_FITTED_ENVIRONMENT_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/io/dataset.h"

namespace sft {

constexpr char kFittedEnvironmentId[] = "fitted_environment";
constexpr char kFittedEnvironmentFile[] = "environment.exr";
// Beside it: {"format": "sft-fitted-environment/1", "frame": "world" | "camera"}. A run folder
// without it (runs before camera-fixed maps) holds a world-fixed map.
constexpr char kFittedEnvironmentInfoFile[] = "environment.json";
// The estimated lights as they started, a lights file (ReadLightsFile); absent when there are none.
constexpr char kEstimatedLightsFile[] = "estimated_lights.json";

struct EnvironmentEstimateOptions {
  int width = 32;               // texels around the horizon (u), [2, 512].
  int height = 16;              // texels from pole to pole (v), [1, 256].
  double assumed_albedo = 0.5;  // the gauge (above), (0, 1].
  // Where the map is fixed: kWorld (lights in the room, the default) or kCamera (lights that ride
  // with the camera: a ring light, a lamp on the gantry's camera arm, a turntable capture; the
  // map's frame is then each view's camera frame, z-up in the env convention).
  LightFrame frame = LightFrame::kWorld;
  // Point and directional lights estimated beside the map (scene.json's light format; ids unique,
  // not kFittedEnvironmentId); empty = the map alone. Their specs are the fit's start.
  std::vector<LightSpec> lights;
  // No lights given, one lamp looked for (src/optim/lamp_finder.h): the map is fitted alone
  // first, and a point lamp starts in its brightest lobe's direction. Excludes `lights`.
  bool find_lamp = false;
  // The found lamp's start distance from the object's centre, in half bounding-box diagonals,
  // [0.5, 1000]: the map shows a lamp's direction, not its distance; the fit corrects a start
  // from half to twice the true distance (docs/design-notes.md, "How far off a lamp's guess may
  // be"), so 4 covers lamps 2 to 8 half diagonals away.
  double lamp_distance = 4.0;

  bool Check(std::string* why) const;
};

// Whether no view records its lights (every `lights` list empty) and there is at least one view.
bool LightingUnknown(const Dataset& dataset);

// The start map: width × height RGB, every texel the mean of the photographs over their masks
// (whole images without masks) divided by options.assumed_albedo. Errors name the unreadable file.
Status InitialEnvironment(const Dataset& dataset, const EnvironmentEstimateOptions& options,
                          Image* texels);

// Adds the light kFittedEnvironmentId with map `texels` (fixed in `frame`, whose axes are the
// env frame's; scale 1) to `dataset` and to every view's lights (after the estimated lights, when
// AddEstimatedLights ran first). Refuses a dataset that has a fitted environment already.
Status AddFittedEnvironment(const Image& texels, LightFrame frame, Dataset* dataset);

// Adds estimated lights (EnvironmentEstimateOptions::lights) to `dataset` and to every view's
// lights, before the fitted environment when it has one already (the map stays last, with its
// texels and frame). Errors: a type other than point or directional, an id the dataset has
// already.
Status AddEstimatedLights(const std::vector<LightSpec>& lights, Dataset* dataset);

// The estimated lights of a dataset PrepareUnknownLighting prepared: the lights its views list
// beside the fitted environment (empty when it has none).
std::vector<LightSpec> EstimatedLights(const Dataset& dataset);

// Writes EstimatedLights(dataset) into run folder `run` as kEstimatedLightsFile; writes nothing
// when there are none.
Status WriteEstimatedLights(const std::string& run, const Dataset& dataset);

// Writes the fitted map and its frame into run folder `run` (kFittedEnvironmentFile,
// kFittedEnvironmentInfoFile).
Status WriteFittedEnvironment(const std::string& run, const Image& texels, LightFrame frame);
// The frame of the map in run folder `run` (world when it has no kFittedEnvironmentInfoFile).
// Errors name the file.
Status ReadFittedEnvironmentFrame(const std::string& run, LightFrame* frame);
// "world" or "camera"; false for other names.
bool LightFrameFromName(const std::string& name, LightFrame* frame);
const char* LightFrameName(LightFrame frame);

// Index of the fitted environment light in dataset.lights, -1 when there is none.
int FittedEnvironmentLight(const Dataset& dataset);

// What `sft reconstruct` does with a dataset before fitting it: when its lighting is unknown
// (LightingUnknown), adds the estimated lights — `run`/kEstimatedLightsFile when `run` is a run
// folder holding one (--resume, sft eval), else options.lights — and then the fitted environment
// — the checkpoint's `run`/kFittedEnvironmentFile in its recorded frame when `run` holds one, else
// InitialEnvironment in options.frame — and sets *note to the one console line saying so;
// otherwise changes nothing (*note empty), and refuses options.lights. Errors name the file.
Status PrepareUnknownLighting(const std::string& run, const EnvironmentEstimateOptions& options,
                              Dataset* dataset, std::string* note);

// How far a fitted map is from the true environment, both relative RMS errors (dimensionless, 0 =
// exact) over the fitted grid, every texel weighed by its solid angle.
struct EnvironmentError {
  double radiance = 0.0;    // of the texels' radiance.
  double irradiance = 0.0;  // of the irradiance E(n) = ∫ L(ω)·max(0, n·ω) dω at the texels' n.
};

// The error of `fitted` against `truth` (an equirectangular probe in the fitted map's frame, any
// resolution, RGB or RGBA): `truth` is box-filtered onto the fitted grid, and the fitted radiance
// is divided per channel by `albedo_scale` (the albedo's gauge: when s·albedo matches the true
// albedo, radiance / s matches the true radiance); √(Σ w‖f/s − t‖² / Σ w‖t‖²). Errors: an empty
// or non-RGB image, a non-positive or non-finite scale, a black truth.
Status FittedEnvironmentError(const Image& fitted, const Image& truth,
                              const Eigen::Vector3d& albedo_scale, EnvironmentError* error);

}  // namespace sft

#endif  // SFT_OPTIM_FITTED_ENVIRONMENT_H_
