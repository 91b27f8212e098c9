#include "src/eval/reconstruction_eval.h"

#include <cmath>
#include <filesystem>

#include "src/core/file_util.h"
#include "src/eval/image_metrics.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/image_io.h"
#include "src/io/light_scales.h"
#include "src/io/scene_setup.h"
#include "src/render/render.h"

namespace sft {
namespace {

using json = nlohmann::json;

// A number for JSON: null when not finite (a relative RMSE against a black reference).
json Finite(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

// Per-view scores of one pass and their means over views (the relative RMSE's over the views
// where it is defined).
struct Measure {
  json views = json::array();
  ImageScores sum;
  double rel_rmse_sum = 0.0;
  int count = 0, rel_rmse_count = 0;

  Status Add(int v, const Image& ours, const Image& reference, const Image& mask) {
    ImageScores s;
    SFT_RETURN_IF_ERROR(ComputeImageScores(ours, reference, mask, ImageMetricsOptions(), &s)
                            .Prefixed("view " + std::to_string(v)));
    views.push_back({{"view", v},
                     {"psnr_srgb", s.psnr_srgb},
                     {"ssim_srgb", s.ssim_srgb},
                     {"psnr_linear", s.psnr_linear},
                     {"ssim_linear", s.ssim_linear},
                     {"rel_rmse", Finite(s.relative_rmse)}});
    sum.psnr_srgb += s.psnr_srgb;
    sum.ssim_srgb += s.ssim_srgb;
    sum.psnr_linear += s.psnr_linear;
    sum.ssim_linear += s.ssim_linear;
    if (std::isfinite(s.relative_rmse)) {
      rel_rmse_sum += s.relative_rmse;
      ++rel_rmse_count;
    }
    ++count;
    return Status::Ok();
  }
  json ToJson() const {
    if (count == 0) return nullptr;
    return {{"psnr_srgb", sum.psnr_srgb / count},
            {"ssim_srgb", sum.ssim_srgb / count},
            {"psnr_linear", sum.psnr_linear / count},
            {"ssim_linear", sum.ssim_linear / count},
            {"rel_rmse", rel_rmse_count > 0 ? json(rel_rmse_sum / rel_rmse_count) : json(nullptr)},
            {"views", views}};
  }
};

// A ground-truth pass folder named by `key` of the dataset's ground_truth, or "" when absent.
Status PassFolder(const Dataset& dataset, const char* key, std::string* folder) {
  folder->clear();
  if (!dataset.ground_truth.is_object() || !dataset.ground_truth.contains(key)) return Status::Ok();
  const json& value = dataset.ground_truth[key];
  if (!value.is_string()) return Status::Ok();
  std::string why;
  if (!IsContainedRelativePath(value.get<std::string>(), &why)) {
    return Status::Error(JoinPath(dataset.root, "scene.json") + ": ground_truth." + key + ": " +
                         why);
  }
  *folder = value.get<std::string>();
  return Status::Ok();
}

// The true pass of view v: an image of `folder` (named like the view's image, .exr), or a render
// of `truth` when folder is empty.
Status TruePass(const Dataset& dataset, int v, const std::string& folder, const RenderScene* scene,
                const Material* truth, const ViewSetup& view, RenderOptions options, Image* out) {
  if (!folder.empty()) {
    std::filesystem::path name = std::filesystem::path(dataset.views[v].image).filename();
    name.replace_extension(".exr");
    Image image;
    SFT_RETURN_IF_ERROR(ReadImage(JoinPath(JoinPath(dataset.root, folder), name.string()), &image));
    *out = ToRgb(image);
    return Status::Ok();
  }
  Image image;
  RenderView(*scene, *truth, view, options, &image);
  *out = ToRgb(image);
  return Status::Ok();
}

// What each key of a measure means (written into the report so that the JSON explains itself).
json MeasureDefinitions() {
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

}  // namespace

bool ReconstructionEvalOptions::Check(std::string* why) const {
  if (spp < 1 || spp > 65536) {
    *why = "spp: must be in [1, 65536]";
    return false;
  }
  if (bounces < 1 || bounces > 16) {
    *why = "bounces: must be in [1, 16]";
    return false;
  }
  return true;
}

Status EvaluateReconstruction(const std::string& dataset_dir, const std::string& reconstruction,
                              const ReconstructionEvalOptions& options, json* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("--" + why);
  Dataset dataset;
  SFT_RETURN_IF_ERROR(ReadDataset(dataset_dir, &dataset));
  TriMesh mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(JoinPath(reconstruction, "mesh.ply"), &mesh));
  Material material;
  SFT_RETURN_IF_ERROR(LoadMaterial(JoinPath(reconstruction, "material.json"), mesh, &material));
  const std::string lights = JoinPath(reconstruction, "lights.json");
  if (FileExists(lights)) {
    std::vector<double> scales;
    SFT_RETURN_IF_ERROR(ReadLightScales(lights, dataset, &scales));
    ApplyLightScales(scales, &dataset);
  }
  std::string albedo_folder, roughness_folder;
  SFT_RETURN_IF_ERROR(PassFolder(dataset, "albedo", &albedo_folder));
  SFT_RETURN_IF_ERROR(PassFolder(dataset, "roughness", &roughness_folder));
  // A rendered truth needs the true mesh and material.
  TriMesh true_mesh;
  Material true_material;
  std::unique_ptr<RenderScene> true_scene;
  std::string true_material_path;
  SFT_RETURN_IF_ERROR(PassFolder(dataset, "material", &true_material_path));
  const bool can_render_truth = !dataset.gt_mesh.empty() && !true_material_path.empty();
  if (can_render_truth) {
    SFT_RETURN_IF_ERROR(ReadMesh(JoinPath(dataset.root, dataset.gt_mesh), &true_mesh));
    SFT_RETURN_IF_ERROR(
        LoadMaterial(JoinPath(dataset.root, true_material_path), true_mesh, &true_material));
    true_scene = std::make_unique<RenderScene>(true_mesh);
  }
  DatasetViews views;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &views));
  std::vector<int> selected;
  SFT_RETURN_IF_ERROR(SelectViews(options.views, static_cast<int>(views.views.size()), &selected));
  const RenderScene scene(mesh);
  RenderOptions render;
  render.spp = options.spp;
  render.bounces = options.bounces;
  render.seed = options.seed;
  render.shading = DatasetShading(dataset);  // as the fit renders it with "shading": "auto".
  RenderOptions albedo_pass = render;
  albedo_pass.pass = RenderPass::kAlbedo;
  RenderOptions roughness_pass = render;
  roughness_pass.pass = RenderPass::kRoughness;
  Measure full, albedo, roughness;
  for (int v : selected) {
    Image target, mask, ours;
    SFT_RETURN_IF_ERROR(LoadViewImage(dataset, v, &target));
    if (!dataset.views[v].mask.empty()) SFT_RETURN_IF_ERROR(LoadViewMask(dataset, v, &mask));
    RenderView(scene, material, views.views[v], render, &ours);
    SFT_RETURN_IF_ERROR(full.Add(v, ToRgb(ours), target, mask));
    if (!albedo_folder.empty() || can_render_truth) {
      Image truth;
      SFT_RETURN_IF_ERROR(TruePass(dataset, v, albedo_folder, true_scene.get(), &true_material,
                                   views.views[v], albedo_pass, &truth));
      RenderView(scene, material, views.views[v], albedo_pass, &ours);
      SFT_RETURN_IF_ERROR(albedo.Add(v, ToRgb(ours), truth, mask));
    }
    if (!roughness_folder.empty() || can_render_truth) {
      Image truth;
      SFT_RETURN_IF_ERROR(TruePass(dataset, v, roughness_folder, true_scene.get(), &true_material,
                                   views.views[v], roughness_pass, &truth));
      RenderView(scene, material, views.views[v], roughness_pass, &ours);
      SFT_RETURN_IF_ERROR(roughness.Add(v, ToRgb(ours), truth, mask));
    }
  }
  *report = {{"mode", "reconstruction"},
             {"dataset", dataset_dir},
             {"reconstruction", reconstruction},
             {"spp", options.spp},
             {"bounces", options.bounces},
             {"views", selected},
             {"psnr_peak", 1.0},
             {"definitions", MeasureDefinitions()},
             {"full", full.ToJson()},
             {"albedo", albedo.ToJson()},
             {"roughness", roughness.ToJson()}};
  return Status::Ok();
}

}  // namespace sft
