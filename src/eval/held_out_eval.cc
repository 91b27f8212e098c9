#include "src/eval/held_out_eval.h"

#include <algorithm>
#include <set>

#include "src/core/file_util.h"
#include "src/eval/image_metrics.h"
#include "src/io/scene_setup.h"
#include "src/optim/run_outputs.h"
#include "src/optim/schedule_config.h"

namespace sft {

using json = nlohmann::json;

Eigen::Vector3d MedianGain(const std::vector<Eigen::Vector3d>& gains) {
  Eigen::Vector3d median = Eigen::Vector3d::Ones();
  if (gains.empty()) return median;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> values;
    for (const Eigen::Vector3d& g : gains) values.push_back(g[c]);
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    median[c] = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  }
  return median;
}

Eigen::Vector3d FitViewGain(const Image& ours, const Image& target, const Image& mask) {
  const Image o = ToRgb(ours), t = ToRgb(target);
  Eigen::Vector3d to = Eigen::Vector3d::Zero(), oo = Eigen::Vector3d::Zero();
  for (int y = 0; y < o.height; ++y) {
    for (int x = 0; x < o.width; ++x) {
      if (!mask.data.empty() && !(mask.at(x, y, 0) > 0.5f)) continue;
      for (int c = 0; c < 3; ++c) {
        to[c] += static_cast<double>(t.at(x, y, c)) * o.at(x, y, c);
        oo[c] += static_cast<double>(o.at(x, y, c)) * o.at(x, y, c);
      }
    }
  }
  Eigen::Vector3d gain = Eigen::Vector3d::Ones();
  for (int c = 0; c < 3; ++c) {
    if (oo[c] > 0.0) gain[c] = to[c] / oo[c];
  }
  return gain;
}

Image ScaleChannels(const Image& image, const Eigen::Vector3d& gain) {
  Image rgb = ToRgb(image);
  for (size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] *= static_cast<float>(gain[i % 3]);
  return rgb;
}

namespace {

// The views whose exposure gains a stage of the run fitted (none when no stage fits exposure).
Status ExposureFittedViews(const RunState& state, const std::string& source, int dataset_views,
                           std::vector<int>* views) {
  std::vector<StageOptions> stages;
  SFT_RETURN_IF_ERROR(StagesFromJson(state.stages, source, &stages));
  std::set<int> fitted;
  for (const StageOptions& stage : stages) {
    if (!stage.fit.fit_exposure) continue;
    std::vector<int> selected;
    SFT_RETURN_IF_ERROR(SelectViews(stage.fit.views, dataset_views, &selected).Prefixed(source));
    fitted.insert(selected.begin(), selected.end());
  }
  for (int v : state.held_out_views) fitted.erase(v);
  views->assign(fitted.begin(), fitted.end());
  return Status::Ok();
}

}  // namespace

Status ReadHeldOutSetup(const std::string& reconstruction, int dataset_views, HeldOutSetup* setup) {
  const std::string path = JoinPath(reconstruction, "state.json");
  RunState state;
  SFT_RETURN_IF_ERROR(ReadRunState(reconstruction, &state));
  if (state.held_out_views.empty()) {
    return Status::Error(path + ": the run held out no views (--held-out scores the views that " +
                         "sft reconstruct --holdout K kept out of the fit)");
  }
  for (int v : state.held_out_views) {
    if (v >= dataset_views) {
      return Status::Error(path + ": held_out_views: view " + std::to_string(v) +
                           " is not in the dataset (" + std::to_string(dataset_views) + " views)");
    }
  }
  setup->views = state.held_out_views;
  SFT_RETURN_IF_ERROR(ExposureFittedViews(state, path, dataset_views, &setup->gain_views));
  std::vector<Eigen::Vector3d> gains;
  if (static_cast<int>(state.view_gains.size()) == dataset_views) {
    for (int v : setup->gain_views) gains.push_back(state.view_gains[v]);
  } else {
    setup->gain_views.clear();  // no gains recorded: every gain is 1.
  }
  setup->gain = MedianGain(gains);
  return Status::Ok();
}

Status HeldOutScores::Add(int v, const Image& ours, const Image& target, const Image& mask,
                          const Eigen::Vector3d& gain) {
  const std::string where = "held-out view " + std::to_string(v);
  const ImageMetricsOptions linear;  // peak 1.
  double psnr = 0.0, ssim = 0.0, psnr_fit = 0.0;
  const Image scaled = ScaleChannels(ours, gain);
  SFT_RETURN_IF_ERROR(ComputePsnr(scaled, target, mask, linear, &psnr).Prefixed(where));
  SFT_RETURN_IF_ERROR(ComputeSsim(scaled, target, mask, linear, &ssim).Prefixed(where));
  const Eigen::Vector3d fit = FitViewGain(ours, target, mask);
  SFT_RETURN_IF_ERROR(
      ComputePsnr(ScaleChannels(ours, fit), target, mask, linear, &psnr_fit).Prefixed(where));
  views_.push_back({{"view", v},
                    {"psnr_linear", psnr},
                    {"ssim_linear", ssim},
                    {"psnr_linear_gain_fit", psnr_fit},
                    {"gain_fit", {fit[0], fit[1], fit[2]}}});
  psnr_sum_ += psnr;
  ssim_sum_ += ssim;
  psnr_fit_sum_ += psnr_fit;
  ++count_;
  return Status::Ok();
}

json HeldOutScores::ToJson() const {
  if (count_ == 0) return nullptr;
  return {{"psnr_linear", psnr_sum_ / count_},
          {"ssim_linear", ssim_sum_ / count_},
          {"psnr_linear_gain_fit", psnr_fit_sum_ / count_},
          {"per_view", views_}};
}

}  // namespace sft
