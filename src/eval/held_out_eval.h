// Scores of a reconstruction on its held-out views (`sft eval --held-out`; views kept out of the
// fit by `sft reconstruct --holdout K`, src/optim/holdout.h). A held-out view has no fitted
// exposure gain, so its render is multiplied by the median of the fitted gains (per channel, over
// the views the run's exposure stages fitted; 1 when no stage fitted exposure): the exposure a
// new photograph of the same capture most likely has. Beside that, the PSNR after the view's own
// least-squares gain (per channel, over the mask) separates shape and material errors from an
// exposure the run could not know.
#ifndef SFT_EVAL_HELD_OUT_EVAL_H_
#define SFT_EVAL_HELD_OUT_EVAL_H_

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"

namespace sft {

// Per-channel median of `gains` (the mean of the middle two for an even count); 1 when empty.
Eigen::Vector3d MedianGain(const std::vector<Eigen::Vector3d>& gains);

// The per-channel gain g minimising Σ (g·ours − target)² over the mask's pixels (> 0.5; an empty
// mask = every pixel), on the first three channels of both images; 1 for a channel that is
// black in ours. The images must have the same size.
Eigen::Vector3d FitViewGain(const Image& ours, const Image& target, const Image& mask);

// `image` as RGB, each channel multiplied by gain[c].
Image ScaleChannels(const Image& image, const Eigen::Vector3d& gain);

// What a run folder says about its held-out views: state.json's held_out_views and the median
// of the fitted exposure gains.
struct HeldOutSetup {
  std::vector<int> views;                          // the held-out views, ascending.
  Eigen::Vector3d gain = Eigen::Vector3d::Ones();  // MedianGain of the fitted gains.
  std::vector<int> gain_views;                     // the views whose gains were used.
};

// Reads `reconstruction`/state.json. Errors (one line naming the file): not a run folder, a run
// that held out no views, a held-out view outside [0, dataset_views).
Status ReadHeldOutSetup(const std::string& reconstruction, int dataset_views, HeldOutSetup* setup);

// Per-view held-out scores and their means.
class HeldOutScores {
 public:
  // Scores view v: `ours` (linear RGB, before any gain) times `gain` against `target` over
  // `mask` (PSNR and SSIM of linear values, peak 1), and the PSNR after FitViewGain.
  Status Add(int v, const Image& ours, const Image& target, const Image& mask,
             const Eigen::Vector3d& gain);
  // {"psnr_linear", "ssim_linear", "psnr_linear_gain_fit": means over the views, "per_view":
  // [{"view", "psnr_linear", "ssim_linear", "psnr_linear_gain_fit", "gain_fit": [R, G, B]}]};
  // null when no view was added.
  nlohmann::json ToJson() const;

 private:
  nlohmann::json views_ = nlohmann::json::array();
  double psnr_sum_ = 0.0, ssim_sum_ = 0.0, psnr_fit_sum_ = 0.0;
  int count_ = 0;
};

}  // namespace sft

#endif  // SFT_EVAL_HELD_OUT_EVAL_H_
