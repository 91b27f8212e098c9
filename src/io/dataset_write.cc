// WriteSceneJson of src/io/dataset.h: the scene.json writer (the reader is dataset.cc).
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "src/core/file_util.h"
#include "src/io/dataset.h"
#include "src/io/dataset_internal.h"
#include "src/io/lights_file.h"

namespace sft {
namespace {

using json = nlohmann::json;
using ojson = nlohmann::ordered_json;
using dataset_internal::IndexPath;

// Appends the members of `extra` (when it is an object) to `entry`, except keys `entry` already
// has: documented keys win over same-named extras.
void AppendExtra(const json& extra, ojson* entry) {
  if (!extra.is_object()) return;
  for (const auto& [key, value] : extra.items()) {
    if (!entry->contains(key)) (*entry)[key] = value;
  }
}

ojson CamerasJson(const Dataset& dataset) {
  ojson cameras = ojson::array();
  for (size_t i = 0; i < dataset.cameras.size(); ++i) {
    const Camera& camera = dataset.cameras[i];
    ojson entry;
    entry["id"] = camera.id;
    entry["model"] = CameraModelName(camera.model);
    entry["width"] = camera.width;
    entry["height"] = camera.height;
    entry["params"] = camera.params;
    if (i < dataset.camera_extra.size()) AppendExtra(dataset.camera_extra[i], &entry);
    cameras.push_back(std::move(entry));
  }
  return cameras;
}

ojson LightsJson(const std::vector<LightSpec>& specs) {
  ojson lights = ojson::array();
  for (const LightSpec& light : specs) {
    ojson entry;
    entry["id"] = light.id;
    if (light.type == LightType::kPoint) {
      entry["type"] = "point";
      entry["frame"] = light.frame == LightFrame::kCamera ? "camera" : "world";
      entry["position"] = {light.position.x(), light.position.y(), light.position.z()};
      entry["intensity"] = {light.intensity.x(), light.intensity.y(), light.intensity.z()};
    } else if (light.type == LightType::kDirectional) {
      entry["type"] = "directional";
      entry["frame"] = light.frame == LightFrame::kCamera ? "camera" : "world";
      entry["direction"] = {light.direction.x(), light.direction.y(), light.direction.z()};
      entry["irradiance"] = {light.irradiance.x(), light.irradiance.y(), light.irradiance.z()};
    } else {
      entry["type"] = "environment";
      if (light.frame == LightFrame::kCamera) entry["frame"] = "camera";
      entry["image"] = light.image;
      ojson matrix = ojson::array();
      for (int r = 0; r < 3; ++r) {
        matrix.push_back(
            {light.world_from_env(r, 0), light.world_from_env(r, 1), light.world_from_env(r, 2)});
      }
      entry["world_from_env"] = std::move(matrix);
      entry["scale"] = light.scale;
      if (!light.ground_normal.isZero()) {
        entry["ground_normal"] = {light.ground_normal.x(), light.ground_normal.y(),
                                  light.ground_normal.z()};
      }
      if (light.ground_radius > 0) {
        entry["ground_radius"] = light.ground_radius;
        entry["ground_point"] = {light.ground_point.x(), light.ground_point.y(),
                                 light.ground_point.z()};
      }
    }
    AppendExtra(light.extra, &entry);
    lights.push_back(std::move(entry));
  }
  return lights;
}

// The camera id to write for `view` (errors prefixed by `where`, "FILE: views[i]"). A view built
// in code may carry an index or an id: whichever is set is used, disagreement is an error, and a
// reference ReadDataset would reject is never written.
Status ViewCameraId(const Dataset& dataset, const ViewSpec& view, const std::string& where,
                    std::string* camera_id) {
  *camera_id = view.camera_id;
  if (view.camera >= 0 && view.camera < static_cast<int>(dataset.cameras.size())) {
    const std::string& by_index = dataset.cameras[view.camera].id;
    if (!camera_id->empty() && *camera_id != by_index) {
      return Status::Error(where + ".camera: camera_id \"" + *camera_id +
                           "\" disagrees with camera index " + std::to_string(view.camera));
    }
    *camera_id = by_index;
  }
  for (const Camera& camera : dataset.cameras) {
    if (camera.id == *camera_id) return Status::Ok();
  }
  return Status::Error(where + ".camera: unknown camera \"" + *camera_id + "\"");
}

// The light ids to write for `view`, by the same rules as ViewCameraId.
Status ViewLightIds(const Dataset& dataset, const ViewSpec& view, const std::string& where,
                    std::vector<std::string>* light_ids) {
  light_ids->clear();
  for (int l : view.lights) {
    if (l < 0 || l >= static_cast<int>(dataset.lights.size())) {
      return Status::Error(where + ".lights: light index " + std::to_string(l) + " out of range");
    }
    light_ids->push_back(dataset.lights[l].id);
  }
  if (view.lights.empty()) {
    *light_ids = view.light_ids;
  } else if (!view.light_ids.empty() && view.light_ids != *light_ids) {
    return Status::Error(where + ".lights: light_ids disagree with light indices");
  }
  for (const std::string& id : *light_ids) {
    bool known = false;
    for (const LightSpec& light : dataset.lights) known = known || light.id == id;
    if (!known) return Status::Error(where + ".lights: unknown light \"" + id + "\"");
  }
  return Status::Ok();
}

Status ViewsJson(const Dataset& dataset, const std::string& file, ojson* views) {
  *views = ojson::array();
  for (size_t i = 0; i < dataset.views.size(); ++i) {
    const ViewSpec& view = dataset.views[i];
    const std::string where = file + ": " + IndexPath("views", i);
    std::string camera_id;
    SFT_RETURN_IF_ERROR(ViewCameraId(dataset, view, where, &camera_id));
    std::vector<std::string> light_ids;
    SFT_RETURN_IF_ERROR(ViewLightIds(dataset, view, where, &light_ids));
    ojson entry;
    entry["image"] = view.image;
    if (!view.mask.empty()) entry["mask"] = view.mask;
    entry["camera"] = camera_id;
    entry["lights"] = light_ids;
    const Eigen::Quaterniond& q = view.cam_from_world.rotation;
    const Eigen::Vector3d& t = view.cam_from_world.translation;
    entry["cam_from_world"]["rotation"] = {q.w(), q.x(), q.y(), q.z()};
    entry["cam_from_world"]["translation"] = {t.x(), t.y(), t.z()};
    AppendExtra(view.cam_from_world_extra, &entry["cam_from_world"]);
    AppendExtra(view.extra, &entry);
    views->push_back(std::move(entry));
  }
  return Status::Ok();
}

// ground_truth and the optional keys importers write (docs/dataset.md, docs/import.md).
void AppendOptionalKeys(const Dataset& dataset, ojson* root) {
  ojson ground_truth;
  if (dataset.ground_truth.is_object()) ground_truth = dataset.ground_truth;
  if (!dataset.gt_mesh.empty()) ground_truth["mesh"] = dataset.gt_mesh;
  if (!ground_truth.is_null()) (*root)["ground_truth"] = std::move(ground_truth);
  if (!dataset.sparse_points.empty()) (*root)["sparse_points"] = dataset.sparse_points;
  if (!dataset.initial_mesh.empty()) (*root)["initial_mesh"] = dataset.initial_mesh;
  if (!dataset.dense_points.empty()) (*root)["dense_points"] = dataset.dense_points;
  if (dataset.has_source_from_world) {
    const Similarity3d& s = dataset.source_from_world;
    ojson entry;
    entry["scale"] = s.scale;
    entry["rotation"] = {s.rotation.w(), s.rotation.x(), s.rotation.y(), s.rotation.z()};
    entry["translation"] = {s.translation.x(), s.translation.y(), s.translation.z()};
    AppendExtra(s.extra, &entry);
    (*root)["source_from_world"] = std::move(entry);
  }
  if (dataset.has_support_plane) {
    const Eigen::Vector3d& n = dataset.support_normal;
    const Eigen::Vector3d& p = dataset.support_point;
    (*root)["support_plane"] = {{"normal", {n.x(), n.y(), n.z()}},
                                {"point", {p.x(), p.y(), p.z()}}};
  }
  if (!dataset.image_encoding.empty()) (*root)["image_encoding"] = dataset.image_encoding;
  if (!dataset.lighting.empty()) (*root)["lighting"] = dataset.lighting;
}

}  // namespace

Status WriteSceneJson(const Dataset& dataset, const std::string& dir) {
  const std::string file = JoinPath(dir, dataset_internal::kSceneFile);
  try {
    ojson root;
    root["format"] = dataset_internal::kFormatTag;
    root["cameras"] = CamerasJson(dataset);
    root["lights"] = LightsJson(dataset.lights);
    ojson views;
    SFT_RETURN_IF_ERROR(ViewsJson(dataset, file, &views));
    root["views"] = std::move(views);
    root["background"] = dataset.background == Background::kEnvironment ? "environment" : "black";
    AppendOptionalKeys(dataset, &root);
    AppendExtra(dataset.extra, &root);
    return WriteTextFile(file, root.dump(1, ' ', false, json::error_handler_t::replace) + "\n");
  } catch (const std::exception& e) {
    return Status::Error(file + ": cannot serialize scene (" +
                         dataset_internal::StripJsonExceptionId(e.what()) + ")");
  }
}

Status LightsFileText(const std::vector<LightSpec>& lights, std::string* text) {
  try {
    ojson root;
    root["lights"] = LightsJson(lights);
    *text = root.dump(1, ' ', false, json::error_handler_t::replace) + "\n";
    return Status::Ok();
  } catch (const std::exception& e) {
    return Status::Error("cannot serialize lights (" +
                         dataset_internal::StripJsonExceptionId(e.what()) + ")");
  }
}

Status WriteLightsFile(const std::string& file, const std::vector<LightSpec>& lights) {
  std::string text;
  SFT_RETURN_IF_ERROR(LightsFileText(lights, &text).Prefixed(file));
  return WriteTextFile(file, text);
}

}  // namespace sft
