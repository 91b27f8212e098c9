#include "src/eval/relight_eval.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "src/core/file_util.h"
#include "src/eval/view_scores.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/lights_file.h"
#include "src/io/scene_setup.h"

namespace sft {
namespace {

using json = nlohmann::json;

constexpr char kProbePrefix[] = "probe:";

// The dataset's own lights as a condition.
RelightCondition CaptureCondition(const Dataset& dataset) {
  RelightCondition c;
  c.name = "capture";
  c.source = "capture";
  c.lights = dataset.lights;
  for (const ViewSpec& view : dataset.views) c.view_lights.push_back(view.lights);
  return c;
}

// "side": each view's capture point lights turned by 90° about `centre` towards world +z.
Status SideCondition(const Dataset& dataset, const Eigen::Vector3d& centre, RelightCondition* c) {
  c->name = "side";
  c->source = "side";
  for (size_t v = 0; v < dataset.views.size(); ++v) {
    const ViewSpec& view = dataset.views[v];
    const Rigid3d world_from_cam = view.cam_from_world.Inverse();
    std::vector<int> indices;
    for (int l : view.lights) {
      const LightSpec& light = dataset.lights[l];
      if (light.type != LightType::kPoint) continue;
      const Eigen::Vector3d p =
          light.frame == LightFrame::kCamera ? world_from_cam * light.position : light.position;
      const Eigen::Vector3d d = p - centre;
      const double r = d.norm();
      if (!(r > 0.0)) continue;  // a light at the centre has no direction to turn.
      const Eigen::Vector3d dir = d / r;
      // The unit vector perpendicular to dir in the plane of dir and +z (or +x).
      Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
      if ((up - up.dot(dir) * dir).norm() < 1e-3) up = Eigen::Vector3d::UnitX();
      const Eigen::Vector3d turned = (up - up.dot(dir) * dir).normalized();
      LightSpec moved = light;
      moved.id = light.id + "_side_view" + std::to_string(v);
      moved.frame = LightFrame::kWorld;
      moved.position = centre + r * turned;
      indices.push_back(static_cast<int>(c->lights.size()));
      c->lights.push_back(std::move(moved));
    }
    if (indices.empty()) {
      return Status::Error("--relight side: views[" + std::to_string(v) +
                           "] has no point light to turn (capture lights: " +
                           std::to_string(view.lights.size()) + ")");
    }
    c->view_lights.push_back(std::move(indices));
  }
  return Status::Ok();
}

// A folder name for condition k: "NN_name" with unsafe characters replaced.
std::string ConditionFolder(size_t k, const std::string& name) {
  char prefix[32];  // room for any size_t.
  std::snprintf(prefix, sizeof(prefix), "%02zu_", k);
  std::string safe = name;
  for (char& ch : safe) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '-' || ch == '_';
    if (!ok) ch = '_';
  }
  return prefix + safe;
}

}  // namespace

Dataset RelitDataset(const Dataset& dataset, const RelightCondition& c) {
  Dataset relit = dataset;
  relit.lights = c.lights;
  relit.background = Background::kBlack;
  std::vector<int> all;
  for (size_t l = 0; l < c.lights.size(); ++l) all.push_back(static_cast<int>(l));
  for (size_t v = 0; v < relit.views.size(); ++v) {
    relit.views[v].lights = c.view_lights.empty() ? all : c.view_lights[v];
    relit.views[v].light_ids.clear();
    for (int l : relit.views[v].lights) relit.views[v].light_ids.push_back(c.lights[l].id);
  }
  return relit;
}

namespace {

// Renders and scores condition k, writing the renders under inputs.out when set.
Status ScoreCondition(const RelightInputs& in, const RelightCondition& c, size_t k,
                      const std::vector<std::string>& out_paths, json* result) {
  const Dataset relit = RelitDataset(*in.dataset, c);
  DatasetViews views;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(relit, &views).Prefixed("--relight " + c.source));
  const std::string folder =
      in.out.empty() ? "" : JoinPath(JoinPath(in.out, "relight"), ConditionFolder(k, c.name));
  ViewScores scores;
  for (int v : in.views) {
    Image mask, ours, truth;
    if (!in.dataset->views[v].mask.empty()) {
      SFT_RETURN_IF_ERROR(LoadViewMask(*in.dataset, v, &mask));
    }
    RenderView(*in.scene, *in.material, views.views[v], in.render, &ours);
    RenderView(*in.truth, *in.true_material, views.views[v], in.render, &truth);
    ours = ToRgb(ours);
    truth = ToRgb(truth);
    SFT_RETURN_IF_ERROR(scores.Add(v, ours, truth, mask).Prefixed("relight " + c.name));
    if (!folder.empty()) {
      SFT_RETURN_IF_ERROR(WriteExr(JoinPath(JoinPath(folder, "ours"), out_paths[v]), ours));
      SFT_RETURN_IF_ERROR(WriteExr(JoinPath(JoinPath(folder, "truth"), out_paths[v]), truth));
    }
  }
  *result = scores.ToJson();
  (*result)["name"] = c.name;
  (*result)["source"] = c.source;
  if (!folder.empty()) (*result)["images"] = folder;
  return Status::Ok();
}

}  // namespace

Status MakeRelightConditions(const std::vector<std::string>& specs, const Dataset& dataset,
                             const Eigen::Vector3d& centre,
                             std::vector<RelightCondition>* conditions) {
  std::vector<RelightCondition> result = {CaptureCondition(dataset)};
  for (const std::string& spec : specs) {
    if (spec == "side") {
      RelightCondition c;
      SFT_RETURN_IF_ERROR(SideCondition(dataset, centre, &c));
      result.push_back(std::move(c));
    } else if (spec.rfind(kProbePrefix, 0) == 0) {
      const std::string path = spec.substr(sizeof(kProbePrefix) - 1);
      if (path.empty()) return Status::Error("--relight " + spec + ": expected probe:PATH.exr");
      if (!FileExists(path))
        return Status::Error("--relight " + spec + ": " + path + ": file not found");
      RelightCondition c;
      c.name = kProbePrefix + std::filesystem::path(path).stem().string();
      c.source = spec;
      LightSpec light;
      light.id = c.name;
      light.type = LightType::kEnvironment;
      light.image = std::filesystem::absolute(path).string();
      c.lights.push_back(std::move(light));
      result.push_back(std::move(c));
    } else {
      std::vector<LightSpec> lights;
      SFT_RETURN_IF_ERROR(ReadLightsFile(spec, &lights).Prefixed("--relight"));
      for (LightSpec& light : lights) {
        RelightCondition c;
        c.name = light.id;
        c.source = spec;
        c.lights.push_back(std::move(light));
        result.push_back(std::move(c));
      }
    }
  }
  for (size_t i = 0; i < result.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (result[i].name == result[j].name) {
        return Status::Error("--relight " + result[i].source + ": condition \"" + result[i].name +
                             "\" appears twice (also from " + result[j].source + ")");
      }
    }
  }
  *conditions = std::move(result);
  return Status::Ok();
}

Status EvaluateRelighting(const RelightInputs& inputs,
                          const std::vector<RelightCondition>& conditions, json* relight) {
  const std::vector<std::string> out_paths = ViewOutputPaths(*inputs.dataset, ".exr");
  json list = json::array();
  const char* kKeys[] = {"psnr_srgb", "ssim_srgb", "psnr_linear", "ssim_linear"};
  json novel_mean = nullptr;
  int novel = 0;
  for (size_t k = 0; k < conditions.size(); ++k) {
    json result;
    SFT_RETURN_IF_ERROR(ScoreCondition(inputs, conditions[k], k, out_paths, &result));
    if (conditions[k].source != "capture" && result.contains("psnr_srgb")) {
      if (novel_mean.is_null()) novel_mean = json::object();
      for (const char* key : kKeys) {
        novel_mean[key] = novel_mean.value(key, 0.0) + result[key].get<double>();
      }
      ++novel;
    }
    list.push_back(std::move(result));
  }
  if (novel > 0) {
    for (const char* key : kKeys) novel_mean[key] = novel_mean[key].get<double>() / novel;
  }
  *relight = {{"conditions", list}, {"novel_mean", novel_mean}};
  return Status::Ok();
}

}  // namespace sft
