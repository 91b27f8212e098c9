// Per-view image scores of one comparison (a pass of `sft eval`, or one relighting condition) and
// their means over the views, as JSON (docs/cli.md "sft eval").
#ifndef SFT_EVAL_VIEW_SCORES_H_
#define SFT_EVAL_VIEW_SCORES_H_

#include <nlohmann/json.hpp>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/eval/image_metrics.h"

namespace sft {

class ViewScores {
 public:
  // Scores view v (ComputeImageScores over `mask`; an empty mask = every pixel).
  Status Add(int v, const Image& ours, const Image& reference, const Image& mask);
  // {"psnr_srgb", "ssim_srgb", "psnr_linear", "ssim_linear", "rel_rmse", "views": [{"view", the
  // same five}]}: means over the views (rel_rmse over the views where it is defined, else null);
  // null when no view was added.
  nlohmann::json ToJson() const;
  // Number of views added.
  int count() const { return count_; }

 private:
  nlohmann::json views_ = nlohmann::json::array();
  ImageScores sum_;
  double rel_rmse_sum_ = 0.0;
  int count_ = 0, rel_rmse_count_ = 0;
};

// What each key of ViewScores::ToJson means (written into reports so that the JSON explains
// itself).
nlohmann::json ViewScoreDefinitions();

}  // namespace sft

#endif  // SFT_EVAL_VIEW_SCORES_H_
