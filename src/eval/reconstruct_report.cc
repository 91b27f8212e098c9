#include "src/eval/reconstruct_report.h"

#include <algorithm>
#include <cstdio>

#include "src/eval/held_out_eval.h"
#include "src/eval/lighting_report.h"
#include "src/eval/line_chart.h"
#include "src/eval/reconstruction_eval.h"
#include "src/eval/report.h"
#include "src/eval/studio_lights.h"

namespace sft {
namespace {

constexpr int kMaxViewRows = 4;
constexpr int kMaxHeldOutRows = 2;
constexpr int kHeldOutSpp = 32;  // the held-out rows' renders (sft eval --held-out's scores: 64).
constexpr int kMaxRelitRows = 2;

// Renders of the result under the run's own lighting, shared between the report's rows so that
// a view is rendered once: views, their renders and their targets' ExposureScale (no mask).
struct CaptureRenders {
  std::vector<int> views;
  std::vector<Image> renders;
  std::vector<double> scales;
};

double MeanPsnr(const IterationRecord& r) {
  double sum = 0.0;
  for (double p : r.view_psnr) sum += p;
  return r.view_psnr.empty() ? 0.0 : sum / r.view_psnr.size();
}

// Cost and mean PSNR of every iteration against wall time, one series per phase.
void AddProgressCharts(const std::vector<IterationRecord>& records, HtmlReport* html) {
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
    // A new line wherever the other phase's records came between: a line across them would show
    // a trend no iterate had.
    bool interrupted = false;
    for (const IterationRecord& r : records) {
      if (r.phase != phase) {
        interrupted = !c.x.empty();
        continue;
      }
      if (interrupted) {
        c.breaks.push_back(c.x.size());
        p.breaks.push_back(p.x.size());
        interrupted = false;
      }
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
  html->AddSvg(LineChartSvg(cost));
  html->AddSvg(LineChartSvg(psnr));
}

// F1 and Chamfer of the outer records against wall time (nothing without --reference).
void AddReferenceCharts(const nlohmann::json& outer, HtmlReport* html) {
  LineSeries f1{"F1", {}, {}}, chamfer{"Chamfer", {}, {}};
  for (const auto& r : outer) {
    if (!r.contains("f1") || !r.contains("chamfer") || !r.contains("seconds")) continue;
    f1.x.push_back(r["seconds"].get<double>());
    f1.y.push_back(r["f1"].get<double>());
    chamfer.x.push_back(r["seconds"].get<double>());
    chamfer.y.push_back(r["chamfer"].get<double>());
  }
  if (f1.x.empty()) return;
  LineChart f1_chart;
  f1_chart.title = "F1 against the reference mesh, against wall time";
  f1_chart.x_label = "seconds";
  f1_chart.y_label = "F1";
  f1_chart.series = {f1};
  LineChart chamfer_chart;
  chamfer_chart.title = "Chamfer distance to the reference mesh, against wall time";
  chamfer_chart.x_label = "seconds";
  chamfer_chart.y_label = "Chamfer";
  chamfer_chart.log_y = true;
  chamfer_chart.series = {chamfer};
  html->AddSvg(LineChartSvg(f1_chart));
  html->AddSvg(LineChartSvg(chamfer_chart));
}

// The stages and the mesh's normals after each (images written by the schedule).
Status AddStages(const nlohmann::json& stages, HtmlReport* html) {
  if (stages.empty()) return Status::Ok();
  html->AddHeading("The mesh after each stage (normals of the first fitted view)");
  ImageRow row;
  row.label = "stages";
  for (const auto& s : stages) {
    const std::string caption = s.value("stage", "?") + ": " + std::to_string(s.value("faces", 0)) +
                                " faces, " + FormatNumber(s.value("end_seconds", 0.0)) + " s";
    row.images.push_back({s.value("normals", ""), caption, nullptr});
  }
  return html->AddImageRow(row);
}

// The effect planner's plan per outer iteration: one column per switch, "on", "off" or the bounce
// count, with the measured changes in units of their thresholds (nothing when the effects were
// fixed).
void AddEffectPlans(const nlohmann::json& outer, HtmlReport* html) {
  std::vector<std::string> header = {"outer", "stage", "planner s"};
  std::vector<std::vector<std::string>> rows;
  for (const auto& r : outer) {
    if (!r.contains("effects") || !r["effects"].contains("decisions")) continue;
    const nlohmann::json& plan = r["effects"];
    if (rows.empty()) {
      for (const auto& d : plan["decisions"]) header.push_back(d.value("name", "?"));
    }
    std::vector<std::string> row = {std::to_string(r.value("outer", 0)), r.value("stage", ""),
                                    FormatNumber(plan.value("seconds", 0.0))};
    for (const auto& d : plan["decisions"]) {
      std::string cell = d.value("name", "") == "bounces"
                             ? std::to_string(d.value("bounces", 1)) + " seg"
                             : (d.value("on", false) ? "on" : "off");
      if (d.value("reason", "") == "measured") {
        // The change in units of the threshold, for the images and the step.
        for (const char* key : {"image", "step"}) {
          if (!d.contains(key) || !(d[key].value("threshold", 0.0) > 0.0)) continue;
          cell += std::string(" ") + key + " " +
                  FormatNumber(d[key].value("change", 0.0) / d[key].value("threshold", 1.0)) +
                  "×, " + FormatNumber(100.0 * d[key].value("share", 0.0)) + "%";
        }
      } else {
        cell += " (" + d.value("reason", "") + ")";
      }
      row.push_back(cell);
    }
    rows.push_back(row);
  }
  if (rows.empty()) return;
  html->AddHeading("Effects chosen by the planner");
  html->AddParagraph(
      "Per outer iteration: each switch on or off, with its measured change of the images and "
      "of the vertex gradient (step) in units of the noise threshold (noise_factor × the "
      "seed-to-seed noise / √outer iterations) and as a share of the values' RMS; a switch stays "
      "on when either is exceeded (1× or planner_max_share), or why it was not measured.");
  html->AddTable(header, rows);
}

// Up to kMaxHeldOutRows held-out views (sft reconstruct --holdout): target | render × the median
// fitted gain | difference, rendered as `sft eval --held-out --spp kHeldOutSpp` renders them,
// with that view's linear PSNR before and after its own gain. Nothing when the run held out no
// views. *shown: the views and their renders.
Status AddHeldOutRows(const std::string& out, const Dataset& dataset, HtmlReport* html,
                      CaptureRenders* shown) {
  HeldOutSetup setup;
  if (!ReadHeldOutSetup(out, static_cast<int>(dataset.views.size()), &setup).ok()) {
    return Status::Ok();  // no held-out views (or no readable state): no rows.
  }
  const std::vector<int> views(
      setup.views.begin(),
      setup.views.begin() + std::min<size_t>(kMaxHeldOutRows, setup.views.size()));
  ReconstructionEvalOptions options;
  options.spp = kHeldOutSpp;
  std::vector<Image> renders;
  SFT_RETURN_IF_ERROR(RenderRunViews(dataset.root, out, views, options, &renders));
  html->AddHeading("Held-out views (not fitted)");
  for (size_t k = 0; k < views.size(); ++k) {
    const int v = views[k];
    Image target, mask;
    SFT_RETURN_IF_ERROR(LoadViewImage(dataset, v, &target));
    if (!dataset.views[v].mask.empty()) SFT_RETURN_IF_ERROR(LoadViewMask(dataset, v, &mask));
    HeldOutScores scores;
    SFT_RETURN_IF_ERROR(scores.Add(v, renders[k], target, mask, setup.gain));
    const nlohmann::json score = scores.ToJson()["per_view"][0];
    shown->views.push_back(v);
    shown->renders.push_back(renders[k]);
    shown->scales.push_back(ExposureScale(target, nullptr));
    const Image ours = ScaleChannels(renders[k], setup.gain);
    const double scale = ExposureScale(target, mask.empty() ? nullptr : &mask);
    const std::string base = "report_files/held_out_" + std::to_string(v) + "_";
    SFT_RETURN_IF_ERROR(html->WriteImage(base + "target.png", ScaledRgb(target, scale)));
    SFT_RETURN_IF_ERROR(html->WriteImage(base + "render.png", ScaledRgb(ours, scale)));
    SFT_RETURN_IF_ERROR(html->WriteImage(base + "difference.png",
                                         AbsDifferenceRgb(ours, target, kDifferenceGain * scale)));
    ImageRow row;
    row.label = "view " + std::to_string(v) + " (held out)";
    row.images = {{base + "target.png", "target", nullptr},
                  {base + "render.png", "render × median fitted gain", nullptr},
                  {base + "difference.png", "|render − target| ×" + std::to_string(kDifferenceGain),
                   nullptr}};
    row.notes = {
        {"PSNR (dB, linear)", FormatNumber(score.value("psnr_linear", 0.0))},
        {"PSNR after its own gain", FormatNumber(score.value("psnr_linear_gain_fit", 0.0))},
        {"spp", std::to_string(kHeldOutSpp)}};
    SFT_RETURN_IF_ERROR(html->AddImageRow(row));
  }
  return Status::Ok();
}

// Up to kMaxRelitRows views of the result under the studio lights (src/eval/studio_lights.h),
// beside the render under the run's own lighting: the held-out views when there are any (their
// renders `held_out` reused), else fitted views spread over the list. The relit images are shown
// unscaled (their radiance reads as albedo); the run's lighting at its target's exposure.
Status AddRelitRows(const std::string& out, const Dataset& dataset,
                    const std::vector<int>& fitted_views, const CaptureRenders& held_out,
                    HtmlReport* html) {
  CaptureRenders capture = held_out;
  const std::vector<RelightCondition> conditions = StudioConditions();
  std::vector<const RelightCondition*> lightings;
  if (capture.views.empty()) {
    for (int k = 0; k < kMaxRelitRows && k < static_cast<int>(fitted_views.size()); ++k) {
      capture.views.push_back(fitted_views[k * fitted_views.size() / kMaxRelitRows]);
    }
    lightings.push_back(nullptr);  // the run's own lighting too.
  }
  const std::vector<int> views(
      capture.views.begin(),
      capture.views.begin() + std::min<size_t>(capture.views.size(), kMaxRelitRows));
  if (views.empty()) return Status::Ok();
  for (const RelightCondition& c : conditions) lightings.push_back(&c);
  ReconstructionEvalOptions options;
  options.spp = kHeldOutSpp;
  std::vector<std::vector<Image>> renders;
  SFT_RETURN_IF_ERROR(RenderRunViewsUnder(dataset.root, out, views, options, lightings, &renders));
  if (lightings[0] == nullptr) {
    capture.renders = std::move(renders[0]);
    renders.erase(renders.begin());
    for (int v : views) {
      Image target;
      SFT_RETURN_IF_ERROR(LoadViewImage(dataset, v, &target));
      capture.scales.push_back(ExposureScale(target, nullptr));
    }
  }
  html->AddHeading("Relit (lights the fit never saw)");
  html->AddParagraph(
      "key: a light from the camera's upper right with a 20% white fill; ambient: a uniform white "
      "sky, where a diffuse surface shows its albedo darkened by occlusion. Both at exposure 1, "
      "so their values read as albedo.");
  for (size_t k = 0; k < views.size(); ++k) {
    const std::string base = "report_files/relit_" + std::to_string(views[k]) + "_";
    ImageRow row;
    row.label = "view " + std::to_string(views[k]);
    SFT_RETURN_IF_ERROR(
        html->WriteImage(base + "capture.png", ScaledRgb(capture.renders[k], capture.scales[k])));
    row.images.push_back({base + "capture.png", "the run's lighting", nullptr});
    for (size_t c = 0; c < conditions.size(); ++c) {
      const std::string file = base + conditions[c].name + ".png";
      SFT_RETURN_IF_ERROR(html->WriteImage(file, ScaledRgb(renders[c][k], 1.0)));
      row.images.push_back({file, conditions[c].name, nullptr});
    }
    row.notes = {{"spp", std::to_string(kHeldOutSpp)}};
    SFT_RETURN_IF_ERROR(html->AddImageRow(row));
  }
  return Status::Ok();
}

}  // namespace

Status WriteReconstructReport(const std::string& out, const Dataset& dataset,
                              const std::vector<IterationRecord>& records,
                              Reconstruction* reconstruction, const nlohmann::json& outer_records,
                              const nlohmann::json& stage_records, const ReportModel& model) {
  HtmlReport html(out, "sft reconstruct: " + dataset.root);
  const IterationRecord* last = records.empty() ? nullptr : &records.back();
  html.AddSummaryTable({{"dataset", dataset.root},
                        {"views fitted", std::to_string(reconstruction->view_indices().size())},
                        {"iterations", std::to_string(records.size())},
                        {"final cost", last ? FormatNumber(last->cost) : "n/a"},
                        {"final mean PSNR (dB, peak 1, level 0 over the active pixels)",
                         last ? FormatNumber(MeanPsnr(*last)) : "n/a"},
                        {"wall time (s)", last ? FormatNumber(last->seconds) : "n/a"}});
  AddProgressCharts(records, &html);
  AddReferenceCharts(outer_records, &html);
  SFT_RETURN_IF_ERROR(AddStages(stage_records, &html));
  AddEffectPlans(outer_records, &html);
  SFT_RETURN_IF_ERROR(AddFittedLighting(out, dataset, &html));
  if (!model.viewer.export_dir.empty()) {
    SFT_RETURN_IF_ERROR(AddModelViewer(model.viewer, dataset, &html));
  } else if (!model.missing.empty()) {
    html.AddHeading("The result in 3D");
    html.AddParagraph("No 3D view: " + model.missing);
  }
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
  CaptureRenders held_out;
  SFT_RETURN_IF_ERROR(AddHeldOutRows(out, dataset, &html, &held_out));
  SFT_RETURN_IF_ERROR(AddRelitRows(out, dataset, reconstruction->view_indices(), held_out, &html));
  return html.Write("report.html");
}

}  // namespace sft
