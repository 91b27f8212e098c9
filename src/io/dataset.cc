#include "src/io/dataset.h"

#include <glog/logging.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <cmath>
#include <exception>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/dataset_internal.h"
#include "src/io/lights_file.h"

namespace sft {
namespace dataset_internal {

std::string IndexPath(const std::string& prefix, size_t i) {
  return prefix + "[" + std::to_string(i) + "]";
}

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string StripJsonExceptionId(const std::string& what) {
  if (!what.empty() && what[0] == '[') {
    const size_t end = what.find("] ");
    if (end != std::string::npos) return what.substr(end + 2);
  }
  return what;
}

}  // namespace dataset_internal

namespace {

using json = nlohmann::json;
using dataset_internal::IndexPath;
using dataset_internal::kFormatTag;
using dataset_internal::kSceneFile;
using dataset_internal::SizeText;
using dataset_internal::StripJsonExceptionId;

// Largest deviation of world_from_env^T world_from_env from the identity that still counts as a
// rotation (the file holds decimal numbers written by other tools).
constexpr double kRotationTolerance = 1e-3;
// Keys of each object that ReadDataset interprets; all others are kept verbatim as extras.
using Keys = std::initializer_list<const char*>;
constexpr Keys kTopLevelKeys = {
    "format",         "cameras",       "lights",       "views",        "background",
    "ground_truth",   "sparse_points", "initial_mesh", "dense_points", "source_from_world",
    "image_encoding", "lighting",      "support_plane"};
constexpr Keys kSimilarityKeys = {"scale", "rotation", "translation"};
constexpr Keys kCameraKeys = {"id", "model", "width", "height", "params"};
constexpr Keys kPointLightKeys = {"id", "type", "frame", "position", "intensity"};
constexpr Keys kDirectionalLightKeys = {"id", "type", "frame", "direction", "irradiance"};
constexpr Keys kEnvironmentLightKeys = {
    "id",    "type",          "frame",         "image",       "world_from_env",
    "scale", "ground_normal", "ground_radius", "ground_point"};
constexpr Keys kViewKeys = {"image", "mask", "camera", "lights", "cam_from_world"};
constexpr Keys kPoseKeys = {"rotation", "translation"};

// The members of object `obj` whose keys are not in `known`, as an object; null when none.
json UnknownKeys(const json& obj, Keys known) {
  json extra;
  for (const auto& [key, value] : obj.items()) {
    bool is_known = false;
    for (const char* k : known) is_known = is_known || key == k;
    if (!is_known) extra[key] = value;
  }
  return extra;
}

std::string Field(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

// "string \"abc\"", "number 3", "array" ... for error messages.
std::string Describe(const json& value) {
  if (value.is_string() || value.is_number() || value.is_boolean()) {
    std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return std::string(value.type_name()) + " " + text;
  }
  return value.type_name();
}

// Parses the JSON document of one scene file; every error names the file and the JSON path.
class SceneParser {
 public:
  explicit SceneParser(std::string file) : file_(std::move(file)) {}
  // A lights file (ReadLightsFile) may name probes anywhere: absolute paths and ".." allowed.
  void AllowAnyPath() { any_path_ = true; }

  Status Error(const std::string& path, const std::string& what) const {
    return Status::Error(file_ + ": " + path + ": " + what);
  }

  Status Parse(const json& root, Dataset* dataset) {
    if (!root.is_object()) {
      return Status::Error(file_ + ": expected a JSON object at the top level, got " +
                           Describe(root));
    }
    SFT_RETURN_IF_ERROR(ParseFormat(root));
    SFT_RETURN_IF_ERROR(ParseCameras(root, dataset));
    SFT_RETURN_IF_ERROR(ParseLights(root, dataset));
    SFT_RETURN_IF_ERROR(ParseViews(root, dataset));
    SFT_RETURN_IF_ERROR(ParseBackground(root, dataset));
    SFT_RETURN_IF_ERROR(ParseGroundTruth(root, dataset));
    SFT_RETURN_IF_ERROR(ParseImportKeys(root, dataset));
    SFT_RETURN_IF_ERROR(ParseSupportPlane(root, dataset));
    dataset->extra = UnknownKeys(root, kTopLevelKeys);
    return Status::Ok();
  }

  // A lights file: an object whose "lights" array (required, non-empty) is read like scene.json's.
  Status ParseLightsOnly(const json& root, std::vector<LightSpec>* lights) const {
    if (!root.is_object()) {
      return Status::Error(file_ + ": expected a JSON object at the top level, got " +
                           Describe(root));
    }
    Dataset dataset;
    SFT_RETURN_IF_ERROR(ParseLights(root, &dataset, /*required=*/true));
    *lights = std::move(dataset.lights);
    return Status::Ok();
  }

 private:
  // Member `key` of object `obj`, or null when absent.
  static const json* Find(const json& obj, const char* key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  Status Require(const json& obj, const std::string& prefix, const char* key,
                 const json** value) const {
    *value = Find(obj, key);
    if (*value == nullptr) return Error(Field(prefix, key), "missing");
    return Status::Ok();
  }

  Status String(const json& value, const std::string& path, bool allow_empty,
                std::string* out) const {
    if (!value.is_string()) return Error(path, "expected a string, got " + Describe(value));
    *out = value.get<std::string>();
    if (!allow_empty && out->empty()) return Error(path, "must not be empty");
    return Status::Ok();
  }

  // A file path inside the dataset: relative, no ".." (docs/dataset.md). Readers reject anything
  // else, so that no command can be led outside the dataset (or, mirroring the path under its
  // output folder, outside that) by scene.json.
  Status ContainedPath(const std::string& path, const std::string& value) const {
    if (any_path_ && !value.empty()) return Status::Ok();
    std::string why;
    if (!IsContainedRelativePath(value, &why)) return Error(path, why);
    return Status::Ok();
  }

  Status RequiredString(const json& obj, const std::string& prefix, const char* key,
                        std::string* out) const {
    const json* value = nullptr;
    SFT_RETURN_IF_ERROR(Require(obj, prefix, key, &value));
    return String(*value, Field(prefix, key), /*allow_empty=*/false, out);
  }

  Status Number(const json& value, const std::string& path, double* out) const {
    if (!value.is_number()) return Error(path, "expected a number, got " + Describe(value));
    *out = value.get<double>();
    if (!std::isfinite(*out)) return Error(path, "expected a finite number");
    return Status::Ok();
  }

  Status PositiveInt(const json& value, const std::string& path, int* out) const {
    double v = 0;
    if (!value.is_number() || !Number(value, path, &v).ok() || v != std::floor(v) || v <= 0 ||
        v > std::numeric_limits<int>::max()) {
      return Error(path, "expected a positive integer, got " + Describe(value));
    }
    *out = static_cast<int>(v);
    return Status::Ok();
  }

  // Width and height within kMaxCameraSide and their product within kMaxCameraPixels.
  Status CheckCameraSize(const Camera& camera, const std::string& path) const {
    for (const auto& [key, size] : {std::pair<const char*, int>{"width", camera.width},
                                    std::pair<const char*, int>{"height", camera.height}}) {
      if (size > kMaxCameraSide) {
        return Error(Field(path, key), std::to_string(size) + " is larger than the maximum " +
                                           std::to_string(kMaxCameraSide) + " pixels");
      }
    }
    const int64_t pixels = static_cast<int64_t>(camera.width) * camera.height;
    if (pixels > kMaxCameraPixels) {
      return Error(path, SizeText(camera.width, camera.height) + " has " + std::to_string(pixels) +
                             " pixels, more than the maximum " + std::to_string(kMaxCameraPixels) +
                             " (2^30)");
    }
    return Status::Ok();
  }

  // An array of exactly `n` finite numbers (any length when n < 0).
  Status Numbers(const json& value, const std::string& path, int n,
                 std::vector<double>* out) const {
    const std::string expected =
        n >= 0 ? "expected " + std::to_string(n) + " numbers" : "expected an array of numbers";
    if (!value.is_array()) return Error(path, expected + ", got " + Describe(value));
    if (n >= 0 && value.size() != static_cast<size_t>(n)) {
      return Error(path, expected + ", got " + std::to_string(value.size()));
    }
    out->assign(value.size(), 0.0);
    for (size_t i = 0; i < value.size(); ++i) {
      SFT_RETURN_IF_ERROR(Number(value[i], IndexPath(path, i), &(*out)[i]));
    }
    return Status::Ok();
  }

  Status Vector3(const json& value, const std::string& path, Eigen::Vector3d* out) const {
    std::vector<double> v;
    SFT_RETURN_IF_ERROR(Numbers(value, path, 3, &v));
    *out = Eigen::Vector3d(v[0], v[1], v[2]);
    return Status::Ok();
  }

  Status Array(const json& root, const char* key, bool required, const json** value) const {
    *value = Find(root, key);
    if (*value == nullptr) {
      if (required) return Error(key, "missing");
      return Status::Ok();
    }
    if (!(*value)->is_array()) return Error(key, "expected an array, got " + Describe(**value));
    return Status::Ok();
  }

  Status ParseFormat(const json& root) const {
    const json* format = Find(root, "format");
    if (format == nullptr) {
      return Error("format", std::string("missing (expected \"") + kFormatTag + "\")");
    }
    if (!format->is_string() || format->get<std::string>() != kFormatTag) {
      return Error("format",
                   std::string("expected \"") + kFormatTag + "\", got " + Describe(*format));
    }
    return Status::Ok();
  }

  Status ParseCameras(const json& root, Dataset* dataset) const {
    const json* cameras = nullptr;
    SFT_RETURN_IF_ERROR(Array(root, "cameras", /*required=*/true, &cameras));
    std::map<std::string, size_t> seen;
    for (size_t i = 0; i < cameras->size(); ++i) {
      const json& entry = (*cameras)[i];
      const std::string path = IndexPath("cameras", i);
      if (!entry.is_object()) return Error(path, "expected an object, got " + Describe(entry));
      Camera camera;
      SFT_RETURN_IF_ERROR(RequiredString(entry, path, "id", &camera.id));
      if (const auto it = seen.find(camera.id); it != seen.end()) {
        return Error(Field(path, "id"), "duplicate camera id \"" + camera.id + "\" (also " +
                                            IndexPath("cameras", it->second) + ")");
      }
      seen[camera.id] = i;
      std::string model;
      SFT_RETURN_IF_ERROR(RequiredString(entry, path, "model", &model));
      if (!CameraModelFromName(model, &camera.model)) {
        return Error(Field(path, "model"),
                     "unknown camera model \"" + model +
                         "\" (known: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV)");
      }
      const json* value = nullptr;
      SFT_RETURN_IF_ERROR(Require(entry, path, "width", &value));
      SFT_RETURN_IF_ERROR(PositiveInt(*value, Field(path, "width"), &camera.width));
      SFT_RETURN_IF_ERROR(Require(entry, path, "height", &value));
      SFT_RETURN_IF_ERROR(PositiveInt(*value, Field(path, "height"), &camera.height));
      SFT_RETURN_IF_ERROR(CheckCameraSize(camera, path));
      SFT_RETURN_IF_ERROR(Require(entry, path, "params", &value));
      SFT_RETURN_IF_ERROR(Numbers(*value, Field(path, "params"), -1, &camera.params));
      std::string why;
      if (!camera.Check(&why)) return Status::Error(file_ + ": " + path + "." + why);
      dataset->cameras.push_back(std::move(camera));
      dataset->camera_extra.push_back(UnknownKeys(entry, kCameraKeys));
    }
    return Status::Ok();
  }

  // A light's optional "frame": "world" (the default) or "camera" (it moves with each view).
  Status ParseLightFrame(const json& entry, const std::string& path, LightSpec* light) const {
    if (const json* frame = Find(entry, "frame")) {
      std::string name;
      SFT_RETURN_IF_ERROR(String(*frame, Field(path, "frame"), false, &name));
      if (name == "world") {
        light->frame = LightFrame::kWorld;
      } else if (name == "camera") {
        light->frame = LightFrame::kCamera;
      } else {
        return Error(Field(path, "frame"),
                     "expected \"world\" or \"camera\", got \"" + name + "\"");
      }
    }
    return Status::Ok();
  }

  // Three non-negative numbers, or one grey number g for [g, g, g] (a light's RGB power).
  Status NonNegativeRgb(const json& entry, const std::string& path, const char* key,
                        Eigen::Vector3d* out) const {
    const json* value = nullptr;
    SFT_RETURN_IF_ERROR(Require(entry, path, key, &value));
    const std::string field = Field(path, key);
    if (value->is_number()) {  // a grey light.
      double grey = 0;
      SFT_RETURN_IF_ERROR(Number(*value, field, &grey));
      *out = Eigen::Vector3d::Constant(grey);
    } else {
      SFT_RETURN_IF_ERROR(Vector3(*value, field, out));
    }
    if ((out->array() < 0).any()) return Error(field, "must be non-negative");
    return Status::Ok();
  }

  Status ParsePointLight(const json& entry, const std::string& path, LightSpec* light) const {
    light->type = LightType::kPoint;
    SFT_RETURN_IF_ERROR(ParseLightFrame(entry, path, light));
    const json* value = nullptr;
    SFT_RETURN_IF_ERROR(Require(entry, path, "position", &value));
    SFT_RETURN_IF_ERROR(Vector3(*value, Field(path, "position"), &light->position));
    return NonNegativeRgb(entry, path, "intensity", &light->intensity);
  }

  // "direction": the direction the light travels, normalized here; a zero vector is an error.
  Status ParseDirectionalLight(const json& entry, const std::string& path, LightSpec* light) const {
    light->type = LightType::kDirectional;
    SFT_RETURN_IF_ERROR(ParseLightFrame(entry, path, light));
    const json* value = nullptr;
    SFT_RETURN_IF_ERROR(Require(entry, path, "direction", &value));
    const std::string direction_path = Field(path, "direction");
    SFT_RETURN_IF_ERROR(Vector3(*value, direction_path, &light->direction));
    const double norm = light->direction.norm();
    if (!(norm > 1e-12) || !std::isfinite(norm)) {
      return Error(direction_path, "must have a non-zero finite length");
    }
    // Leave unit directions untouched so that write/read cycles are exact.
    if (std::abs(norm - 1.0) > 4 * std::numeric_limits<double>::epsilon()) {
      light->direction /= norm;
    }
    return NonNegativeRgb(entry, path, "irradiance", &light->irradiance);
  }

  Status ParseEnvironmentLight(const json& entry, const std::string& path, LightSpec* light) const {
    light->type = LightType::kEnvironment;
    SFT_RETURN_IF_ERROR(ParseLightFrame(entry, path, light));
    SFT_RETURN_IF_ERROR(RequiredString(entry, path, "image", &light->image));
    SFT_RETURN_IF_ERROR(ContainedPath(Field(path, "image"), light->image));
    if (const json* matrix = Find(entry, "world_from_env")) {
      const std::string matrix_path = Field(path, "world_from_env");
      if (!matrix->is_array() || matrix->size() != 3) {
        return Error(matrix_path, "expected a 3x3 matrix (3 rows of 3 numbers), got " +
                                      (matrix->is_array() ? std::to_string(matrix->size()) + " rows"
                                                          : Describe(*matrix)));
      }
      for (int r = 0; r < 3; ++r) {
        std::vector<double> row;
        SFT_RETURN_IF_ERROR(Numbers((*matrix)[r], IndexPath(matrix_path, r), 3, &row));
        for (int c = 0; c < 3; ++c) light->world_from_env(r, c) = row[c];
      }
      const Eigen::Matrix3d& m = light->world_from_env;
      const double error = (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
      if (error > kRotationTolerance || m.determinant() <= 0) {
        return Error(matrix_path, "must be a rotation (orthonormal with determinant +1)");
      }
    }
    if (const json* scale = Find(entry, "scale")) {
      SFT_RETURN_IF_ERROR(Number(*scale, Field(path, "scale"), &light->scale));
      if (light->scale < 0) return Error(Field(path, "scale"), "must be non-negative");
    }
    if (const json* ground = Find(entry, "ground_normal")) {
      const std::string ground_path = Field(path, "ground_normal");
      SFT_RETURN_IF_ERROR(Vector3(*ground, ground_path, &light->ground_normal));
      const double norm = light->ground_normal.norm();
      if (!(norm > 1e-12) || !std::isfinite(norm)) {
        return Error(ground_path, "must have a non-zero finite length");
      }
      if (light->frame != LightFrame::kWorld) {
        return Error(ground_path, "only a world-fixed environment can have a ground");
      }
      if (std::abs(norm - 1.0) > 4 * std::numeric_limits<double>::epsilon()) {
        light->ground_normal /= norm;
      }
    }
    return ParseGroundDisc(entry, path, light);
  }

  // "ground_radius" and "ground_point": both or neither, and only with "ground_normal".
  Status ParseGroundDisc(const json& entry, const std::string& path, LightSpec* light) const {
    const json* radius = Find(entry, "ground_radius");
    const json* point = Find(entry, "ground_point");
    if (radius == nullptr && point == nullptr) return Status::Ok();
    const std::string radius_path = Field(path, "ground_radius");
    if (radius == nullptr || point == nullptr) {
      return Error(radius == nullptr ? radius_path : Field(path, "ground_point"),
                   "ground_radius and ground_point go together");
    }
    if (light->ground_normal.isZero()) {
      return Error(radius_path, "needs ground_normal (the disc's plane)");
    }
    SFT_RETURN_IF_ERROR(Number(*radius, radius_path, &light->ground_radius));
    if (!(light->ground_radius > 0) || !std::isfinite(light->ground_radius)) {
      return Error(radius_path, "must be positive and finite");
    }
    return Vector3(*point, Field(path, "ground_point"), &light->ground_point);
  }

  Status ParseLights(const json& root, Dataset* dataset, bool required = false) const {
    const json* lights = nullptr;
    SFT_RETURN_IF_ERROR(Array(root, "lights", required, &lights));
    if (required && lights->empty()) return Error("lights", "expected at least one light");
    if (lights == nullptr) return Status::Ok();
    std::map<std::string, size_t> seen;
    for (size_t i = 0; i < lights->size(); ++i) {
      const json& entry = (*lights)[i];
      const std::string path = IndexPath("lights", i);
      if (!entry.is_object()) return Error(path, "expected an object, got " + Describe(entry));
      LightSpec light;
      SFT_RETURN_IF_ERROR(RequiredString(entry, path, "id", &light.id));
      if (const auto it = seen.find(light.id); it != seen.end()) {
        return Error(Field(path, "id"), "duplicate light id \"" + light.id + "\" (also " +
                                            IndexPath("lights", it->second) + ")");
      }
      seen[light.id] = i;
      std::string type;
      SFT_RETURN_IF_ERROR(RequiredString(entry, path, "type", &type));
      if (type == "point") {
        SFT_RETURN_IF_ERROR(ParsePointLight(entry, path, &light));
        light.extra = UnknownKeys(entry, kPointLightKeys);
      } else if (type == "directional") {
        SFT_RETURN_IF_ERROR(ParseDirectionalLight(entry, path, &light));
        light.extra = UnknownKeys(entry, kDirectionalLightKeys);
      } else if (type == "environment") {
        SFT_RETURN_IF_ERROR(ParseEnvironmentLight(entry, path, &light));
        light.extra = UnknownKeys(entry, kEnvironmentLightKeys);
      } else {
        return Error(Field(path, "type"),
                     "unknown light type \"" + type +
                         "\" (expected \"point\", \"directional\" or \"environment\")");
      }
      dataset->lights.push_back(std::move(light));
    }
    return Status::Ok();
  }

  // A unit quaternion [w, x, y, z]; a non-unit one is normalized, a zero one is an error.
  Status Quaternion(const json& value, const std::string& path, Eigen::Quaterniond* out) const {
    std::vector<double> q;
    SFT_RETURN_IF_ERROR(Numbers(value, path, 4, &q));
    Eigen::Quaterniond quaternion(q[0], q[1], q[2], q[3]);  // (w, x, y, z)
    const double norm = quaternion.norm();
    if (!(norm > 1e-12) || !std::isfinite(norm)) {
      return Error(path, "quaternion must have a non-zero finite norm");
    }
    // Leave already-unit quaternions untouched so that write/read cycles are exact.
    if (std::abs(norm - 1.0) > 4 * std::numeric_limits<double>::epsilon()) {
      quaternion.coeffs() /= norm;
    }
    *out = quaternion;
    return Status::Ok();
  }

  // Also returns the unknown keys of `cam_from_world` in `extra`.
  Status ParsePose(const json& view, const std::string& view_path, Rigid3d* pose,
                   json* extra) const {
    const json* value = nullptr;
    SFT_RETURN_IF_ERROR(Require(view, view_path, "cam_from_world", &value));
    const std::string path = Field(view_path, "cam_from_world");
    if (!value->is_object()) return Error(path, "expected an object, got " + Describe(*value));
    const json* rotation = nullptr;
    SFT_RETURN_IF_ERROR(Require(*value, path, "rotation", &rotation));
    SFT_RETURN_IF_ERROR(Quaternion(*rotation, Field(path, "rotation"), &pose->rotation));
    const json* translation = nullptr;
    SFT_RETURN_IF_ERROR(Require(*value, path, "translation", &translation));
    SFT_RETURN_IF_ERROR(Vector3(*translation, Field(path, "translation"), &pose->translation));
    *extra = UnknownKeys(*value, kPoseKeys);
    return Status::Ok();
  }

  Status ParseViews(const json& root, Dataset* dataset) const {
    const json* views = nullptr;
    SFT_RETURN_IF_ERROR(Array(root, "views", /*required=*/true, &views));
    if (views->empty()) return Error("views", "expected at least one view");
    for (size_t i = 0; i < views->size(); ++i) {
      const json& entry = (*views)[i];
      const std::string path = IndexPath("views", i);
      if (!entry.is_object()) return Error(path, "expected an object, got " + Describe(entry));
      ViewSpec view;
      SFT_RETURN_IF_ERROR(RequiredString(entry, path, "image", &view.image));
      SFT_RETURN_IF_ERROR(ContainedPath(Field(path, "image"), view.image));
      if (const json* mask = Find(entry, "mask"); mask != nullptr && !mask->is_null()) {
        SFT_RETURN_IF_ERROR(String(*mask, Field(path, "mask"), false, &view.mask));
        SFT_RETURN_IF_ERROR(ContainedPath(Field(path, "mask"), view.mask));
      }
      SFT_RETURN_IF_ERROR(RequiredString(entry, path, "camera", &view.camera_id));
      for (size_t c = 0; c < dataset->cameras.size(); ++c) {
        if (dataset->cameras[c].id == view.camera_id) view.camera = static_cast<int>(c);
      }
      if (view.camera < 0) {
        return Error(Field(path, "camera"), "unknown camera \"" + view.camera_id + "\"");
      }
      if (const json* lights = Find(entry, "lights")) {
        const std::string lights_path = Field(path, "lights");
        if (!lights->is_array()) {
          return Error(lights_path, "expected an array of light ids, got " + Describe(*lights));
        }
        for (size_t k = 0; k < lights->size(); ++k) {
          std::string id;
          SFT_RETURN_IF_ERROR(String((*lights)[k], IndexPath(lights_path, k), false, &id));
          int index = -1;
          for (size_t l = 0; l < dataset->lights.size(); ++l) {
            if (dataset->lights[l].id == id) index = static_cast<int>(l);
          }
          if (index < 0) return Error(IndexPath(lights_path, k), "unknown light \"" + id + "\"");
          for (const std::string& other : view.light_ids) {
            if (other == id)
              return Error(IndexPath(lights_path, k), "light \"" + id + "\" listed twice");
          }
          view.light_ids.push_back(id);
          view.lights.push_back(index);
        }
      }
      SFT_RETURN_IF_ERROR(ParsePose(entry, path, &view.cam_from_world, &view.cam_from_world_extra));
      view.extra = UnknownKeys(entry, kViewKeys);
      dataset->views.push_back(std::move(view));
    }
    return Status::Ok();
  }

  Status ParseBackground(const json& root, Dataset* dataset) const {
    const json* value = Find(root, "background");
    if (value == nullptr) return Status::Ok();
    std::string name;
    SFT_RETURN_IF_ERROR(String(*value, "background", false, &name));
    if (name == "black") {
      dataset->background = Background::kBlack;
    } else if (name == "environment") {
      bool has_environment = false;
      for (const LightSpec& light : dataset->lights) {
        has_environment = has_environment || light.type == LightType::kEnvironment;
      }
      if (!has_environment) {
        return Error("background", "\"environment\" needs an environment light in \"lights\"");
      }
      dataset->background = Background::kEnvironment;
    } else {
      return Error("background", "expected \"black\" or \"environment\", got \"" + name + "\"");
    }
    return Status::Ok();
  }

  Status ParseGroundTruth(const json& root, Dataset* dataset) const {
    const json* value = Find(root, "ground_truth");
    if (value == nullptr || value->is_null()) return Status::Ok();
    if (!value->is_object()) {
      return Error("ground_truth", "expected an object, got " + Describe(*value));
    }
    dataset->ground_truth = *value;
    if (const json* mesh = Find(*value, "mesh"); mesh != nullptr && !mesh->is_null()) {
      SFT_RETURN_IF_ERROR(String(*mesh, "ground_truth.mesh", false, &dataset->gt_mesh));
      SFT_RETURN_IF_ERROR(ContainedPath("ground_truth.mesh", dataset->gt_mesh));
    }
    if (const json* shading = Find(*value, "shading"); shading != nullptr && !shading->is_null()) {
      SFT_RETURN_IF_ERROR(String(*shading, "ground_truth.shading", false, &dataset->gt_shading));
      if (dataset->gt_shading != "flat" && dataset->gt_shading != "smooth") {
        return Error("ground_truth.shading",
                     "expected \"flat\" or \"smooth\", got \"" + dataset->gt_shading + "\"");
      }
    }
    return Status::Ok();
  }

  // The optional keys of importers (docs/dataset.md, docs/import.md): file paths follow the
  // dataset's path rules, texts are free, source_from_world is a similarity with scale > 0.
  Status ParseImportKeys(const json& root, Dataset* dataset) const {
    for (const auto& [key, out] :
         {std::pair<const char*, std::string*>{"sparse_points", &dataset->sparse_points},
          {"initial_mesh", &dataset->initial_mesh},
          {"dense_points", &dataset->dense_points}}) {
      if (const json* value = Find(root, key); value != nullptr && !value->is_null()) {
        SFT_RETURN_IF_ERROR(String(*value, key, false, out));
        SFT_RETURN_IF_ERROR(ContainedPath(key, *out));
      }
    }
    for (const auto& [key, out] :
         {std::pair<const char*, std::string*>{"image_encoding", &dataset->image_encoding},
          {"lighting", &dataset->lighting}}) {
      if (const json* value = Find(root, key); value != nullptr && !value->is_null()) {
        SFT_RETURN_IF_ERROR(String(*value, key, true, out));
      }
    }
    const json* value = Find(root, "source_from_world");
    if (value == nullptr || value->is_null()) return Status::Ok();
    const std::string path = "source_from_world";
    if (!value->is_object()) return Error(path, "expected an object, got " + Describe(*value));
    Similarity3d similarity;
    const json* field = nullptr;
    SFT_RETURN_IF_ERROR(Require(*value, path, "scale", &field));
    SFT_RETURN_IF_ERROR(Number(*field, Field(path, "scale"), &similarity.scale));
    if (!(similarity.scale > 0)) {
      return Error(Field(path, "scale"), "expected a positive number, got " + Describe(*field));
    }
    SFT_RETURN_IF_ERROR(Require(*value, path, "rotation", &field));
    SFT_RETURN_IF_ERROR(Quaternion(*field, Field(path, "rotation"), &similarity.rotation));
    SFT_RETURN_IF_ERROR(Require(*value, path, "translation", &field));
    SFT_RETURN_IF_ERROR(Vector3(*field, Field(path, "translation"), &similarity.translation));
    similarity.extra = UnknownKeys(*value, kSimilarityKeys);
    dataset->source_from_world = similarity;
    dataset->has_source_from_world = true;
    return Status::Ok();
  }

  // "support_plane": {"normal": 3 numbers (not zero; normalised on read), "point": 3 numbers}.
  Status ParseSupportPlane(const json& root, Dataset* dataset) const {
    const json* value = Find(root, "support_plane");
    if (value == nullptr || value->is_null()) return Status::Ok();
    const std::string path = "support_plane";
    if (!value->is_object()) return Error(path, "expected an object, got " + Describe(*value));
    const json* field = nullptr;
    SFT_RETURN_IF_ERROR(Require(*value, path, "normal", &field));
    Eigen::Vector3d normal;
    SFT_RETURN_IF_ERROR(Vector3(*field, Field(path, "normal"), &normal));
    if (!(normal.norm() > 1e-12)) return Error(Field(path, "normal"), "must not be zero");
    SFT_RETURN_IF_ERROR(Require(*value, path, "point", &field));
    SFT_RETURN_IF_ERROR(Vector3(*field, Field(path, "point"), &dataset->support_point));
    dataset->support_normal = normal.normalized();
    dataset->has_support_plane = true;
    return Status::Ok();
  }

  std::string file_;
  bool any_path_ = false;
};

std::string ScenePath(const Dataset& dataset) { return JoinPath(dataset.root, kSceneFile); }

}  // namespace

Status ReadDataset(const std::string& dir, Dataset* dataset) {
  const std::string file = JoinPath(dir, kSceneFile);
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    return Status::Error(dir + ": dataset directory not found");
  }
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(file, &text));
  return ParseSceneJson(text, dir, dataset);
}

Status ParseSceneJson(std::string text, const std::string& dir, Dataset* dataset) {
  const std::string file = JoinPath(dir, kSceneFile);
  StripUtf8Bom(&text);  // nlohmann::json skips it too; explicit for every reader.
  try {
    json root;
    try {
      root = json::parse(text);
    } catch (const json::exception& e) {  // parse_error, or out_of_range for 1e999.
      return Status::Error(file + ": invalid JSON: " + StripJsonExceptionId(e.what()));
    }
    Dataset result;
    result.root = dir;
    SFT_RETURN_IF_ERROR(SceneParser(file).Parse(root, &result));
    *dataset = std::move(result);
    return Status::Ok();
  } catch (const std::exception& e) {
    return Status::Error(file + ": " + StripJsonExceptionId(e.what()));
  }
}

Status ParseLightsFileText(std::string text, const std::string& source,
                           std::vector<LightSpec>* lights) {
  StripUtf8Bom(&text);
  try {
    json root;
    try {
      root = json::parse(text);
    } catch (const json::exception& e) {
      return Status::Error(source + ": invalid JSON: " + StripJsonExceptionId(e.what()));
    }
    SceneParser parser(source);
    parser.AllowAnyPath();
    return parser.ParseLightsOnly(root, lights);
  } catch (const std::exception& e) {
    return Status::Error(source + ": " + StripJsonExceptionId(e.what()));
  }
}

Status ReadLightsFile(const std::string& file, std::vector<LightSpec>* lights) {
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(file, &text));
  std::vector<LightSpec> result;
  SFT_RETURN_IF_ERROR(ParseLightsFileText(std::move(text), file, &result));
  const std::string folder = std::filesystem::path(file).parent_path().string();
  for (LightSpec& light : result) {
    // Absolute, so that the light can join any dataset (LoadProbe joins onto its root).
    if (light.type == LightType::kEnvironment) {
      light.image = std::filesystem::absolute(JoinPath(folder, light.image)).string();
    }
  }
  *lights = std::move(result);
  return Status::Ok();
}

Status CheckViewsHaveLights(const Dataset& dataset) {
  for (size_t i = 0; i < dataset.views.size(); ++i) {
    if (dataset.views[i].lights.empty()) {
      return Status::Error(ScenePath(dataset) + ": " + IndexPath("views", i) +
                           ".lights: empty (unknown lighting" +
                           (dataset.lighting.empty() ? "" : ": \"" + dataset.lighting + "\"") +
                           "); rendering needs every view's lights (sft reconstruct estimates "
                           "unknown lighting, and sft eval renders a run's fitted lighting)");
    }
  }
  return Status::Ok();
}

std::vector<std::string> ViewOutputPaths(const Dataset& dataset, const std::string& extension) {
  std::vector<std::string> paths;
  std::set<std::string> taken;
  for (size_t v = 0; v < dataset.views.size(); ++v) {
    std::filesystem::path relative(dataset.views[v].image);
    auto first = relative.begin();
    if (first != relative.end() && *first == "images" && std::next(first) != relative.end()) {
      std::filesystem::path rest;
      for (auto it = std::next(first); it != relative.end(); ++it) rest /= *it;
      relative = rest;
    }
    relative.replace_extension(extension);
    std::filesystem::path path = (std::filesystem::path("images") / relative).lexically_normal();
    char suffix[32];
    std::snprintf(suffix, sizeof(suffix), "_view%03zu", v);
    std::string stem = path.stem().string();
    while (taken.count(path.string()) > 0) {
      stem += suffix;
      path.replace_filename(stem + extension);
    }
    taken.insert(path.string());
    paths.push_back(path.string());
  }
  return paths;
}

}  // namespace sft
