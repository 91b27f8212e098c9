#include "src/optim/pose_corrections.h"

#include <glog/logging.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <nlohmann/json.hpp>

#include "src/render/environment.h"

namespace sft {
namespace {

using json = nlohmann::json;
using Row6 = Eigen::Matrix<double, 1, 6>;

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace

Rigid3d CorrectedCamFromWorld(const Rigid3d& cam_from_world, const PoseDelta& delta) {
  const Eigen::Matrix3d turn = RotationFromVector(delta.head<3>());
  Rigid3d out;
  out.rotation = Eigen::Quaterniond(turn * cam_from_world.rotation.toRotationMatrix());
  out.rotation.normalize();
  out.translation = turn * cam_from_world.translation + delta.tail<3>();
  return out;
}

void ApplyPoseCorrection(const PoseDelta& delta, ViewSetup* view) {
  if (delta.isZero(0.0)) return;
  const Rigid3d old_cam_from_world = view->cam_from_world;
  view->cam_from_world = CorrectedCamFromWorld(old_cam_from_world, delta);
  const Rigid3d world_from_cam = view->cam_from_world.Inverse();
  for (PointLight& light : view->point_lights) {
    if (light.camera_frame) light.position = world_from_cam * (old_cam_from_world * light.position);
  }
  for (DirectionalLight& light : view->directional_lights) {
    if (light.camera_frame) {
      light.direction = world_from_cam.rotation * (old_cam_from_world.rotation * light.direction);
    }
  }
}

void AddPoseChainSelection(ParameterSelection* selection) {
  selection->vertices = true;
  selection->light_positions = true;
  selection->light_directions = true;
  selection->environment_rotations = true;
}

PoseChain::PoseChain(const ParameterLayout& layout, const ViewSetup& view, const PoseDelta& delta,
                     const std::vector<Eigen::Vector3d>& positions,
                     const std::vector<Eigen::Vector3d>& light_directions) {
  CHECK_EQ(static_cast<int>(positions.size()), layout.num_vertices);
  rotation_ = view.cam_from_world.rotation.toRotationMatrix();
  world_from_cam_ = rotation_.transpose();
  left_ = RotationLeftJacobian(delta.head<3>());
  translation_ = view.cam_from_world.translation - delta.tail<3>();
  vertex_rows_.resize(3 * positions.size());
  for (size_t v = 0; v < positions.size(); ++v) {
    const Eigen::Matrix<double, 3, 6> m = PointJacobian(positions[v]);
    for (int k = 0; k < 3; ++k) vertex_rows_[3 * v + k] = m.row(k);
  }
  light_offset_ = layout.LightPositionOffset();
  light_rows_.assign(layout.size() - light_offset_, Row6::Zero());
  light_moves_.assign(light_rows_.size(), false);
  const auto set = [&](int param, const Eigen::Matrix<double, 3, 6>& m) {
    for (int k = 0; k < 3; ++k) {
      light_rows_[param - light_offset_ + k] = m.row(k);
      light_moves_[param - light_offset_ + k] = true;
    }
  };
  // The world rotation b = R'ᵀ·J_l(ω)·dω that turns world-fixed directions.
  const Eigen::Matrix3d turn = world_from_cam_ * left_;
  for (const PointLight& light : view.point_lights) {
    if (light.camera_frame || !layout.FitsLightPosition(light.light_index)) continue;
    set(layout.LightPositionOffset() + 3 * light.light_index, PointJacobian(light.position));
  }
  for (const DirectionalLight& light : view.directional_lights) {
    if (light.camera_frame || !layout.FitsLightDirection(light.light_index)) continue;
    Eigen::Matrix<double, 3, 6> m = Eigen::Matrix<double, 3, 6>::Zero();
    m.leftCols<3>() = -Hat(light_directions.at(light.light_index)) * turn;
    set(layout.LightDirectionOffset() + 3 * light.light_index, m);
  }
  if (view.environment != nullptr && layout.FitsEnvironmentRotation(view.environment_light_index)) {
    Eigen::Matrix<double, 3, 6> m = Eigen::Matrix<double, 3, 6>::Zero();
    m.leftCols<3>() = view.environment_rotation_jacobian.inverse() * turn;
    set(layout.EnvironmentRotationOffset() + 3 * view.environment_light_index, m);
  }
}

Eigen::Matrix<double, 3, 6> PoseChain::PointJacobian(const Eigen::Vector3d& x) const {
  const Eigen::Vector3d q = rotation_ * x + translation_;
  Eigen::Matrix<double, 3, 6> m;
  m.leftCols<3>() = -world_from_cam_ * Hat(q) * left_;
  m.rightCols<3>() = world_from_cam_;
  return m;
}

const Eigen::Matrix<double, 1, 6>* PoseChain::Derivative(int param) const {
  if (param >= 0 && param < static_cast<int>(vertex_rows_.size())) return &vertex_rows_[param];
  const int k = param - light_offset_;
  if (k >= 0 && k < static_cast<int>(light_rows_.size()) && light_moves_[k]) {
    return &light_rows_[k];
  }
  return nullptr;
}

PoseDelta PoseChain::Contract(const std::vector<double>& gradient) const {
  Row6 sum = Row6::Zero();
  for (size_t i = 0; i < gradient.size(); ++i) {
    if (gradient[i] == 0.0) continue;
    const Row6* d = Derivative(static_cast<int>(i));
    if (d != nullptr) sum += gradient[i] * *d;
  }
  return sum.transpose();
}

LevelRows PoseRows(const LevelRows& rows, const PoseChain& chain, int pose_offset,
                   const std::function<bool(int)>& keep) {
  LevelRows out;
  out.width = rows.width;
  out.height = rows.height;
  const size_t pixels = rows.offsets.empty() ? 0 : rows.offsets.size() - 1;
  out.offsets.reserve(pixels + 1);
  out.entries.reserve(rows.entries.size() / 4 + 6 * pixels);
  out.offsets.push_back(0);
  for (size_t p = 0; p < pixels; ++p) {
    Eigen::Matrix<double, 3, 6> pose = Eigen::Matrix<double, 3, 6>::Zero();
    bool any = false;
    for (uint64_t i = rows.offsets[p]; i < rows.offsets[p + 1]; ++i) {
      const RowEntry& e = rows.entries[i];
      if (const Row6* d = chain.Derivative(e.param)) {
        for (int c = 0; c < 3; ++c) pose.row(c) += e.d[c] * *d;
        any = true;
      }
      if (keep(e.param)) {
        CHECK_LT(e.param, pose_offset);
        out.entries.push_back(e);
      }
    }
    for (int k = 0; any && k < 6; ++k) {
      if (pose.col(k).isZero(0.0)) continue;
      out.entries.push_back({pose_offset + k, {pose(0, k), pose(1, k), pose(2, k)}});
    }
    out.offsets.push_back(out.entries.size());
  }
  return out;
}

std::string PosesJson(const std::vector<PoseDelta>& corrections,
                      const std::vector<Rigid3d>& cam_from_world,
                      const std::vector<std::string>& images, int gauge_view) {
  CHECK_EQ(corrections.size(), cam_from_world.size());
  json views = json::array();
  for (size_t v = 0; v < corrections.size(); ++v) {
    const PoseDelta& d = corrections[v];
    if (d.isZero(0.0)) continue;
    const Rigid3d pose = CorrectedCamFromWorld(cam_from_world[v], d);
    json entry = {
        {"view", v},
        {"rotation", {d[0], d[1], d[2]}},
        {"translation", {d[3], d[4], d[5]}},
        {"cam_from_world",
         {{"rotation",
           {pose.rotation.w(), pose.rotation.x(), pose.rotation.y(), pose.rotation.z()}},
          {"translation", {pose.translation.x(), pose.translation.y(), pose.translation.z()}}}}};
    if (v < images.size()) entry["image"] = images[v];
    views.push_back(entry);
  }
  const json j = {{"format", "sft-poses/1"}, {"gauge_view", gauge_view}, {"views", views}};
  return j.dump(1) + "\n";
}

namespace {

// Three finite numbers of entry `field`.
bool ReadVector3(const json& entry, const char* field, Eigen::Vector3d* out) {
  if (!entry.contains(field)) return false;
  const json& a = entry[field];
  if (!a.is_array() || a.size() != 3) return false;
  for (int k = 0; k < 3; ++k) {
    if (!a[k].is_number() || !std::isfinite(a[k].get<double>())) return false;
    (*out)[k] = a[k].get<double>();
  }
  return true;
}

}  // namespace

Status ParsePosesJson(const std::string& text, int num_views, std::vector<PoseDelta>* corrections) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return Status::Error("not a JSON object");
  if (j.value("format", std::string()) != "sft-poses/1") {
    return Status::Error("format: expected \"sft-poses/1\"");
  }
  if (!j.contains("views") || !j["views"].is_array()) {
    return Status::Error("views: expected an array");
  }
  corrections->assign(num_views, PoseDelta::Zero());
  std::vector<bool> seen(num_views, false);
  for (size_t k = 0; k < j["views"].size(); ++k) {
    const json& entry = j["views"][k];
    const std::string where = "views[" + std::to_string(k) + "]";
    if (!entry.is_object() || !entry.contains("view") || !entry["view"].is_number_integer()) {
      return Status::Error(where + ".view: expected a view index");
    }
    const int64_t v = entry["view"].get<int64_t>();
    if (v < 0 || v >= num_views) {
      return Status::Error(where + ".view: " + std::to_string(v) + " is not a view of the " +
                           std::to_string(num_views) + "-view dataset");
    }
    if (seen[v]) return Status::Error(where + ".view: view " + std::to_string(v) + " twice");
    seen[v] = true;
    Eigen::Vector3d rotation, translation;
    if (!ReadVector3(entry, "rotation", &rotation)) {
      return Status::Error(where + ".rotation: expected 3 finite numbers (radians)");
    }
    if (!ReadVector3(entry, "translation", &translation)) {
      return Status::Error(where + ".translation: expected 3 finite numbers");
    }
    (*corrections)[v] << rotation, translation;
  }
  return Status::Ok();
}

}  // namespace sft
