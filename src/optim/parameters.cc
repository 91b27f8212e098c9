#include "src/optim/parameters.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace sft {

bool ParameterBounds::Check(std::string* why) const {
  if (!(roughness_min >= 0.0 && roughness_min < 1.0)) {
    *why = "roughness_min: must be in [0, 1)";
    return false;
  }
  if (!(light_scale_min > 0.0 && light_scale_min < light_scale_max &&
        std::isfinite(light_scale_max))) {
    *why = "light_scale_min/light_scale_max: need 0 < min < max < infinity";
    return false;
  }
  if (!(environment_rotation_max > 0.0 && environment_rotation_max <= M_PI)) {
    *why = "environment_rotation_max: must be in (0, pi]";
    return false;
  }
  if (!(pose_rotation_max > 0.0 && pose_rotation_max <= M_PI && pose_translation_max > 0.0 &&
        std::isfinite(pose_translation_max))) {
    *why = "pose_rotation_max/pose_translation_max: need 0 < rotation <= pi, 0 < translation";
    return false;
  }
  if (!(environment_max > 0.0 && std::isfinite(environment_max))) {
    *why = "environment_max: must be finite and > 0";
    return false;
  }
  if (!(gain_min > 0.0 && gain_min < 1.0 && gain_max > 1.0 && std::isfinite(gain_max))) {
    *why = "gain_min/gain_max: need 0 < min < 1 < max < infinity";
    return false;
  }
  return true;
}

ParameterSelection ActiveParameters::ToSelection() const {
  ParameterSelection selection;
  selection.vertices = vertices;
  selection.albedo = albedo;
  selection.roughness = roughness;
  selection.specular = specular;
  selection.lights = lights;
  selection.environment = environment;
  selection.light_positions = light_positions;
  selection.light_directions = light_directions;
  selection.environment_rotations = environment_rotations;
  return selection;
}

bool ActiveParameters::Includes(ParameterKind kind) const { return ToSelection().Selected(kind); }

SceneParameters::SceneParameters(const std::vector<Eigen::Vector3d>& positions,
                                 const Material& material, int num_lights, int num_gain_views) {
  CHECK_GE(num_gain_views, 0);
  layout_.num_vertices = static_cast<int>(positions.size());
  layout_.num_albedo_texels = material.NumAlbedoTexels();
  layout_.num_roughness_texels = material.NumRoughnessTexels();
  layout_.num_lights = num_lights;
  num_gain_views_ = num_gain_views;
  values_.assign(layout_.size() + 3 * num_gain_views, 0.0);
  for (size_t v = 0; v < positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) values_[3 * v + k] = positions[v][k];
  }
  std::copy(material.AlbedoValues().begin(), material.AlbedoValues().end(),
            values_.begin() + layout_.AlbedoOffset());
  std::copy(material.RoughnessValues().begin(), material.RoughnessValues().end(),
            values_.begin() + layout_.RoughnessOffset());
  values_[layout_.SpecularIndex()] = material.specular;
  for (int l = 0; l < num_lights; ++l) values_[layout_.LightOffset() + l] = 1.0;
  std::fill(values_.begin() + ExposureOffset(), values_.end(), 1.0);
}

SceneParameters::SceneParameters(const std::vector<Eigen::Vector3d>& positions,
                                 const Material& material, int num_lights, int num_gain_views,
                                 int environment_light, const Image& texels) {
  CHECK(environment_light >= 0 && environment_light < num_lights);
  CHECK(texels.width > 0 && texels.height > 0 && texels.channels >= 3);
  layout_.num_environment_texels = texels.width * texels.height;
  layout_.environment_light = environment_light;
  environment_width_ = texels.width;
  environment_height_ = texels.height;
  // The base layout, then the texels between the light scales and the gains.
  SceneParameters base(positions, material, num_lights, num_gain_views);
  ParameterLayout layout = base.layout_;
  layout.num_environment_texels = layout_.num_environment_texels;
  layout.environment_light = environment_light;
  layout_ = layout;
  num_gain_views_ = num_gain_views;
  values_.assign(layout_.size() + 3 * num_gain_views, 1.0);
  std::copy(base.values_.begin(), base.values_.begin() + base.layout_.size(), values_.begin());
  for (int t = 0; t < layout_.num_environment_texels; ++t) {
    for (int c = 0; c < 3; ++c) {
      const float v = texels.at(t % texels.width, t / texels.width, c);
      values_[layout_.EnvironmentOffset() + 3 * t + c] = std::isfinite(v) && v > 0.0f ? v : 0.0;
    }
  }
}

bool& SceneParameters::LightVectorsPresent(ParameterKind kind) {
  if (kind == ParameterKind::kLightPosition) return layout_.light_positions;
  if (kind == ParameterKind::kLightDirection) return layout_.light_directions;
  CHECK(kind == ParameterKind::kEnvironmentRotation);
  return layout_.environment_rotations;
}

bool SceneParameters::HasLightVectors(ParameterKind kind) const {
  if (kind == ParameterKind::kLightPosition) return layout_.light_positions;
  if (kind == ParameterKind::kLightDirection) return layout_.light_directions;
  return layout_.environment_rotations;
}

int SceneParameters::LightVectorsOffset(ParameterKind kind) const {
  if (kind == ParameterKind::kLightPosition) return layout_.LightPositionOffset();
  if (kind == ParameterKind::kLightDirection) return layout_.LightDirectionOffset();
  return layout_.EnvironmentRotationOffset();
}

void SceneParameters::AddLightVectors(const std::vector<Eigen::Vector3d>& vectors,
                                      ParameterKind kind) {
  CHECK_EQ(static_cast<int>(vectors.size()), layout_.num_lights);
  std::vector<double> packed(3 * vectors.size());
  for (size_t l = 0; l < vectors.size(); ++l) {
    for (int k = 0; k < 3; ++k) packed[3 * l + k] = vectors[l][k];
  }
  bool& present = LightVectorsPresent(kind);
  const auto first = values_.begin() + LightVectorsOffset(kind);
  if (present) {
    std::copy(packed.begin(), packed.end(), first);
    return;
  }
  // Inserted before the later blocks (ExposureOffset() moves with the layout's size).
  values_.insert(first, packed.begin(), packed.end());
  present = true;
}

std::vector<Eigen::Vector3d> SceneParameters::LightVectors(ParameterKind kind) const {
  std::vector<Eigen::Vector3d> vectors;
  if (!HasLightVectors(kind)) return vectors;
  const int offset = LightVectorsOffset(kind);
  for (int l = 0; l < layout_.num_lights; ++l) {
    const double* p = &values_[offset + 3 * l];
    vectors.emplace_back(p[0], p[1], p[2]);
  }
  return vectors;
}

void SceneParameters::AddPoses(int num_pose_views) {
  CHECK_GE(num_pose_views, 0);
  CHECK_EQ(num_pose_views_, 0) << "poses added twice";
  num_pose_views_ = num_pose_views;
  values_.resize(values_.size() + 6 * num_pose_views, 0.0);
}

PoseDelta SceneParameters::Pose(int view) const {
  if (view < 0 || view >= num_pose_views_) return PoseDelta::Zero();
  return Eigen::Map<const PoseDelta>(&values_[PoseIndex(view, 0)]);
}

Image SceneParameters::EnvironmentTexels() const {
  if (!has_environment()) return Image();
  Image texels(environment_width_, environment_height_, 3);
  for (int t = 0; t < layout_.num_environment_texels; ++t) {
    for (int c = 0; c < 3; ++c) {
      texels.at(t % environment_width_, t / environment_width_, c) =
          static_cast<float>(values_[layout_.EnvironmentOffset() + 3 * t + c]);
    }
  }
  return texels;
}

Eigen::Vector3d SceneParameters::Gains(int view) const {
  if (view < 0 || view >= num_gain_views_) return Eigen::Vector3d::Ones();
  return Eigen::Vector3d(values_[GainIndex(view, 0)], values_[GainIndex(view, 1)],
                         values_[GainIndex(view, 2)]);
}

std::vector<BlockSpan> SceneParameters::Blocks() const {
  std::vector<BlockSpan> blocks;
  blocks.reserve(layout_.num_vertices + layout_.num_albedo_texels + layout_.num_roughness_texels +
                 1 + layout_.num_lights + layout_.num_environment_texels + num_gain_views_);
  for (int v = 0; v < layout_.num_vertices; ++v) {
    blocks.push_back({3 * v, 3, ParameterKind::kVertex});
  }
  for (int t = 0; t < layout_.num_albedo_texels; ++t) {
    blocks.push_back({layout_.AlbedoOffset() + 3 * t, 3, ParameterKind::kAlbedo});
  }
  for (int t = 0; t < layout_.num_roughness_texels; ++t) {
    blocks.push_back({layout_.RoughnessOffset() + t, 1, ParameterKind::kRoughness});
  }
  blocks.push_back({layout_.SpecularIndex(), 1, ParameterKind::kSpecular});
  for (int l = 0; l < layout_.num_lights; ++l) {
    blocks.push_back({layout_.LightOffset() + l, 1, ParameterKind::kLight});
  }
  for (int t = 0; t < layout_.num_environment_texels; ++t) {
    blocks.push_back({layout_.EnvironmentOffset() + 3 * t, 3, ParameterKind::kEnvironment});
  }
  for (int l = 0; layout_.light_positions && l < layout_.num_lights; ++l) {
    blocks.push_back({layout_.LightPositionOffset() + 3 * l, 3, ParameterKind::kLightPosition});
  }
  for (int l = 0; layout_.light_directions && l < layout_.num_lights; ++l) {
    blocks.push_back({layout_.LightDirectionOffset() + 3 * l, 3, ParameterKind::kLightDirection});
  }
  for (int l = 0; layout_.environment_rotations && l < layout_.num_lights; ++l) {
    blocks.push_back(
        {layout_.EnvironmentRotationOffset() + 3 * l, 3, ParameterKind::kEnvironmentRotation});
  }
  for (int v = 0; v < num_gain_views_; ++v) {
    blocks.push_back({GainIndex(v, 0), 3, ParameterKind::kLight, /*exposure=*/true});
  }
  for (int v = 0; v < num_pose_views_; ++v) {
    blocks.push_back({PoseIndex(v, 0), 6, ParameterKind::kLight, /*exposure=*/false,
                      /*pose=*/true});
  }
  return blocks;
}

BlockSpan SceneParameters::BlockOf(int index) const {
  DCHECK(index >= 0 && index < size());
  if (IsPose(index)) {
    const int local = index - PoseOffset();
    return {index - local % 6, 6, ParameterKind::kLight, /*exposure=*/false, /*pose=*/true};
  }
  if (IsExposure(index)) {
    const int local = index - ExposureOffset();
    return {index - local % 3, 3, ParameterKind::kLight, /*exposure=*/true};
  }
  switch (layout_.KindOf(index)) {
    case ParameterKind::kVertex:
      return {index - index % 3, 3, ParameterKind::kVertex};
    case ParameterKind::kAlbedo: {
      const int local = index - layout_.AlbedoOffset();
      return {index - local % 3, 3, ParameterKind::kAlbedo};
    }
    case ParameterKind::kRoughness:
      return {index, 1, ParameterKind::kRoughness};
    case ParameterKind::kSpecular:
      return {index, 1, ParameterKind::kSpecular};
    case ParameterKind::kLight:
      return {index, 1, ParameterKind::kLight};
    case ParameterKind::kEnvironment: {
      const int local = index - layout_.EnvironmentOffset();
      return {index - local % 3, 3, ParameterKind::kEnvironment};
    }
    case ParameterKind::kLightPosition: {
      const int local = index - layout_.LightPositionOffset();
      return {index - local % 3, 3, ParameterKind::kLightPosition};
    }
    case ParameterKind::kLightDirection: {
      const int local = index - layout_.LightDirectionOffset();
      return {index - local % 3, 3, ParameterKind::kLightDirection};
    }
    case ParameterKind::kEnvironmentRotation: {
      const int local = index - layout_.EnvironmentRotationOffset();
      return {index - local % 3, 3, ParameterKind::kEnvironmentRotation};
    }
  }
  return {index, 1, ParameterKind::kLight};
}

void SceneParameters::Positions(std::vector<Eigen::Vector3d>* positions) const {
  positions->resize(layout_.num_vertices);
  for (int v = 0; v < layout_.num_vertices; ++v) {
    (*positions)[v] = Eigen::Vector3d(values_[3 * v], values_[3 * v + 1], values_[3 * v + 2]);
  }
}

void SceneParameters::WriteMaterial(Material* material) const {
  CHECK_EQ(material->NumAlbedoTexels(), layout_.num_albedo_texels);
  CHECK_EQ(material->NumRoughnessTexels(), layout_.num_roughness_texels);
  std::copy(values_.begin() + layout_.AlbedoOffset(), values_.begin() + layout_.RoughnessOffset(),
            material->AlbedoValues().begin());
  std::copy(values_.begin() + layout_.RoughnessOffset(), values_.begin() + layout_.SpecularIndex(),
            material->RoughnessValues().begin());
  material->specular = values_[layout_.SpecularIndex()];
}

std::vector<double> SceneParameters::LightScales() const {
  return std::vector<double>(values_.begin() + layout_.LightOffset(),
                             values_.begin() + layout_.EnvironmentOffset());
}

double SceneParameters::Lower(int index, const ParameterBounds& bounds) const {
  if (IsPose(index)) return -Upper(index, bounds);
  if (IsExposure(index)) return bounds.gain_min;
  switch (layout_.KindOf(index)) {
    case ParameterKind::kVertex:
    case ParameterKind::kLightPosition:
    case ParameterKind::kLightDirection:
      return -std::numeric_limits<double>::infinity();
    case ParameterKind::kAlbedo:
    case ParameterKind::kSpecular:
      return 0.0;
    case ParameterKind::kRoughness:
      return bounds.roughness_min;
    case ParameterKind::kLight:
      return bounds.light_scale_min;
    case ParameterKind::kEnvironment:
      return 0.0;
    case ParameterKind::kEnvironmentRotation:
      return -bounds.environment_rotation_max;
  }
  return 0.0;
}

double SceneParameters::Upper(int index, const ParameterBounds& bounds) const {
  if (IsPose(index)) {
    return (index - PoseOffset()) % 6 < 3 ? bounds.pose_rotation_max : bounds.pose_translation_max;
  }
  if (IsExposure(index)) return bounds.gain_max;
  switch (layout_.KindOf(index)) {
    case ParameterKind::kVertex:
    case ParameterKind::kLightPosition:
    case ParameterKind::kLightDirection:
      return std::numeric_limits<double>::infinity();
    case ParameterKind::kLight:
      return bounds.light_scale_max;
    case ParameterKind::kEnvironment:
      return bounds.environment_max;
    case ParameterKind::kEnvironmentRotation:
      return bounds.environment_rotation_max;
    default:
      return 1.0;
  }
}

void SceneParameters::Project(const ParameterBounds& bounds, std::vector<double>* values) const {
  for (int i = layout_.AlbedoOffset(); i < size(); ++i) {
    (*values)[i] = std::clamp((*values)[i], Lower(i, bounds), Upper(i, bounds));
  }
}

}  // namespace sft
