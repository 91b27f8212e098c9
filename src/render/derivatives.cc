#include "src/render/derivatives.h"

#include <string>
#include <utility>

namespace sft {

ParameterKind ParameterLayout::KindOf(int index) const {
  if (index < AlbedoOffset()) return ParameterKind::kVertex;
  if (index < RoughnessOffset()) return ParameterKind::kAlbedo;
  if (index < SpecularIndex()) return ParameterKind::kRoughness;
  if (index == SpecularIndex()) return ParameterKind::kSpecular;
  if (index < EnvironmentOffset()) return ParameterKind::kLight;
  if (index < LightPositionOffset()) return ParameterKind::kEnvironment;
  if (index < LightDirectionOffset()) return ParameterKind::kLightPosition;
  if (index < EnvironmentRotationOffset()) return ParameterKind::kLightDirection;
  return ParameterKind::kEnvironmentRotation;
}

std::string ParameterLayout::Describe(int index) const {
  static const char kAxis[] = "xyz";
  static const char kChannel[] = "rgb";
  switch (KindOf(index)) {
    case ParameterKind::kVertex:
      return "vertex[" + std::to_string(index / 3) + "]." + kAxis[index % 3];
    case ParameterKind::kAlbedo: {
      const int local = index - AlbedoOffset();
      return "albedo[" + std::to_string(local / 3) + "]." + kChannel[local % 3];
    }
    case ParameterKind::kRoughness:
      return "roughness[" + std::to_string(index - RoughnessOffset()) + "]";
    case ParameterKind::kSpecular:
      return "specular";
    case ParameterKind::kLight:
      return "light[" + std::to_string(index - LightOffset()) + "]";
    case ParameterKind::kEnvironment: {
      const int local = index - EnvironmentOffset();
      return "environment[" + std::to_string(local / 3) + "]." + kChannel[local % 3];
    }
    case ParameterKind::kLightPosition: {
      const int local = index - LightPositionOffset();
      return "light_position[" + std::to_string(local / 3) + "]." + kAxis[local % 3];
    }
    case ParameterKind::kLightDirection: {
      const int local = index - LightDirectionOffset();
      return "light_direction[" + std::to_string(local / 3) + "]." + kAxis[local % 3];
    }
    case ParameterKind::kEnvironmentRotation: {
      const int local = index - EnvironmentRotationOffset();
      return "environment_rotation[" + std::to_string(local / 3) + "]." + kAxis[local % 3];
    }
  }
  return "?";
}

bool ParameterKindFromName(const std::string& name, ParameterKind* kind) {
  if (name == "vertices")
    *kind = ParameterKind::kVertex;
  else if (name == "albedo")
    *kind = ParameterKind::kAlbedo;
  else if (name == "roughness")
    *kind = ParameterKind::kRoughness;
  else if (name == "specular")
    *kind = ParameterKind::kSpecular;
  else if (name == "light")
    *kind = ParameterKind::kLight;
  else if (name == "environment")
    *kind = ParameterKind::kEnvironment;
  else if (name == "light_position")
    *kind = ParameterKind::kLightPosition;
  else if (name == "light_direction")
    *kind = ParameterKind::kLightDirection;
  else if (name == "environment_rotation")
    *kind = ParameterKind::kEnvironmentRotation;
  else
    return false;
  return true;
}

const char* ParameterKindName(ParameterKind kind) {
  switch (kind) {
    case ParameterKind::kVertex:
      return "vertices";
    case ParameterKind::kAlbedo:
      return "albedo";
    case ParameterKind::kRoughness:
      return "roughness";
    case ParameterKind::kSpecular:
      return "specular";
    case ParameterKind::kLight:
      return "light";
    case ParameterKind::kEnvironment:
      return "environment";
    case ParameterKind::kLightPosition:
      return "light_position";
    case ParameterKind::kLightDirection:
      return "light_direction";
    case ParameterKind::kEnvironmentRotation:
      return "environment_rotation";
  }
  return "?";
}

ParameterSelection ParameterSelection::Only(ParameterKind kind) {
  ParameterSelection s;
  s.vertices = kind == ParameterKind::kVertex;
  s.albedo = kind == ParameterKind::kAlbedo;
  s.roughness = kind == ParameterKind::kRoughness;
  s.specular = kind == ParameterKind::kSpecular;
  s.lights = kind == ParameterKind::kLight;
  s.environment = kind == ParameterKind::kEnvironment;
  s.light_positions = kind == ParameterKind::kLightPosition;
  s.light_directions = kind == ParameterKind::kLightDirection;
  s.environment_rotations = kind == ParameterKind::kEnvironmentRotation;
  return s;
}

bool ParameterSelection::Selected(ParameterKind kind) const {
  switch (kind) {
    case ParameterKind::kVertex:
      return vertices;
    case ParameterKind::kAlbedo:
      return albedo;
    case ParameterKind::kRoughness:
      return roughness;
    case ParameterKind::kSpecular:
      return specular;
    case ParameterKind::kLight:
      return lights;
    case ParameterKind::kEnvironment:
      return environment;
    case ParameterKind::kLightPosition:
      return light_positions;
    case ParameterKind::kLightDirection:
      return light_directions;
    case ParameterKind::kEnvironmentRotation:
      return environment_rotations;
  }
  return false;
}

const char* DerivativeTermName(DerivativeTerm term) {
  switch (term) {
    case DerivativeTerm::kRest:
      return "rest";
    case DerivativeTerm::kPrimaryEdges:
      return "primary_edges";
    case DerivativeTerm::kShadowEdges:
      return "shadow_edges";
    case DerivativeTerm::kTexelEdges:
      return "texel_edges";
    case DerivativeTerm::kSecondaryEdges:
      return "secondary_edges";
  }
  return "?";
}

bool DerivativeTermFromName(const std::string& name, DerivativeTerm* term) {
  for (int t = 0; t < kNumDerivativeTerms; ++t) {
    if (name == DerivativeTermName(static_cast<DerivativeTerm>(t))) {
      *term = static_cast<DerivativeTerm>(t);
      return true;
    }
  }
  return false;
}

void GradientParts::Reset(size_t size) {
  for (std::vector<double>& part : parts) part.assign(size, 0.0);
}

// Messages name the fields as the CLI flags do (primary-edge-ratio, ...).
bool DerivativeRequest::Check(std::string* why) const {
  for (const auto& [name, ratio] :
       {std::pair<const char*, double>{"primary-edge-ratio", primary_edge_ratio},
        std::pair<const char*, double>{"shadow-edge-ratio", shadow_edge_ratio},
        std::pair<const char*, double>{"texel-edge-ratio", texel_edge_ratio}}) {
    if (!(ratio >= 0.0 && ratio <= 16.0)) {
      *why = std::string(name) + ": must be in [0, 16], got " + std::to_string(ratio);
      return false;
    }
  }
  if (!(secondary_edge_samples >= 0.0 && secondary_edge_samples <= 16.0)) {
    *why =
        "secondary-edge-samples: must be in [0, 16], got " + std::to_string(secondary_edge_samples);
    return false;
  }
  if (adjoint_weights != nullptr && adjoint_weights->channels < 3) {
    *why = "adjoint weights: need 3 channels";
    return false;
  }
  return true;
}

}  // namespace sft
