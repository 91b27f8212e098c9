// Image accuracy of a reconstruction (`sft eval --dataset D --reconstruction O`): the
// reconstruction (O/mesh.ply, O/material.json, O/lights.json when present) is re-rendered from
// every view of D and compared with
//   full       D's images (colour pass, the dataset's lights times the fitted scales);
//   albedo     D's true albedo: the images of the folder `ground_truth.albedo` (one EXR per view,
//              named like the view's image, premultiplied by coverage as Cycles' DiffCol pass),
//              or else the albedo pass of `ground_truth.mesh` with `ground_truth.material`;
//   roughness  the same with `ground_truth.roughness` or the material's roughness.
// over each view's mask (all pixels when it has none). PSNR with peak 1 and SSIM
// (src/eval/image_metrics.h), per view and their means over views.
#ifndef SFT_EVAL_RECONSTRUCTION_EVAL_H_
#define SFT_EVAL_RECONSTRUCTION_EVAL_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

struct ReconstructionEvalOptions {
  int spp = 64;            // samples per pixel of the re-renders, [1, 65536].
  int bounces = 2;         // path segments of the colour re-render, [1, 16].
  uint64_t seed = 99;      // re-render seed.
  std::vector<int> views;  // view indices; empty = all.

  bool Check(std::string* why) const;
};

// Fills *report with {"mode": "reconstruction", "full": {...}, "albedo": {...} | null,
// "roughness": {...} | null, ...}; each measure {"psnr", "ssim", "views": [{"view", "psnr",
// "ssim"}]}.
Status EvaluateReconstruction(const std::string& dataset_dir, const std::string& reconstruction,
                              const ReconstructionEvalOptions& options, nlohmann::json* report);

}  // namespace sft

#endif  // SFT_EVAL_RECONSTRUCTION_EVAL_H_
