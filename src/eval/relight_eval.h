// Relighting as a metric (`sft eval --relight`, docs/cli.md): the reconstruction and the dataset's
// ground truth (ground_truth.mesh with ground_truth.material) are both rendered from the dataset's
// views under lights the fit never saw, and compared with PSNR and SSIM over each view's mask
// (ViewScores). A reconstruction that baked the capture's lighting into its albedo, or got the
// roughness wrong, shows it here even when it matches the captured images.
//
// A condition is one set of lights for every view. The specs of --relight:
//   FILE         a lights file (ReadLightsFile: {"lights": [...]} in scene.json's light format);
//                each light is a condition of its own, named by its id.
//   probe:PATH   one environment light from the equirectangular EXR PATH (identity rotation,
//                scale 1), named "probe:" + the file's stem.
//   side         each view's capture point lights turned 90° about the object's centre (the true
//                mesh's bounding-box centre) towards world +z (towards +x when a light lies on
//                the z axis through the centre), at the same distance and intensity: the light
//                moves from the camera's side to above the object.
// Every evaluation also scores the condition "capture" (the dataset's own lights, rendered for
// both, without the fitted light scales), so that relit and capture-lit numbers are measured the
// same way. Renders are on a black background (masks exclude it from the scores anyway).
#ifndef SFT_EVAL_RELIGHT_EVAL_H_
#define SFT_EVAL_RELIGHT_EVAL_H_

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/io/dataset.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {

struct RelightCondition {
  std::string name;               // its key in the report and part of its output folder.
  std::string source;             // the --relight spec it came from ("capture" for the dataset's).
  std::vector<LightSpec> lights;  // point lights (world or camera frame) and environment probes.
  // view_lights[v]: indices into `lights` that light view v; empty = every view uses them all.
  std::vector<std::vector<int>> view_lights;
};

// The conditions of `specs` (see above), after "capture". `centre` is the object's centre for
// "side". Errors name the spec, or the file and JSON field of a lights file.
Status MakeRelightConditions(const std::vector<std::string>& specs, const Dataset& dataset,
                             const Eigen::Vector3d& centre,
                             std::vector<RelightCondition>* conditions);

// `dataset` lit by condition c: its lights replaced by c's (each view by its view_lights, or all
// of them), on a black background.
Dataset RelitDataset(const Dataset& dataset, const RelightCondition& c);

// What is rendered and compared.
struct RelightInputs {
  const Dataset* dataset = nullptr;    // views, cameras, masks; its lights are not used.
  const RenderScene* scene = nullptr;  // the reconstruction.
  const Material* material = nullptr;  // its material.
  const RenderScene* truth = nullptr;  // the ground truth.
  const Material* true_material = nullptr;
  std::vector<int> views;  // the views to render.
  RenderOptions render;    // spp, bounces, seed, shading (pass: colour).
  // When non-empty, the renders are written as EXR to OUT/relight/<NN>_<name>/{ours,truth}/
  // <view path> (ViewOutputPaths; NN the condition's index, name with characters other than
  // letters, digits, '-' and '_' replaced by '_').
  std::string out;
};

// Fills *relight with {"conditions": [{"name", "source", "psnr_srgb", ..., "views": [...]}, ...],
// "novel_mean": {means over the conditions other than "capture" of the four PSNR/SSIM keys}}.
Status EvaluateRelighting(const RelightInputs& inputs,
                          const std::vector<RelightCondition>& conditions, nlohmann::json* relight);

}  // namespace sft

#endif  // SFT_EVAL_RELIGHT_EVAL_H_
