#include "src/io/nerf_transforms.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"
#include "src/io/dataset.h"
#include "src/io/pinhole_matrices.h"

namespace sft {
namespace {

using nlohmann::json;

// Reads the intrinsics keys present in `object` into `out` (keeping what is already there when a
// key is absent). `path` is the object's JSON path for errors ("" at the top level).
Status ReadIntrinsics(const json& object, const std::string& file, const std::string& path,
                      NerfIntrinsics* out) {
  auto where = [&](const char* key) { return file + ": " + path + key; };
  for (const char* key : {"fl_x", "fl_y", "cx", "cy", "camera_angle_x", "camera_angle_y", "k1",
                          "k2", "k3", "k4", "p1", "p2"}) {
    const auto it = object.find(key);
    if (it == object.end()) continue;
    if (!it->is_number() || !std::isfinite(it->get<double>())) {
      return Status::Error(where(key) + ": expected a finite number");
    }
    const double v = it->get<double>();
    const std::string k = key;
    if (k == "fl_x") out->fl_x = v;
    if (k == "fl_y") out->fl_y = v;
    if (k == "cx") out->cx = v;
    if (k == "cy") out->cy = v;
    if (k == "camera_angle_x") out->angle_x = v;
    if (k == "camera_angle_y") out->angle_y = v;
    if (k == "k1") out->k1 = v;
    if (k == "k2") out->k2 = v;
    if (k == "p1") out->p1 = v;
    if (k == "p2") out->p2 = v;
    if ((k == "k3" || k == "k4") && v != 0) {
      return Status::Error(where(key) + ": radial distortion beyond k2 is not supported (sft's " +
                           "OPENCV model has k1, k2, p1, p2)");
    }
    if ((k == "camera_angle_x" || k == "camera_angle_y") && !(v > 0 && v < M_PI)) {
      return Status::Error(where(key) + ": must be in (0, pi) radians");
    }
  }
  for (const char* key : {"w", "h"}) {
    const auto it = object.find(key);
    if (it == object.end()) continue;
    // 800 and 800.0 are both common.
    const double v = it->is_number() ? it->get<double>() : -1;
    if (!(v >= 1 && v <= kMaxCameraSide && v == std::floor(v))) {
      return Status::Error(where(key) + ": expected a positive integer up to " +
                           std::to_string(kMaxCameraSide));
    }
    (std::string(key) == "w" ? out->w : out->h) = static_cast<int>(v);
  }
  const auto model = object.find("camera_model");
  if (model != object.end()) {
    const std::string name = model->is_string() ? model->get<std::string>() : "";
    if (name != "OPENCV" && name != "PINHOLE" && name != "SIMPLE_PINHOLE") {
      return Status::Error(
          where("camera_model") + ": " +
          (model->is_string() ? "\"" + name.substr(0, 32) + "\"" : "not a string") +
          " is not supported (OPENCV, PINHOLE or SIMPLE_PINHOLE)");
    }
  }
  return Status::Ok();
}

Status ReadPose(const json& frame, const std::string& where, Rigid3d* cam_from_world) {
  const auto it = frame.find("transform_matrix");
  if (it == frame.end()) return Status::Error(where + ": missing");
  const json& m = *it;
  Eigen::Matrix4d c2w;
  bool ok = m.is_array() && m.size() == 4;
  for (int r = 0; ok && r < 4; ++r) {
    ok = m[r].is_array() && m[r].size() == 4;
    for (int c = 0; ok && c < 4; ++c) {
      ok = m[r][c].is_number() && std::isfinite(m[r][c].get<double>());
      if (ok) c2w(r, c) = m[r][c].get<double>();
    }
  }
  if (!ok) return Status::Error(where + ": expected 4 rows of 4 finite numbers");
  if (!((c2w.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() <= 1e-6)) {
    return Status::Error(where + ": the last row must be 0 0 0 1");
  }
  // OpenGL camera axes (x right, y up, looking down −z) to sft's (x right, y down, looking +z).
  const Eigen::Matrix3d world_from_cam =
      c2w.topLeftCorner<3, 3>() * Eigen::Vector3d(1, -1, -1).asDiagonal();
  Eigen::Quaterniond world_from_cam_q;
  std::string why;
  if (!RotationFromMatrix(world_from_cam, &world_from_cam_q, &why)) {
    return Status::Error(where + ": rotation block: " + why);
  }
  cam_from_world->rotation = world_from_cam_q.conjugate();
  cam_from_world->translation = -(cam_from_world->rotation * c2w.topRightCorner<3, 1>());
  return Status::Ok();
}

std::string StripExceptionId(const std::string& what) {
  const size_t at = what.find("] ");
  return what.rfind("[json.exception.", 0) == 0 && at != std::string::npos ? what.substr(at + 2)
                                                                           : what;
}

}  // namespace

Status ParseNerfTransforms(const std::string& text, const std::string& file,
                           std::vector<NerfFrame>* frames) {
  frames->clear();
  try {
    std::string contents = text;
    StripUtf8Bom(&contents);
    const json root = json::parse(contents);
    if (!root.is_object()) return Status::Error(file + ": expected a JSON object");
    NerfIntrinsics global;
    SFT_RETURN_IF_ERROR(ReadIntrinsics(root, file, "", &global));
    const auto list = root.find("frames");
    if (list == root.end() || !list->is_array() || list->empty()) {
      return Status::Error(file + ": frames: expected a non-empty array");
    }
    for (size_t i = 0; i < list->size(); ++i) {
      const std::string path = "frames[" + std::to_string(i) + "]";
      const json& f = (*list)[i];
      if (!f.is_object()) return Status::Error(file + ": " + path + ": expected an object");
      NerfFrame frame;
      frame.intrinsics = global;
      SFT_RETURN_IF_ERROR(ReadIntrinsics(f, file, path + ".", &frame.intrinsics));
      const auto name = f.find("file_path");
      if (name == f.end() || !name->is_string()) {
        return Status::Error(file + ": " + path + ".file_path: expected a string");
      }
      frame.file_path = name->get<std::string>();
      std::string why;
      if (!IsContainedRelativePath(frame.file_path, &why)) {
        return Status::Error(file + ": " + path + ".file_path: \"" + frame.file_path.substr(0, 64) +
                             "\": " + why);
      }
      SFT_RETURN_IF_ERROR(
          ReadPose(f, file + ": " + path + ".transform_matrix", &frame.cam_from_world));
      frames->push_back(std::move(frame));
    }
  } catch (const json::exception& e) {
    return Status::Error(file + ": " + StripExceptionId(e.what()));
  }
  return Status::Ok();
}

Status NerfCamera(const NerfIntrinsics& in, int width, int height, const std::string& where,
                  Camera* camera) {
  if ((in.w && *in.w != width) || (in.h && *in.h != height)) {
    return Status::Error(where + ": the image is " + std::to_string(width) + "x" +
                         std::to_string(height) +
                         " but the intrinsics are for w=" + (in.w ? std::to_string(*in.w) : "?") +
                         ", h=" + (in.h ? std::to_string(*in.h) : "?"));
  }
  std::optional<double> fx = in.fl_x, fy = in.fl_y;
  if (!fx && in.angle_x) fx = 0.5 * width / std::tan(0.5 * *in.angle_x);
  if (!fy && in.angle_y) fy = 0.5 * height / std::tan(0.5 * *in.angle_y);
  if (!fx) fx = fy;
  if (!fy) fy = fx;
  if (!fx) {
    return Status::Error(where +
                         ": no focal length (fl_x, fl_y, camera_angle_x or "
                         "camera_angle_y)");
  }
  const double cx = in.cx.value_or(0.5 * width), cy = in.cy.value_or(0.5 * height);
  camera->width = width;
  camera->height = height;
  const bool distorted = in.k1 != 0 || in.k2 != 0 || in.p1 != 0 || in.p2 != 0;
  camera->model = distorted ? CameraModel::kOpenCV : CameraModel::kPinhole;
  camera->params = {*fx, *fy, cx, cy};
  if (distorted) camera->params.insert(camera->params.end(), {in.k1, in.k2, in.p1, in.p2});
  std::string why;
  if (!camera->Check(&why)) return Status::Error(where + ": " + why);
  return Status::Ok();
}

}  // namespace sft
