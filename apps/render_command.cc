// sft render: renders every view of a dataset with a given mesh and material into DIR/images/
// (EXR, same base names as the dataset's images), plus DIR/render.json with timings and counts.
#include <nlohmann/json.hpp>

#include <filesystem>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/image_io.h"
#include "src/io/scene_setup.h"
#include "src/render/render.h"

namespace sft {
namespace {

struct RenderCommandOptions {
  std::string dataset;
  std::string mesh;
  std::string material;
  std::string out;
  std::string pass = "color";
  std::string effects = "all";
  std::vector<int> views;
  RenderOptions render;
  bool quiet = false;
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
  Dataset dataset;
  SFT_RETURN_IF_ERROR(ReadDataset(opts.dataset, &dataset));
  TriMesh mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(opts.mesh, &mesh));
  Material material;
  SFT_RETURN_IF_ERROR(LoadMaterial(opts.material, mesh, &material));
  DatasetViews views;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &views));
  std::vector<int> selected;
  const Status selection =
      SelectViews(opts.views, static_cast<int>(views.views.size()), &selected);
  if (!selection.ok()) return Status::Error("--" + selection.message());
  const RenderScene scene(mesh);
  Progress progress("render", static_cast<int64_t>(selected.size()), !opts.quiet);
  nlohmann::json report;
  report["dataset"] = opts.dataset;
  report["mesh"] = opts.mesh;
  report["spp"] = render.spp;
  report["bounces"] = render.bounces;
  report["effects"] = render.effects.ToString();
  report["pass"] = opts.pass;
  report["seed"] = render.seed;
  nlohmann::json per_view = nlohmann::json::array();
  for (int v : selected) {
    Image image;
    RenderStats stats;
    RenderView(scene, material, views.views[v], render, &image, &stats);
    std::filesystem::path name(dataset.views[v].image);
    name.replace_extension(".exr");
    const std::string out_path = JoinPath(opts.out, name.string());
    SFT_RETURN_IF_ERROR(WriteExr(out_path, image));
    per_view.push_back({{"view", v},
                        {"image", name.string()},
                        {"seconds", stats.seconds},
                        {"camera_rays", stats.camera_rays},
                        {"shadow_rays", stats.shadow_rays},
                        {"bounce_rays", stats.bounce_rays}});
    progress.Advance();
  }
  progress.Finish();
  report["views"] = per_view;
  report["seconds"] = progress.ElapsedSeconds();
  return WriteTextFile(JoinPath(opts.out, "render.json"), report.dump(1) + "\n");
}

}  // namespace

CommandRunner SetupRenderCommand(CLI::App* app) {
  auto opts = std::make_shared<RenderCommandOptions>();
  app->add_option("--dataset", opts->dataset, "Dataset directory (sft-dataset/1)")->required();
  app->add_option("--mesh", opts->mesh, "Mesh to render (OBJ, PLY, OFF)")->required();
  app->add_option("--material", opts->material,
                  "Material: JSON file or inline JSON (see README); default albedo 0.7");
  app->add_option("--out", opts->out, "Output directory; images go to OUT/images/")->required();
  app->add_option("--spp", opts->render.spp, "Samples per pixel")->capture_default_str();
  app->add_option("--bounces", opts->render.bounces,
                  "Path segments: 1 = direct light only, 2 = one indirect bounce")
      ->capture_default_str();
  app->add_option("--pass", opts->pass, "color | albedo | roughness | normal | depth")
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
  return [opts]() {
    const Status status = RunRender(*opts);
    return status.ok() ? 0 : PrintError("render", status);
  };
}

}  // namespace sft
