#include "src/eval/reconstruction_eval.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>

#include "src/core/file_util.h"
#include "src/eval/held_out_eval.h"
#include "src/eval/image_metrics.h"
#include "src/eval/relight_eval.h"
#include "src/eval/view_scores.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/light_scales.h"
#include "src/io/scene_setup.h"
#include "src/optim/fitted_environment.h"
#include "src/optim/run_outputs.h"
#include "src/render/render.h"

namespace sft {
namespace {

using json = nlohmann::json;

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
  if (held_out && !views.empty()) {
    *why = "views: --held-out scores the run's held-out views; give one of --views and --held-out";
    return false;
  }
  return true;
}

namespace {

// The reconstruction to render: O/mesh.ply and O/material.json, or the overrides of `options`.
Status LoadReconstruction(const std::string& reconstruction,
                          const ReconstructionEvalOptions& options, TriMesh* mesh,
                          Material* material) {
  const std::string mesh_path =
      options.mesh.empty() ? JoinPath(reconstruction, "mesh.ply") : options.mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(mesh_path, mesh));
  const std::string material_spec =
      options.material.empty() ? JoinPath(reconstruction, "material.json") : options.material;
  // Rendered only: the UV-texture forms (an export's model.mtl) are allowed.
  SFT_RETURN_IF_ERROR(LoadMaterial(material_spec, *mesh, material, MaterialUse::kRender));
  return Status::Ok();
}

// The ground truth to render: ground_truth.mesh with ground_truth.material, when both are given.
struct Truth {
  TriMesh mesh;
  Material material;
  std::unique_ptr<RenderScene> scene;  // null when the dataset has no renderable truth.
};

Status LoadTruth(const Dataset& dataset, Truth* truth) {
  std::string material_path;
  SFT_RETURN_IF_ERROR(GroundTruthPath(dataset, "material", &material_path));
  if (dataset.gt_mesh.empty() || material_path.empty()) return Status::Ok();
  SFT_RETURN_IF_ERROR(ReadMesh(JoinPath(dataset.root, dataset.gt_mesh), &truth->mesh));
  SFT_RETURN_IF_ERROR(LoadMaterial(JoinPath(dataset.root, material_path), truth->mesh,
                                   &truth->material, MaterialUse::kRender));
  truth->scene = std::make_unique<RenderScene>(truth->mesh);
  return Status::Ok();
}

// The centre of the mesh's bounding box.
Eigen::Vector3d BoundingBoxCentre(const TriMesh& mesh) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    const Eigen::Vector3d q(p[0], p[1], p[2]);
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  return 0.5 * (lo + hi);
}

// The relighting conditions of options.relight; refuses a dataset without a renderable truth.
Status PrepareRelight(const Dataset& dataset, const Truth& truth,
                      const ReconstructionEvalOptions& options,
                      std::vector<RelightCondition>* conditions) {
  conditions->clear();
  if (options.relight.empty()) return Status::Ok();
  if (truth.scene == nullptr) {
    return Status::Error(JoinPath(dataset.root, "scene.json") +
                         ": --relight needs the true object, ground_truth.mesh and "
                         "ground_truth.material, and this dataset has not both");
  }
  return MakeRelightConditions(options.relight, dataset, BoundingBoxCentre(truth.mesh), conditions);
}

// One view's albedo pass, ours and the truth, kept until the gauge is known.
struct AlbedoPair {
  int view = 0;
  Image ours, truth, mask;
};

// The per-channel factor s_c minimising Σ (s_c·o − t)² over the masked pixels (all pixels of a
// view without a mask) of every view: the albedo's gauge when the lighting was estimated
// (src/optim/fitted_environment.h). 1 for a channel that is black in ours.
Eigen::Vector3d BestChannelScale(const std::vector<AlbedoPair>& pairs) {
  Eigen::Vector3d to = Eigen::Vector3d::Zero(), oo = Eigen::Vector3d::Zero();
  for (const AlbedoPair& p : pairs) {
    for (int y = 0; y < p.ours.height; ++y) {
      for (int x = 0; x < p.ours.width; ++x) {
        if (!p.mask.empty() && !(p.mask.at(x, y, 0) > 0.5f)) continue;
        for (int c = 0; c < 3; ++c) {
          const double o = p.ours.at(x, y, c), t = p.truth.at(x, y, c);
          to[c] += t * o;
          oo[c] += o * o;
        }
      }
    }
  }
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  for (int c = 0; c < 3; ++c) {
    if (oo[c] > 0.0) scale[c] = to[c] / oo[c];
  }
  return scale;
}

// The "held_out" section of the report: null unless --held-out.
json HeldOutJson(bool wanted, const HeldOutSetup& setup, const HeldOutScores& scores) {
  if (!wanted) return nullptr;
  json out = {{"views", setup.views},
              {"gain", {setup.gain[0], setup.gain[1], setup.gain[2]}},
              {"gain_views", setup.gain_views}};
  out.update(scores.ToJson());
  return out;
}

}  // namespace

namespace {

// What a run renders with: the dataset as the run saw it (its fitted environment when the
// lighting was unknown, the fitted light scales) and the reconstruction's mesh and material.
struct RunToRender {
  Dataset capture;  // the dataset as read, before the fitted light scales: relighting's capture.
  Dataset dataset;  // with the fitted lighting.
  TriMesh mesh;
  Material material;
  bool lighting_estimated = false;
};

Status LoadRunToRender(const std::string& dataset_dir, const std::string& reconstruction,
                       const ReconstructionEvalOptions& options, RunToRender* run) {
  SFT_RETURN_IF_ERROR(ReadDataset(dataset_dir, &run->dataset));
  run->capture = run->dataset;
  SFT_RETURN_IF_ERROR(LoadReconstruction(reconstruction, options, &run->mesh, &run->material));
  // Unknown lighting: the run's fitted environment (its environment.exr), before its light
  // scales, which count that light.
  run->lighting_estimated = LightingUnknown(run->dataset);
  if (run->lighting_estimated) {
    if (!FileExists(JoinPath(reconstruction, kFittedEnvironmentFile))) {
      return Status::Error(JoinPath(reconstruction, kFittedEnvironmentFile) +
                           ": missing; the dataset's lighting is unknown and the run's fitted "
                           "environment is needed to render it");
    }
    std::string note;
    SFT_RETURN_IF_ERROR(
        PrepareUnknownLighting(reconstruction, EnvironmentEstimateOptions(), &run->dataset, &note));
  }
  const std::string lights = JoinPath(reconstruction, "lights.json");
  if (FileExists(lights)) {
    SFT_RETURN_IF_ERROR(ApplyLightsFile(lights, &run->dataset));
  }
  // Refined poses (fit_poses): the fitted views render at their corrected poses; views the run
  // did not correct (held-out ones among them) keep the dataset's.
  std::vector<PoseDelta> poses;
  bool found = false;
  SFT_RETURN_IF_ERROR(
      ReadPoses(JoinPath(reconstruction, kPosesFile), run->dataset, &poses, &found));
  for (size_t v = 0; v < poses.size(); ++v) {
    Rigid3d& pose = run->dataset.views[v].cam_from_world;
    pose = CorrectedCamFromWorld(pose, poses[v]);
  }
  return Status::Ok();
}

RenderOptions EvalRenderOptions(const ReconstructionEvalOptions& options, const Dataset& dataset) {
  RenderOptions render;
  render.spp = options.spp;
  render.bounces = options.bounces;
  render.seed = options.seed;
  render.shading = DatasetShading(dataset);  // as the fit renders it with "shading": "auto".
  return render;
}

// The per-view scores of the colour, albedo and roughness passes.
struct PassScores {
  ViewScores full, albedo, roughness;
  std::vector<AlbedoPair> albedo_pairs;  // scored after the best channel scale (ScoreAlbedo).
  HeldOutScores held_out;
};

Status ScoreViews(const RunToRender& run, const RenderScene& scene, const Truth& truth,
                  const DatasetViews& views, const std::vector<int>& selected,
                  const RenderOptions& render, const HeldOutSetup* held_out, PassScores* scores) {
  std::string albedo_folder, roughness_folder;
  SFT_RETURN_IF_ERROR(GroundTruthPath(run.dataset, "albedo", &albedo_folder));
  SFT_RETURN_IF_ERROR(GroundTruthPath(run.dataset, "roughness", &roughness_folder));
  const bool can_render_truth = truth.scene != nullptr;
  RenderOptions albedo_pass = render;
  albedo_pass.pass = RenderPass::kAlbedo;
  RenderOptions roughness_pass = render;
  roughness_pass.pass = RenderPass::kRoughness;
  const Eigen::Vector3d gain = held_out ? held_out->gain : Eigen::Vector3d::Ones();
  for (int v : selected) {
    Image target, mask, ours;
    SFT_RETURN_IF_ERROR(LoadViewImage(run.dataset, v, &target));
    if (!run.dataset.views[v].mask.empty()) {
      SFT_RETURN_IF_ERROR(LoadViewMask(run.dataset, v, &mask));
    }
    RenderView(scene, run.material, views.views[v], render, &ours);
    if (held_out) SFT_RETURN_IF_ERROR(scores->held_out.Add(v, ToRgb(ours), target, mask, gain));
    SFT_RETURN_IF_ERROR(scores->full.Add(v, ScaleChannels(ours, gain), target, mask));
    if (!albedo_folder.empty() || can_render_truth) {
      Image true_pass;
      SFT_RETURN_IF_ERROR(TruePass(run.dataset, v, albedo_folder, truth.scene.get(),
                                   &truth.material, views.views[v], albedo_pass, &true_pass));
      RenderView(scene, run.material, views.views[v], albedo_pass, &ours);
      scores->albedo_pairs.push_back({v, ToRgb(ours), ToRgb(true_pass), mask});
    }
    if (!roughness_folder.empty() || can_render_truth) {
      Image true_pass;
      SFT_RETURN_IF_ERROR(TruePass(run.dataset, v, roughness_folder, truth.scene.get(),
                                   &truth.material, views.views[v], roughness_pass, &true_pass));
      RenderView(scene, run.material, views.views[v], roughness_pass, &ours);
      SFT_RETURN_IF_ERROR(scores->roughness.Add(v, ToRgb(ours), true_pass, mask));
    }
  }
  return Status::Ok();
}

// Scores the albedo pairs; with estimated lighting the albedo is known up to one factor per
// channel, so after the best one (returned).
Status ScoreAlbedo(bool lighting_estimated, PassScores* scores, Eigen::Vector3d* scale) {
  *scale = lighting_estimated ? BestChannelScale(scores->albedo_pairs) : Eigen::Vector3d::Ones();
  for (AlbedoPair& p : scores->albedo_pairs) {
    for (size_t i = 0; i < p.ours.data.size(); ++i) {
      p.ours.data[i] *= static_cast<float>((*scale)[i % 3]);
    }
    SFT_RETURN_IF_ERROR(scores->albedo.Add(p.view, p.ours, p.truth, p.mask));
  }
  return Status::Ok();
}

// {"rel_rmse", "irradiance_rel_rmse", "width", "height"} of the run's fitted map against
// options.true_environment after the albedo's gauge; null without one. An error for a run whose
// lighting was given.
Status ScoreEnvironment(const RunToRender& run, const ReconstructionEvalOptions& options,
                        const Eigen::Vector3d& albedo_scale, json* score) {
  *score = nullptr;
  if (options.true_environment.empty()) return Status::Ok();
  const int light = FittedEnvironmentLight(run.dataset);
  if (!run.lighting_estimated || light < 0) {
    return Status::Error("--true-environment: the dataset's lighting is given, nothing was fitted");
  }
  Image truth;
  SFT_RETURN_IF_ERROR(ReadImage(options.true_environment, &truth));
  const LightSpec& fitted = run.dataset.lights[light];
  Image map = fitted.pixels;
  for (float& value : map.data) value *= static_cast<float>(fitted.scale);
  EnvironmentError error;
  Status status = FittedEnvironmentError(map, ToRgb(truth), albedo_scale, &error);
  if (!status.ok()) return Status::Error(options.true_environment + ": " + status.message());
  *score = {{"rel_rmse", error.radiance},
            {"irradiance_rel_rmse", error.irradiance},
            {"width", map.width},
            {"height", map.height}};
  return Status::Ok();
}

}  // namespace

Status EvaluateReconstruction(const std::string& dataset_dir, const std::string& reconstruction,
                              const ReconstructionEvalOptions& options, json* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("--" + why);
  RunToRender run;
  SFT_RETURN_IF_ERROR(LoadRunToRender(dataset_dir, reconstruction, options, &run));
  Truth truth;
  SFT_RETURN_IF_ERROR(LoadTruth(run.dataset, &truth));
  std::vector<RelightCondition> conditions;
  SFT_RETURN_IF_ERROR(PrepareRelight(run.capture, truth, options, &conditions));
  DatasetViews views;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(run.dataset, &views));
  std::vector<int> selected;
  SFT_RETURN_IF_ERROR(SelectViews(options.views, static_cast<int>(views.views.size()), &selected));
  HeldOutSetup held_out;
  if (options.held_out) {
    SFT_RETURN_IF_ERROR(
        ReadHeldOutSetup(reconstruction, static_cast<int>(views.views.size()), &held_out));
    selected = held_out.views;
  }
  const RenderScene scene(run.mesh);
  const RenderOptions render = EvalRenderOptions(options, run.dataset);
  PassScores scores;
  SFT_RETURN_IF_ERROR(ScoreViews(run, scene, truth, views, selected, render,
                                 options.held_out ? &held_out : nullptr, &scores));
  Eigen::Vector3d albedo_scale;
  SFT_RETURN_IF_ERROR(ScoreAlbedo(run.lighting_estimated, &scores, &albedo_scale));
  json environment;
  SFT_RETURN_IF_ERROR(ScoreEnvironment(run, options, albedo_scale, &environment));
  json relight = nullptr;
  if (!conditions.empty()) {
    RelightInputs inputs;
    inputs.dataset = &run.capture;
    inputs.scene = &scene;
    inputs.material = &run.material;
    inputs.truth = truth.scene.get();
    inputs.true_material = &truth.material;
    inputs.views = selected;
    inputs.render = render;
    inputs.out = options.out;
    SFT_RETURN_IF_ERROR(EvaluateRelighting(inputs, conditions, &relight));
  }
  *report = {{"mode", "reconstruction"},
             {"dataset", dataset_dir},
             {"reconstruction", reconstruction},
             {"mesh", options.mesh.empty() ? JoinPath(reconstruction, "mesh.ply") : options.mesh},
             {"material", options.material.empty() ? JoinPath(reconstruction, "material.json")
                                                   : options.material},
             {"spp", options.spp},
             {"bounces", options.bounces},
             {"views", selected},
             {"psnr_peak", 1.0},
             {"definitions", ViewScoreDefinitions()},
             {"full", scores.full.ToJson()},
             {"albedo", scores.albedo.ToJson()},
             {"lighting", run.lighting_estimated ? "estimated" : "given"},
             {"albedo_scale", {albedo_scale[0], albedo_scale[1], albedo_scale[2]}},
             {"environment", environment},
             {"roughness", scores.roughness.ToJson()},
             {"relight", relight},
             {"held_out", HeldOutJson(options.held_out, held_out, scores.held_out)}};
  return Status::Ok();
}

Status RenderRunViews(const std::string& dataset_dir, const std::string& reconstruction,
                      const std::vector<int>& views, const ReconstructionEvalOptions& options,
                      std::vector<Image>* renders) {
  std::vector<std::vector<Image>> under;
  SFT_RETURN_IF_ERROR(
      RenderRunViewsUnder(dataset_dir, reconstruction, views, options, {nullptr}, &under));
  *renders = std::move(under[0]);
  return Status::Ok();
}

Status RenderRunViewsUnder(const std::string& dataset_dir, const std::string& reconstruction,
                           const std::vector<int>& views, const ReconstructionEvalOptions& options,
                           const std::vector<const RelightCondition*>& lightings,
                           std::vector<std::vector<Image>>* renders) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("--" + why);
  RunToRender run;
  SFT_RETURN_IF_ERROR(LoadRunToRender(dataset_dir, reconstruction, options, &run));
  for (int v : views) {
    if (v < 0 || v >= static_cast<int>(run.dataset.views.size())) {
      return Status::Error("view " + std::to_string(v) + ": not in " + dataset_dir);
    }
  }
  const RenderScene scene(run.mesh);
  const RenderOptions render = EvalRenderOptions(options, run.dataset);
  renders->assign(lightings.size(), {});
  for (size_t i = 0; i < lightings.size(); ++i) {
    const Dataset lit =
        lightings[i] == nullptr ? run.dataset : RelitDataset(run.dataset, *lightings[i]);
    DatasetViews dataset_views;
    SFT_RETURN_IF_ERROR(MakeDatasetViews(lit, &dataset_views));
    for (int v : views) {
      Image image;
      RenderView(scene, run.material, dataset_views.views[v], render, &image);
      (*renders)[i].push_back(ToRgb(image));
    }
  }
  return Status::Ok();
}

}  // namespace sft
