// sft render: renders every view of a dataset with a given mesh and material into DIR/images/
// (EXR; each view's image path mirrored under images/, see ViewOutputPaths), plus DIR/render.json
// with timings and counts. It writes nothing outside DIR and refuses a DIR that is, is inside or
// holds one of its inputs.
// Unless --no-report, each render is also compared with its dataset image (CompareImages over the
// view's mask, or the target's alpha when the view has no mask), the measures go into render.json
// and DIR/report.html shows target, render and |difference| per view (PNGs in DIR/report_files/).
#include <cstdio>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/eval/image_compare.h"
#include "src/eval/report.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/image_io.h"
#include "src/io/light_scales.h"
#include "src/io/scene_setup.h"
#include "src/render/render.h"

namespace sft {
namespace {

// The command-line values of `sft render`; validated by FinishRenderOptions and the loaders.
struct RenderCommandOptions {
  std::string dataset;           // dataset directory (sft-dataset/1).
  std::string mesh;              // mesh to render (OBJ, PLY, OFF).
  std::string material;          // material JSON file or inline JSON; "" = default material.
  std::string out;               // output directory (images/, render.json, report.html).
  std::string lights;            // light scales (lights.json of sft reconstruct); "" = none.
  std::string pass = "color";    // color | albedo | roughness | normal | depth.
  std::string effects = "all";   // enabled effects (Effects::Parse).
  std::string shading = "auto";  // "auto" (the dataset's, DatasetShading), "flat" or "smooth".
  std::vector<int> views;        // view indices; empty = all.
  RenderOptions render;          // spp, bounces, seed, threads.
  bool quiet = false;            // no progress line.
  bool no_report = false;        // skip the comparison with the dataset images and report.html.
};

constexpr char kReportFiles[] = "report_files";  // the report's PNGs, under OUT/.
constexpr int kDifferenceGain = 4;               // |difference| thumbnails are this much brighter.

// One render against its dataset image (the "target").
struct ViewComparison {
  Image target;             // as read (RGB or RGBA); empty when missing or unreadable.
  Image mask;               // 1 channel, > 0.5 = object; empty when there is none.
  std::string mask_source;  // the mask file (relative to the dataset) or "target alpha".
  bool compared = false;    // `agreement` is valid.
  ImageAgreement agreement;
  std::string why_not;  // when !compared: the reason.
};

// 1 where channel 3 of `image` (RGBA) is > 0.5, else 0.
Image AlphaMask(const Image& image) {
  Image mask(image.width, image.height, 1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) mask.at(x, y) = image.at(x, y, 3) > 0.5f ? 1.0f : 0.0f;
  }
  return mask;
}

// Loads view `v`'s target and mask and compares `ours` with it. Never fails: problems (missing or
// unreadable files, size mismatches, no mask) leave `compared` false with the reason.
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

// Parses the shared render flags into `options`, returning a failed status naming the flag.
Status FinishRenderOptions(const std::string& pass, const std::string& effects,
                           RenderOptions* options) {
  if (!RenderPassFromName(pass, &options->pass)) {
    return Status::Error("--pass: unknown pass '" + pass +
                         "' (color, albedo, roughness, normal, depth)");
  }
  std::string why;
  if (!Effects::Parse(effects, &options->effects, &why)) return Status::Error("--" + why);
  if (!options->Check(&why)) return Status::Error("--" + why);
  return Status::Ok();
}

Status RunRender(const RenderCommandOptions& opts) {
  RenderOptions render = opts.render;
  SFT_RETURN_IF_ERROR(FinishRenderOptions(opts.pass, opts.effects, &render));
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(
      opts.out, {{opts.dataset}, {opts.mesh, MaterialFile(opts.material), opts.lights}}, "--out"));
  Dataset dataset;
  SFT_RETURN_IF_ERROR(ReadDataset(opts.dataset, &dataset));
  if (!ResolveShading(opts.shading, dataset, &render.shading)) {
    return Status::Error("--shading: expected auto, flat or smooth, got '" + opts.shading + "'");
  }
  // Only the colour pass is lit; albedo, roughness, normal and depth are first-hit passes that
  // need no light, so they also render datasets with unknown lighting (empty `lights`).
  if (render.pass == RenderPass::kColor) SFT_RETURN_IF_ERROR(CheckViewsHaveLights(dataset));
  if (!opts.lights.empty()) {
    std::vector<double> scales;
    SFT_RETURN_IF_ERROR(ReadLightScales(opts.lights, dataset, &scales));
    ApplyLightScales(scales, &dataset);
  }
  TriMesh mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(opts.mesh, &mesh));
  Material material;
  SFT_RETURN_IF_ERROR(LoadMaterial(opts.material, mesh, &material, MaterialUse::kRender));
  DatasetViews views;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &views));
  std::vector<int> selected;
  const Status selection = SelectViews(opts.views, static_cast<int>(views.views.size()), &selected);
  if (!selection.ok()) return Status::Error("--" + selection.message());
  const std::vector<std::string> out_paths = ViewOutputPaths(dataset, ".exr");
  const RenderScene scene(mesh);
  // Progress in tiles of camera samples, so that the line advances within a long view.
  int64_t total_tiles = 0;
  for (int v : selected) {
    total_tiles += RenderTileCount(views.views[v].camera.width, views.views[v].camera.height);
  }
  Progress progress("render (tiles)", total_tiles, !opts.quiet);
  render.on_tile_done = [&progress] { progress.Advance(); };
  nlohmann::json report;
  report["dataset"] = opts.dataset;
  report["mesh"] = opts.mesh;
  report["spp"] = render.spp;
  report["bounces"] = render.bounces;
  report["effects"] = render.effects.ToString();
  report["shading"] = ShadingName(render.shading);
  report["pass"] = opts.pass;
  report["seed"] = render.seed;
  const bool colour_pass = render.pass == RenderPass::kColor;
  HtmlReport html(opts.out, "sft render: " + opts.dataset);
  std::vector<ImageRow> rows;
  std::vector<std::string> bar_labels;
  std::vector<double> bar_values;
  int compared = 0;
  double sum_mean_abs = 0.0, sum_bias = 0.0, sum_max_block = 0.0;
  nlohmann::json per_view = nlohmann::json::array();
  for (int v : selected) {
    Image image;
    RenderStats stats;
    RenderView(scene, material, views.views[v], render, &image, &stats);
    SFT_RETURN_IF_ERROR(WriteExr(JoinPath(opts.out, out_paths[v]), image));
    nlohmann::json entry = {{"view", v},
                            {"image", out_paths[v]},
                            {"seconds", stats.seconds},
                            {"camera_rays", stats.camera_rays},
                            {"shadow_rays", stats.shadow_rays},
                            {"bounce_rays", stats.bounce_rays},
                            {"nonfinite_samples", stats.nonfinite_samples},
                            {"nonfinite_outputs", stats.nonfinite_outputs}};
    if (stats.NonFinite() > 0) {
      progress.Warn("view " + std::to_string(v) + ": " + std::to_string(stats.nonfinite_samples) +
                    " samples dropped as not finite, " + std::to_string(stats.nonfinite_outputs) +
                    " pixel values not finite");
    }
    if (!opts.no_report) {
      const ViewComparison c = CompareWithTarget(dataset, v, image, colour_pass);
      entry["target"] = dataset.views[v].image;
      bar_labels.push_back(std::to_string(v));
      if (c.compared) {
        entry["comparison"] = AgreementJson(c);
        ++compared;
        sum_mean_abs += c.agreement.relative_mean_abs_difference;
        sum_bias += c.agreement.relative_mean_difference;
        sum_max_block += c.agreement.max_block_relative_difference;
        bar_values.push_back(c.agreement.relative_mean_abs_difference);
      } else {
        entry["comparison"] = nullptr;
        entry["comparison_skipped"] = c.why_not;
        if (colour_pass) {
          progress.Warn("view " + std::to_string(v) + " not compared: " + c.why_not);
        }
        bar_values.push_back(std::numeric_limits<double>::quiet_NaN());
      }
      ImageRow row;
      SFT_RETURN_IF_ERROR(
          MakeReportRow(&html, v, dataset.views[v].image, image, c, colour_pass, &row));
      rows.push_back(std::move(row));
    }
    per_view.push_back(std::move(entry));
  }
  progress.Finish();
  report["views"] = per_view;
  report["seconds"] = progress.ElapsedSeconds();
  if (!opts.no_report) {
    nlohmann::json overall = nullptr;
    if (compared > 0) {
      overall = {{"views_compared", compared},
                 {"mean_relative_mean_abs_difference", sum_mean_abs / compared},
                 {"mean_relative_mean_difference", sum_bias / compared},
                 {"mean_max_block_relative_difference", sum_max_block / compared}};
    }
    report["comparison"] = overall;
    report["views_compared"] = compared;
    report["report"] = "report.html";
    const double mean_abs = compared > 0 ? sum_mean_abs / compared : 0.0;
    html.AddSummaryTable(
        {{"dataset", opts.dataset},
         {"mesh", opts.mesh},
         {"material", opts.material.empty() ? "default" : opts.material},
         {"pass", opts.pass},
         {"spp", std::to_string(render.spp)},
         {"bounces", std::to_string(render.bounces)},
         {"effects", render.effects.ToString()},
         {"seed", std::to_string(render.seed)},
         {"views rendered", std::to_string(selected.size())},
         {"views compared", std::to_string(compared)},
         {"mean relative mean |difference|", compared > 0 ? FormatNumber(mean_abs) : "n/a"},
         {"mean relative mean difference (bias)",
          compared > 0 ? FormatNumber(sum_bias / compared) : "n/a"},
         {"mean max 8×8 block relative difference",
          compared > 0 ? FormatNumber(sum_max_block / compared) : "n/a"},
         {"render seconds", FormatNumber(progress.ElapsedSeconds())}});
    html.AddParagraph(
        "Measures over the view's mask (or the target's alpha > 0.5): mean |render − target| "
        "and mean (render − target) relative to the target's mean, over RGB. Thumbnails are "
        "sRGB-encoded with the exposure that maps the target's 99th percentile (over the mask) "
        "to 1; the difference uses the same exposure ×" +
        std::to_string(kDifferenceGain) + ".");
    BarChart chart;
    chart.title = "relative mean |render − target| per view";
    chart.x_label = "view";
    chart.y_label = "mean |d| / mean target";
    chart.labels = bar_labels;
    chart.values = bar_values;
    if (compared > 0) {
      chart.reference_value = mean_abs;
      chart.reference_label = "mean";
    }
    html.AddBarChart(chart);
    html.AddHeading("Views");
    for (const ImageRow& row : rows) SFT_RETURN_IF_ERROR(html.AddImageRow(row));
    SFT_RETURN_IF_ERROR(html.Write("report.html"));
  }
  return WriteTextFile(JoinPath(opts.out, "render.json"), report.dump(1) + "\n");
}

}  // namespace

CommandRunner SetupRenderCommand(CLI::App* app) {
  auto opts = std::make_shared<RenderCommandOptions>();
  app->add_option("--dataset", opts->dataset, "Dataset directory (sft-dataset/1)")->required();
  app->add_option("--mesh", opts->mesh, "Mesh to render (OBJ, PLY, OFF)")->required();
  app->add_option("--material", opts->material,
                  "Material: JSON file or inline JSON (see docs/cli.md); default albedo 0.7");
  app->add_option("--out", opts->out, "Output directory; images go to OUT/images/")->required();
  app->add_option("--lights", opts->lights,
                  "Light scales to apply (lights.json written by sft reconstruct)");
  app->add_option("--spp", opts->render.spp, "Samples per pixel")->capture_default_str();
  app->add_option("--bounces", opts->render.bounces,
                  "Path segments: 1 = direct light only, 2 = one indirect bounce")
      ->capture_default_str();
  app->add_option("--pass", opts->pass, "color | albedo | roughness | normal | depth")
      ->capture_default_str();
  app->add_option("--shading", opts->shading,
                  "auto (the dataset's ground_truth.shading, else smooth), flat or smooth")
      ->capture_default_str();
  app->add_option("--effects", opts->effects,
                  "Enabled effects: comma list of direct,shadows,bounces,specular,environment, "
                  "or all/none")
      ->capture_default_str();
  app->add_option("--seed", opts->render.seed, "Sample seed")->capture_default_str();
  app->add_option("--threads", opts->render.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
  app->add_option("--views", opts->views, "Only these view indices (comma-separated)")
      ->delimiter(',');
  app->add_flag("--quiet", opts->quiet, "No progress line");
  app->add_flag("--no-report", opts->no_report,
                "Do not compare with the dataset images or write OUT/report.html");
  return [opts]() {
    const Status status = RunRender(*opts);
    return status.ok() ? 0 : PrintError("render", status);
  };
}

}  // namespace sft
