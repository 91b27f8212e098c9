// Image accuracy of a reconstruction (`sft eval --dataset D --reconstruction O`): the
// reconstruction (O/mesh.ply, O/material.json, O/lights.json when present) is re-rendered from
// every view of D and compared with
//   full       D's images (colour pass, the dataset's lights times the fitted scales);
//   albedo     D's true albedo: the images of the folder `ground_truth.albedo` (one EXR per view,
//              named like the view's image, premultiplied by coverage as Cycles' DiffCol pass),
//              or else the albedo pass of `ground_truth.mesh` with `ground_truth.material`;
//   roughness  the same with `ground_truth.roughness` or the material's roughness.
// over each view's mask (all pixels when it has none). For each pass, per view and as means over
// views (src/eval/image_metrics.h): PSNR and SSIM of the display images (clipped to [0, 1] and
// sRGB-encoded: what a viewer sees, meaningful on HDR data), PSNR and SSIM of the linear values
// (peak 1), and the relative RMSE of the linear values.
// With --relight, the reconstruction and the true object are also rendered under other lights and
// compared with each other (src/eval/relight_eval.h).
#ifndef SFT_EVAL_RECONSTRUCTION_EVAL_H_
#define SFT_EVAL_RECONSTRUCTION_EVAL_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/eval/relight_eval.h"

namespace sft {

struct ReconstructionEvalOptions {
  int spp = 64;            // samples per pixel of the re-renders, [1, 65536].
  int bounces = 2;         // path segments of the colour re-render, [1, 16].
  uint64_t seed = 99;      // re-render seed.
  std::vector<int> views;  // view indices; empty = all.
  std::string mesh;        // mesh to render instead of O/mesh.ply (e.g. an export's model.obj).
  std::string material;    // material spec instead of O/material.json (LoadMaterial: a JSON
                           // file, inline JSON or an export's model.mtl).
  // --relight specs (src/eval/relight_eval.h: a lights file, "probe:PATH" or "side"); empty =
  // no relighting. Needs the dataset's ground_truth.mesh and ground_truth.material.
  std::vector<std::string> relight;
  std::string out;  // folder for the relit renders; empty = none written.
  // Score the run's held-out views (state.json's held_out_views; src/eval/held_out_eval.h)
  // instead of `views`: "full" after the median fitted gain, and a "held_out" section.
  bool held_out = false;
  // The true environment of a dataset whose lighting the run estimated (an equirectangular EXR
  // in the world frame): adds "environment" with the fitted map's relative error after the
  // albedo's gauge (FittedEnvironmentError, src/optim/fitted_environment.h). Empty = none.
  std::string true_environment;

  bool Check(std::string* why) const;
};

// Fills *report with {"mode": "reconstruction", "views": [...], "full": {...}, "albedo": {...} |
// null, "roughness": {...} | null, "relight": {...} | null (EvaluateRelighting), "definitions":
// {...}, ...}; each pass {"psnr_srgb",
// "ssim_srgb", "psnr_linear", "ssim_linear", "rel_rmse", "views": [{"view", the same five}]}
// (rel_rmse null where undefined). With options.held_out also "held_out": {"views", "gain",
// "gain_views", HeldOutScores::ToJson's keys}, else null.
Status EvaluateReconstruction(const std::string& dataset_dir, const std::string& reconstruction,
                              const ReconstructionEvalOptions& options, nlohmann::json* report);

// Renders `views` (dataset view indices) of the run in `reconstruction` as EvaluateReconstruction
// does (its mesh and material or the overrides, the fitted lighting and light scales, options'
// spp, bounces and seed), as linear RGB (e.g. the held-out rows of report.html). Errors: as
// EvaluateReconstruction's loading, and a view outside the dataset.
Status RenderRunViews(const std::string& dataset_dir, const std::string& reconstruction,
                      const std::vector<int>& views, const ReconstructionEvalOptions& options,
                      std::vector<Image>* renders);

// The same under each of `lightings`, the run loaded once: (*renders)[i] under lightings[i]'s
// lights instead of the run's (RelitDataset: black background, no fitted light scales), or under
// the run's own lighting where lightings[i] is null.
Status RenderRunViewsUnder(const std::string& dataset_dir, const std::string& reconstruction,
                           const std::vector<int>& views, const ReconstructionEvalOptions& options,
                           const std::vector<const RelightCondition*>& lightings,
                           std::vector<std::vector<Image>>* renders);

}  // namespace sft

#endif  // SFT_EVAL_RECONSTRUCTION_EVAL_H_
