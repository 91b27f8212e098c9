#include "src/eval/view_scores.h"

#include <cmath>
#include <string>

namespace sft {

using json = nlohmann::json;

namespace {

// A number for JSON: null when not finite (a relative RMSE against a black reference).
json Finite(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

}  // namespace

Status ViewScores::Add(int v, const Image& ours, const Image& reference, const Image& mask) {
  ImageScores s;
  SFT_RETURN_IF_ERROR(ComputeImageScores(ours, reference, mask, ImageMetricsOptions(), &s)
                          .Prefixed("view " + std::to_string(v)));
  views_.push_back({{"view", v},
                    {"psnr_srgb", s.psnr_srgb},
                    {"ssim_srgb", s.ssim_srgb},
                    {"psnr_linear", s.psnr_linear},
                    {"ssim_linear", s.ssim_linear},
                    {"rel_rmse", Finite(s.relative_rmse)}});
  sum_.psnr_srgb += s.psnr_srgb;
  sum_.ssim_srgb += s.ssim_srgb;
  sum_.psnr_linear += s.psnr_linear;
  sum_.ssim_linear += s.ssim_linear;
  if (std::isfinite(s.relative_rmse)) {
    rel_rmse_sum_ += s.relative_rmse;
    ++rel_rmse_count_;
  }
  ++count_;
  return Status::Ok();
}

json ViewScores::ToJson() const {
  if (count_ == 0) return nullptr;
  return {{"psnr_srgb", sum_.psnr_srgb / count_},
          {"ssim_srgb", sum_.ssim_srgb / count_},
          {"psnr_linear", sum_.psnr_linear / count_},
          {"ssim_linear", sum_.ssim_linear / count_},
          {"rel_rmse", rel_rmse_count_ > 0 ? json(rel_rmse_sum_ / rel_rmse_count_) : json(nullptr)},
          {"views", views_}};
}

json ViewScoreDefinitions() {
  return {{"psnr_srgb",
           "PSNR (dB, peak 1) of the display images: linear values clipped to [0, 1], then "
           "sRGB-encoded"},
          {"ssim_srgb", "SSIM of the display images (dynamic range 1)"},
          {"psnr_linear", "PSNR (dB, peak 1) of the linear values"},
          {"ssim_linear", "SSIM of the linear values (dynamic range 1)"},
          {"rel_rmse",
           "sqrt(sum (ours - reference)^2 / sum reference^2) of the linear values; null when the "
           "reference is black"}};
}

}  // namespace sft
