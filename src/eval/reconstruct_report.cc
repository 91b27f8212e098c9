#include "src/eval/reconstruct_report.h"

#include <algorithm>
#include <cstdio>

#include "src/eval/line_chart.h"
#include "src/eval/report.h"

namespace sft {
namespace {

constexpr int kMaxViewRows = 4;
constexpr int kDifferenceGain = 4;

double MeanPsnr(const IterationRecord& r) {
  double sum = 0.0;
  for (double p : r.view_psnr) sum += p;
  return r.view_psnr.empty() ? 0.0 : sum / r.view_psnr.size();
}

}  // namespace

Status WriteReconstructReport(const std::string& out, const Dataset& dataset,
                              const std::vector<IterationRecord>& records,
                              Reconstruction* reconstruction) {
  HtmlReport html(out, "sft reconstruct: " + dataset.root);
  const IterationRecord* last = records.empty() ? nullptr : &records.back();
  html.AddSummaryTable({{"dataset", dataset.root},
                        {"views fitted", std::to_string(reconstruction->view_indices().size())},
                        {"iterations", std::to_string(records.size())},
                        {"final cost", last ? FormatNumber(last->cost) : "n/a"},
                        {"final mean PSNR (dB, peak 1, level 0 over the active pixels)",
                         last ? FormatNumber(MeanPsnr(*last)) : "n/a"},
                        {"wall time (s)", last ? FormatNumber(last->seconds) : "n/a"}});
  LineChart cost;
  cost.title = "objective against wall time";
  cost.x_label = "seconds";
  cost.y_label = "cost ½Σr²";
  cost.log_y = true;
  LineChart psnr;
  psnr.title = "mean PSNR of the fitted views against wall time";
  psnr.x_label = "seconds";
  psnr.y_label = "PSNR (dB)";
  for (const std::string phase : {"texture", "geometry"}) {
    LineSeries c{phase, {}, {}}, p{phase, {}, {}};
    for (const IterationRecord& r : records) {
      if (r.phase != phase) continue;
      c.x.push_back(r.seconds);
      c.y.push_back(r.cost);
      p.x.push_back(r.seconds);
      p.y.push_back(MeanPsnr(r));
    }
    if (!c.x.empty()) {
      cost.series.push_back(c);
      psnr.series.push_back(p);
    }
  }
  html.AddSvg(LineChartSvg(cost));
  html.AddSvg(LineChartSvg(psnr));
  html.AddHeading("Views at the final state");
  const std::vector<Image> renders = reconstruction->RenderViews(/*seed=*/0x5f7eed);
  const RenderCache& cache = reconstruction->cache();
  const int rows = std::min<int>(kMaxViewRows, static_cast<int>(renders.size()));
  for (int k = 0; k < rows; ++k) {
    const int v = k * static_cast<int>(renders.size()) / rows;
    const Image& target = cache.Target(v);
    const double scale = ExposureScale(target, nullptr);
    char prefix[64];
    std::snprintf(prefix, sizeof(prefix), "report_files/view_%03d_",
                  reconstruction->view_indices()[v]);
    const std::string base(prefix);
    SFT_RETURN_IF_ERROR(html.WriteImage(base + "target.png", ScaledRgb(target, scale)));
    SFT_RETURN_IF_ERROR(html.WriteImage(base + "render.png", ScaledRgb(renders[v], scale)));
    SFT_RETURN_IF_ERROR(html.WriteImage(
        base + "difference.png", AbsDifferenceRgb(renders[v], target, kDifferenceGain * scale)));
    ImageRow row;
    row.label = "view " + std::to_string(reconstruction->view_indices()[v]);
    row.images = {{base + "target.png", "target", nullptr},
                  {base + "render.png", "render", nullptr},
                  {base + "difference.png", "|render − target| ×" + std::to_string(kDifferenceGain),
                   nullptr}};
    if (last != nullptr && v < static_cast<int>(last->view_psnr.size())) {
      row.notes = {{"PSNR (dB)", FormatNumber(last->view_psnr[v])}};
    }
    SFT_RETURN_IF_ERROR(html.AddImageRow(row));
  }
  return html.Write("report.html");
}

}  // namespace sft
