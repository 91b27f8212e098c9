// The comparison half of `sft render` (docs/cli.md): each render against its dataset image (the
// "target") over the view's mask, or the target's alpha when the view has no mask, and
// OUT/report.html with target, render and |difference| per view (PNGs in OUT/report_files/), a
// summary table and a bar chart of the per-view differences.
//
// Usage:
//   RenderReport report(out, "sft render: " + dataset.root, colour_pass);
//   for each view: render, then report.AddView(dataset, v, image, &entry, &warning);
//   report.Write(settings, &render_json);
#ifndef SFT_EVAL_RENDER_REPORT_H_
#define SFT_EVAL_RENDER_REPORT_H_

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/eval/image_compare.h"
#include "src/eval/report.h"
#include "src/io/dataset.h"

namespace sft {

// One render against its dataset image.
struct ViewComparison {
  Image target;             // as read (RGB or RGBA); empty when missing or unreadable.
  Image mask;               // 1 channel, > 0.5 = object; empty when there is none.
  std::string mask_source;  // the mask file (relative to the dataset) or "target alpha".
  bool compared = false;    // `agreement` is valid.
  ImageAgreement agreement;
  std::string why_not;  // when !compared: the reason.
};

// Loads view `v`'s target and mask and compares `ours` with it. Never fails: problems (missing or
// unreadable files, size mismatches, no mask, a pass other than colour) leave `compared` false
// with the reason.
ViewComparison CompareWithTarget(const Dataset& dataset, int v, const Image& ours,
                                 bool colour_pass);

// What the summary table states about the render (the command's settings).
struct RenderReportSettings {
  std::string dataset;   // the dataset folder.
  std::string mesh;      // the rendered mesh.
  std::string material;  // the material argument; "" = the default material.
  std::string pass;      // color, albedo, roughness, normal or depth.
  int spp = 0;           // samples per pixel.
  int bounces = 0;       // path segments.
  std::string effects;   // Effects::ToString().
  uint64_t seed = 0;     // the sample seed.
};

class RenderReport {
 public:
  // `out`: the report's folder; `colour_pass`: only colour renders are compared.
  RenderReport(const std::string& out, const std::string& title, bool colour_pass);

  // Compares view `v`'s render with its target and writes its thumbnails. Sets (*entry)["target"]
  // and either ["comparison"] (the measures) or ["comparison_skipped"] (why not); *warning says
  // why a colour render was not compared ("" otherwise). Errors: a thumbnail write failed.
  Status AddView(const Dataset& dataset, int v, const Image& image, nlohmann::json* entry,
                 std::string* warning);

  // Writes OUT/report.html and sets (*json)["comparison"] (the means over compared views, or
  // null), ["views_compared"] and ["report"].
  Status Write(const RenderReportSettings& settings, int views_rendered, double seconds,
               nlohmann::json* json);

 private:
  HtmlReport html_;
  bool colour_pass_;
  std::vector<ImageRow> rows_;
  std::vector<std::string> bar_labels_;
  std::vector<double> bar_values_;
  int compared_ = 0;
  double sum_mean_abs_ = 0.0, sum_bias_ = 0.0, sum_max_block_ = 0.0;
};

}  // namespace sft

#endif  // SFT_EVAL_RENDER_REPORT_H_
