// sft render: renders every view of a dataset with a given mesh and material into DIR/images/
// (EXR; each view's image path mirrored under images/, see ViewOutputPaths), plus DIR/render.json
// with timings and counts. It writes nothing outside DIR and refuses a DIR that is, is inside or
// holds one of its inputs.
// Unless --no-report, each render is also compared with its dataset image (CompareImages over the
// view's mask, or the target's alpha when the view has no mask), the measures go into render.json
// and DIR/report.html shows target, render and |difference| per view (src/eval/render_report.h).
#include <cstdio>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/eval/render_report.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
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
    SFT_RETURN_IF_ERROR(ApplyLightsFile(opts.lights, &dataset));
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
  nlohmann::json report = {{"dataset", opts.dataset},
                           {"mesh", opts.mesh},
                           {"spp", render.spp},
                           {"bounces", render.bounces},
                           {"effects", render.effects.ToString()},
                           {"shading", ShadingName(render.shading)},
                           {"pass", opts.pass},
                           {"seed", render.seed}};
  RenderReport comparison(opts.out, "sft render: " + opts.dataset,
                          render.pass == RenderPass::kColor);
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
      std::string warning;
      SFT_RETURN_IF_ERROR(comparison.AddView(dataset, v, image, &entry, &warning));
      if (!warning.empty()) progress.Warn(warning);
    }
    per_view.push_back(std::move(entry));
  }
  progress.Finish();
  report["views"] = per_view;
  report["seconds"] = progress.ElapsedSeconds();
  if (!opts.no_report) {
    const RenderReportSettings settings{opts.dataset,
                                        opts.mesh,
                                        opts.material,
                                        opts.pass,
                                        render.spp,
                                        render.bounces,
                                        render.effects.ToString(),
                                        render.seed};
    SFT_RETURN_IF_ERROR(comparison.Write(settings, static_cast<int>(selected.size()),
                                         progress.ElapsedSeconds(), &report));
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
                  "Fitted lights to apply: scales, point-light positions and directional-light "
                  "directions (lights.json written by sft reconstruct)");
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
