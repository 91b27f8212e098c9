#include "src/eval/render_report.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <utility>

#include "src/core/file_util.h"
#include "src/eval/report.h"
#include "src/image/image_io.h"

namespace sft {
namespace {

constexpr char kReportFiles[] = "report_files";  // the report's PNGs, under OUT/.

// 1 where channel 3 of `image` (RGBA) is > 0.5, else 0.
Image AlphaMask(const Image& image) {
  Image mask(image.width, image.height, 1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) mask.at(x, y) = image.at(x, y, 3) > 0.5f ? 1.0f : 0.0f;
  }
  return mask;
}

}  // namespace

ViewComparison CompareWithTarget(const Dataset& dataset, int v, const Image& ours,
                                 bool colour_pass) {
  ViewComparison result;
  const ViewSpec& view = dataset.views[v];
  Image target;
  const Status read = ReadImage(JoinPath(dataset.root, view.image), &target);
  if (!read.ok()) {
    result.why_not = read.message();
    return result;
  }
  if (target.width != ours.width || target.height != ours.height) {
    result.why_not = JoinPath(dataset.root, view.image) + ": size " + std::to_string(target.width) +
                     "x" + std::to_string(target.height) + " differs from the render's " +
                     std::to_string(ours.width) + "x" + std::to_string(ours.height);
    return result;
  }
  if (target.channels == 1) target = ScaledRgb(target, 1.0);
  result.target = std::move(target);
  if (!view.mask.empty()) {
    const Status mask = LoadViewMask(dataset, v, &result.mask);
    if (!mask.ok()) {
      result.mask = Image();
      result.why_not = mask.message();
      return result;
    }
    result.mask_source = view.mask;
  } else if (result.target.channels == 4) {
    result.mask = AlphaMask(result.target);
    result.mask_source = "target alpha";
  } else {
    result.why_not = "view has no mask and " + view.image + " has no alpha channel";
    return result;
  }
  if (!colour_pass) {
    result.why_not = "only the color pass is compared with the dataset images";
    return result;
  }
  if (ours.channels < 3) {
    result.why_not = "the render has fewer than 3 channels";
    return result;
  }
  result.agreement = CompareImages(ours, result.target, result.mask);
  if (result.agreement.object_pixels == 0) {
    result.why_not = result.mask_source + ": no object pixels";
    return result;
  }
  result.compared = true;
  return result;
}

namespace {

nlohmann::json AgreementJson(const ViewComparison& c) {
  return {{"relative_mean_abs_difference", c.agreement.relative_mean_abs_difference},
          {"relative_mean_difference", c.agreement.relative_mean_difference},
          {"max_block_relative_difference", c.agreement.max_block_relative_difference},
          {"mean_block_relative_difference", c.agreement.mean_block_relative_difference},
          {"blocks_compared", c.agreement.blocks_compared},
          {"object_pixels", c.agreement.object_pixels},
          {"mean_target", c.agreement.mean_reference},
          {"mask", c.mask_source}};
}

// Writes view `v`'s thumbnails (target, render and |difference| × kDifferenceGain, all with the
// target's exposure; the render alone gets its own when there is no target or the pass is not
// colour) and returns the report row for them.
Status MakeReportRow(HtmlReport* report, int v, const std::string& image_name, const Image& ours,
                     const ViewComparison& c, bool colour_pass, ImageRow* row) {
  char prefix[64];
  std::snprintf(prefix, sizeof(prefix), "%s/view_%03d_", kReportFiles, v);
  const std::string base(prefix);
  row->label = "view " + std::to_string(v) + " (" + image_name + ")";
  const bool have_target = !c.target.empty();
  const Image* exposure_mask = c.mask.empty() ? nullptr : &c.mask;
  const double target_scale = have_target ? ExposureScale(c.target, exposure_mask) : 1.0;
  if (have_target) {
    SFT_RETURN_IF_ERROR(report->WriteImage(base + "target.png", ScaledRgb(c.target, target_scale)));
    row->images.push_back({base + "target.png", "target", nullptr});
  } else {
    row->images.push_back({"", "target: not available", nullptr});
  }
  double render_scale = target_scale;
  if (!have_target || !colour_pass) {
    Image alpha;
    if (ours.channels == 4) alpha = AlphaMask(ours);
    render_scale = ExposureScale(ours, alpha.empty() ? nullptr : &alpha);
  }
  SFT_RETURN_IF_ERROR(report->WriteImage(base + "render.png", ScaledRgb(ours, render_scale)));
  row->images.push_back({base + "render.png", "render", nullptr});
  if (c.compared) {
    SFT_RETURN_IF_ERROR(report->WriteImage(
        base + "difference.png", AbsDifferenceRgb(ours, c.target, kDifferenceGain * target_scale)));
    row->images.push_back({base + "difference.png",
                           "|render − target| ×" + std::to_string(kDifferenceGain), nullptr});
    const ImageAgreement& a = c.agreement;
    row->notes = {
        {"relative mean |difference|", FormatNumber(a.relative_mean_abs_difference)},
        {"relative mean difference (bias)", FormatNumber(a.relative_mean_difference)},
        {"max 8×8 block relative difference", FormatNumber(a.max_block_relative_difference)},
        {"blocks compared", std::to_string(a.blocks_compared)},
        {"object pixels", std::to_string(a.object_pixels)},
        {"mask", c.mask_source},
        {"exposure", "×" + FormatNumber(target_scale)}};
  } else {
    row->notes = {{"comparison", "none: " + c.why_not}};
  }
  return Status::Ok();
}

}  // namespace

RenderReport::RenderReport(const std::string& out, const std::string& title, bool colour_pass)
    : html_(out, title), colour_pass_(colour_pass) {}

Status RenderReport::AddView(const Dataset& dataset, int v, const Image& image,
                             nlohmann::json* entry, std::string* warning) {
  warning->clear();
  const ViewComparison c = CompareWithTarget(dataset, v, image, colour_pass_);
  (*entry)["target"] = dataset.views[v].image;
  bar_labels_.push_back(std::to_string(v));
  if (c.compared) {
    (*entry)["comparison"] = AgreementJson(c);
    ++compared_;
    sum_mean_abs_ += c.agreement.relative_mean_abs_difference;
    sum_bias_ += c.agreement.relative_mean_difference;
    sum_max_block_ += c.agreement.max_block_relative_difference;
    bar_values_.push_back(c.agreement.relative_mean_abs_difference);
  } else {
    (*entry)["comparison"] = nullptr;
    (*entry)["comparison_skipped"] = c.why_not;
    if (colour_pass_) *warning = "view " + std::to_string(v) + " not compared: " + c.why_not;
    bar_values_.push_back(std::numeric_limits<double>::quiet_NaN());
  }
  ImageRow row;
  SFT_RETURN_IF_ERROR(
      MakeReportRow(&html_, v, dataset.views[v].image, image, c, colour_pass_, &row));
  rows_.push_back(std::move(row));
  return Status::Ok();
}

Status RenderReport::Write(const RenderReportSettings& s, int views_rendered, double seconds,
                           nlohmann::json* json) {
  const bool any = compared_ > 0;
  const double n = std::max(compared_, 1);
  (*json)["comparison"] =
      any ? nlohmann::json{{"views_compared", compared_},
                           {"mean_relative_mean_abs_difference", sum_mean_abs_ / n},
                           {"mean_relative_mean_difference", sum_bias_ / n},
                           {"mean_max_block_relative_difference", sum_max_block_ / n}}
          : nlohmann::json(nullptr);
  (*json)["views_compared"] = compared_;
  (*json)["report"] = "report.html";
  html_.AddSummaryTable(
      {{"dataset", s.dataset},
       {"mesh", s.mesh},
       {"material", s.material.empty() ? "default" : s.material},
       {"pass", s.pass},
       {"spp", std::to_string(s.spp)},
       {"bounces", std::to_string(s.bounces)},
       {"effects", s.effects},
       {"seed", std::to_string(s.seed)},
       {"views rendered", std::to_string(views_rendered)},
       {"views compared", std::to_string(compared_)},
       {"mean relative mean |difference|", any ? FormatNumber(sum_mean_abs_ / n) : "n/a"},
       {"mean relative mean difference (bias)", any ? FormatNumber(sum_bias_ / n) : "n/a"},
       {"mean max 8×8 block relative difference", any ? FormatNumber(sum_max_block_ / n) : "n/a"},
       {"render seconds", FormatNumber(seconds)}});
  html_.AddParagraph(
      "Measures over the view's mask (or the target's alpha > 0.5): mean |render − target| "
      "and mean (render − target) relative to the target's mean, over RGB. Thumbnails are "
      "sRGB-encoded with the exposure that maps the target's 99th percentile (over the mask) "
      "to 1; the difference uses the same exposure ×" +
      std::to_string(kDifferenceGain) + ".");
  BarChart chart;
  chart.title = "relative mean |render − target| per view";
  chart.x_label = "view";
  chart.y_label = "mean |d| / mean target";
  chart.labels = bar_labels_;
  chart.values = bar_values_;
  if (any) {
    chart.reference_value = sum_mean_abs_ / n;
    chart.reference_label = "mean";
  }
  html_.AddBarChart(chart);
  html_.AddHeading("Views");
  for (const ImageRow& row : rows_) SFT_RETURN_IF_ERROR(html_.AddImageRow(row));
  return html_.Write("report.html");
}

}  // namespace sft
