#include "src/optim/regularizers.h"

#include <glog/logging.h>

#include <cmath>

#include "cost_functions/environment_smoothness.h"
#include "cost_functions/exposure_prior.h"
#include "cost_functions/face_orientation.h"
#include "cost_functions/pose_prior.h"
#include "cost_functions/proximal_smoothing.h"
#include "cost_functions/texel_smoothness.h"
#include "cost_functions/uv_texel_smoothness.h"
#include "cost_functions/vertex_laplacian.h"

namespace sft {
namespace {

// Gives the block of `size` numbers at flat index `first` (already in `problem`) the bounds of its
// parameters.
void SetBlockBounds(int first, int size, const ParameterBounds& bounds, SceneParameters* params,
                    ceres::Problem* problem) {
  double* block = params->data() + first;
  for (int i = 0; i < size; ++i) {
    problem->SetParameterLowerBound(block, i, params->Lower(first + i, bounds));
    problem->SetParameterUpperBound(block, i, params->Upper(first + i, bounds));
  }
}

// Smoothness over the texel pairs `pairs` of one attribute (mesh colors or a UV texture) whose
// texel k is the block at offset + channels·k.
void AddSmoothness(const std::vector<TexelPair>& pairs, int num_texels, int channels, int offset,
                   double weight, bool log_ratio, const ParameterBounds& bounds,
                   SceneParameters* params, ceres::Problem* problem) {
  std::vector<double*> blocks(num_texels);
  for (int k = 0; k < num_texels; ++k) blocks[k] = params->data() + offset + channels * k;
  TexelSmoothnessOptions options;
  options.weight = std::sqrt(weight);
  options.log_ratio = log_ratio;
  AddTexelSmoothness(pairs, channels, options, blocks, problem);
  // Texels no render touches (mesh colors' i + j = r) enter the problem here: give every texel
  // the bounds.
  for (int k = 0; k < num_texels; ++k) {
    if (problem->HasParameterBlock(blocks[k])) {
      SetBlockBounds(offset + channels * k, channels, bounds, params, problem);
    }
  }
}

}  // namespace

bool RegularizerOptions::Check(std::string* why) const {
  for (double w : {laplacian_weight, albedo_smoothness, roughness_smoothness}) {
    if (!(w >= 0.0 && std::isfinite(w))) {
      *why = "regularizer weights must be finite and >= 0";
      return false;
    }
  }
  if (!(environment_smoothness >= 0.0 && std::isfinite(environment_smoothness))) {
    *why = "environment_smoothness: must be finite and >= 0";
    return false;
  }
  if (!(pose_prior == kPosePriorAuto || (pose_prior >= 0.0 && std::isfinite(pose_prior)))) {
    *why = "pose_prior: must be auto or finite and >= 0";
    return false;
  }
  if (!(exposure_prior >= 0.0 && std::isfinite(exposure_prior))) {
    *why = "exposure_prior: must be finite and >= 0";
    return false;
  }
  if (!(orientation_weight >= 0.0 && std::isfinite(orientation_weight) &&
        orientation_min_fraction > 0.0 && orientation_min_fraction < 1.0)) {
    *why = "orientation_weight must be finite and >= 0, orientation_min_fraction in (0, 1)";
    return false;
  }
  if (!(proximal_weight >= 0.0 && std::isfinite(proximal_weight) && proximal_lambda >= 0.0 &&
        proximal_lambda <= 1e6)) {
    *why = "proximal_weight must be finite and >= 0, proximal_lambda in [0, 1e6]";
    return false;
  }
  return true;
}

void AddRegularizers(const TriMesh& rest, const ActiveParameters& active,
                     const RegularizerOptions& options, const ParameterBounds& bounds,
                     const Material& material, SceneParameters* params, ceres::Problem* problem,
                     const std::vector<Eigen::Vector3d>& gain_curvature,
                     const std::vector<Eigen::Matrix<double, 6, 1>>& pose_curvature) {
  const ParameterLayout& layout = params->layout();
  if (active.vertices && options.laplacian_weight > 0.0) {
    VertexLaplacianOptions laplacian;
    laplacian.kind = options.cotangent ? LaplacianKind::kCotangent : LaplacianKind::kUniform;
    laplacian.weight = std::sqrt(options.laplacian_weight);
    laplacian.relative_to_rest = !options.laplacian_of_shape;
    std::vector<double*> blocks(layout.num_vertices);
    for (int v = 0; v < layout.num_vertices; ++v) blocks[v] = params->data() + 3 * v;
    AddVertexLaplacian(rest, laplacian, blocks, problem);
  }
  if (active.vertices && options.orientation_weight > 0.0) {
    std::vector<double*> blocks(layout.num_vertices);
    for (int v = 0; v < layout.num_vertices; ++v) blocks[v] = params->data() + 3 * v;
    FaceOrientationOptions orientation;
    orientation.weight = std::sqrt(options.orientation_weight);
    orientation.min_fraction = options.orientation_min_fraction;
    AddFaceOrientation(rest, orientation, blocks, problem);
  }
  if (active.vertices && options.proximal_weight > 0.0) {
    std::vector<double*> blocks(layout.num_vertices);
    for (int v = 0; v < layout.num_vertices; ++v) blocks[v] = params->data() + 3 * v;
    ProximalSmoothingOptions proximal;
    proximal.weight = std::sqrt(options.proximal_weight);
    proximal.lambda = options.proximal_lambda;
    AddProximalSmoothing(rest, proximal, blocks, problem);
  }
  // Neighbour pairs: the mesh-colors layout's, or a UV texture's within its charts.
  auto pairs = [&](const MeshColors& colors, const UvTexture& texture) {
    if (!material.has_uv_textures()) return TexelNeighbourPairs(rest, colors.resolution());
    std::vector<Eigen::Vector3i> faces;
    MeshToArrays(rest, nullptr, &faces);
    return UvTexelNeighbourPairs(
        ComputeUvTexelCharts(faces, material.uv.corner_uvs, texture.width(), texture.height()));
  };
  if (active.albedo && options.albedo_smoothness > 0.0) {
    // Fitted light scales or a fitted environment can take over the albedo's scale (the images
    // see their product): then the prior ties log albedo, which that trade leaves unchanged.
    const bool scale_free = active.lights || active.environment;
    AddSmoothness(pairs(material.albedo, material.uv.albedo), material.NumAlbedoTexels(), 3,
                  layout.AlbedoOffset(), options.albedo_smoothness, scale_free, bounds, params,
                  problem);
  }
  if (active.roughness && options.roughness_smoothness > 0.0) {
    AddSmoothness(pairs(material.roughness, material.uv.roughness), material.NumRoughnessTexels(),
                  1, layout.RoughnessOffset(), options.roughness_smoothness, /*log_ratio=*/false,
                  bounds, params, problem);
  }
  if (active.environment && params->has_environment() && options.environment_smoothness > 0.0) {
    const int num_texels = layout.num_environment_texels;
    std::vector<double*> blocks(num_texels);
    for (int t = 0; t < num_texels; ++t)
      blocks[t] = params->data() + layout.EnvironmentOffset() + 3 * t;
    TexelSmoothnessOptions smoothness;
    smoothness.weight = std::sqrt(options.environment_smoothness);
    AddTexelSmoothness(
        EnvironmentNeighbourPairs(params->environment_width(), params->environment_height()), 3,
        smoothness, blocks, problem);
    for (int t = 0; t < num_texels; ++t) {
      if (problem->HasParameterBlock(blocks[t])) {
        SetBlockBounds(layout.EnvironmentOffset() + 3 * t, 3, bounds, params, problem);
      }
    }
  }
  if (active.exposure && options.exposure_prior > 0.0) {
    CHECK_EQ(static_cast<int>(gain_curvature.size()), params->num_gain_views());
    for (int v = 0; v < params->num_gain_views(); ++v) {
      if (!params->GainFitted(v)) continue;
      double* block = params->data() + params->GainIndex(v, 0);
      const Eigen::Vector3d w = (options.exposure_prior * gain_curvature[v]).cwiseSqrt();
      problem->AddResidualBlock(new ExposurePriorCost(w[0], w[1], w[2]), nullptr, block);
      SetBlockBounds(params->GainIndex(v, 0), 3, bounds, params, problem);
    }
  }
  if (active.poses && options.pose_prior > 0.0) {
    CHECK_EQ(static_cast<int>(pose_curvature.size()), params->num_pose_views());
    for (int v = 0; v < params->num_pose_views(); ++v) {
      if (!params->PoseFitted(v)) continue;
      double* block = params->data() + params->PoseIndex(v, 0);
      const Eigen::Matrix<double, 6, 1> w = (options.pose_prior * pose_curvature[v]).cwiseSqrt();
      problem->AddResidualBlock(new PosePriorCost(w), nullptr, block);
      SetBlockBounds(params->PoseIndex(v, 0), 6, bounds, params, problem);
    }
  }
}

}  // namespace sft
