#include "src/render/internal/path_derivatives.h"

namespace sft {
namespace render_internal {

void PathDerivatives::SetVertex(int face, const Eigen::Vector3d& barycentrics,
                                const Eigen::Vector3d& dir, double sign, bool track_point) {
  if (!vertices_) return;
  corners_ = ctx_.scene.faces()[face];
  barycentrics_ = barycentrics;
  // A UV texture slides under the hit as its face moves: that term needs x's Jacobian.
  if (ctx_.material.has_uv_textures()) track_point = true;
  if (ctx_.normal_jacobian != nullptr) {
    normal_.SetSmooth(ctx_.scene, *ctx_.normal_jacobian, face, barycentrics, sign,
                      ctx_.request->normal_sliding);
    track_point = true;
  } else {
    normal_.SetFlat(ctx_.scene, face, sign);
  }
  if (track_point) {
    point_.Advance(count_ == 0, dir, normal_.face_normal(), barycentrics, ctx_.scene.faces()[face]);
  }
}

void PathDerivatives::AddContribution(const Eigen::Vector3d& prefix, const SurfaceMaterial& surface,
                                      const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                                      const Eigen::Vector3d& wi, const Eigen::Vector3d& f,
                                      const LightTerm& light, int light_index) {
  const Eigen::Vector3d q = light.q * light.c;
  const Eigen::Vector3d contribution = prefix.cwiseProduct(f).cwiseProduct(q);
  const bool material = ctx_.request->params.albedo || ctx_.request->params.roughness ||
                        ctx_.request->params.specular;
  const Eigen::Vector3d f_q = f.cwiseProduct(q);
  if (material) {
    AddMaterial(surface, EvalBsdfDerivatives(surface.params, n, wo, wi, ctx_.specular_scale),
                prefix.cwiseProduct(q));
    for (int j = 0; j < count_; ++j) {
      AddMaterial(scatters_[j].surface, scatters_[j].d_s, excluded_[j].cwiseProduct(f_q));
    }
  }
  if (ctx_.request->params.lights && light_index >= 0) {
    Add(ctx_.layout->LightOffset() + light_index, contribution);
  }
  if (light.env_count > 0) {
    // ∂C_c/∂T_kc = prefix_c·f_c·c·env_weight[k]: each texel channel reaches its own channel.
    const Eigen::Vector3d base = prefix.cwiseProduct(f) * light.c;
    AddEnvironmentTexels(light.env_texel, light.env_weight, light.env_count, base);
  }
  if (light.env_rotation_param >= 0) {
    // ∂C/∂θ = prefix ⊙ f·c ⊙ ∂q/∂θ (the direction wi, hence f and c, held: the map turns).
    const Eigen::Matrix3d g = (prefix.cwiseProduct(f) * light.c).asDiagonal() * light.dq_d_rotation;
    for (int k = 0; k < 3; ++k) Emit(light.env_rotation_param + k, g.col(k));
  }
  const bool light_position = light.follows_point && light.position_param >= 0;
  const bool light_direction = light.direction_param >= 0;
  if (!vertices_ && !light_position && !light_direction) return;
  // ∂(f ⊙ q·c) = (f ⊙ q)·∂c + c·q·∂g, g the glossy term (the diffuse term is constant).
  Eigen::Vector3d dg_dn, dg_dwi;
  EvalGlossyWithGradient(surface.params, n, wo, wi, &dg_dn, &dg_dwi);
  const Eigen::Vector3d base = prefix.cwiseProduct(light.q);
  const Eigen::Vector3d base_f = base.cwiseProduct(f);
  if (light_direction) {
    // c = n·wi and g(wi) with wi = −d: ∂/∂d = −(base_f·nᵀ + c·base·∂g/∂wiᵀ).
    const Eigen::Matrix3d d_wi = base_f * n.transpose() + light.c * base * dg_dwi.transpose();
    const Eigen::Matrix3d g = -d_wi * light.d_direction_d_param;
    for (int k = 0; k < 3; ++k) Emit(light.direction_param + k, g.col(k));
  }
  if (light.follows_point) {
    // ∂/∂x of the contribution at this vertex (rows: channels), x moving alone.
    const Eigen::Matrix3d d_x =
        base_f * light.dc_dx.transpose() + light.c * base * (dg_dwi.transpose() * light.dwi_dx);
    if (light_position) {
      const Eigen::Matrix3d g = -d_x * light.d_light_d_param;
      for (int k = 0; k < 3; ++k) Emit(light.position_param + k, g.col(k));
    }
    if (vertices_ && point_.valid) {
      for (int e = 0; e < point_.count; ++e) {
        const Eigen::Matrix3d g = d_x * point_.m[e];
        for (int k = 0; k < 3; ++k) Emit(3 * point_.vertex[e] + k, g.col(k));
      }
    }
  }
  if (!vertices_) return;
  const Eigen::Matrix3d d_n = base_f * light.dc_dn.transpose() + light.c * base * dg_dn.transpose();
  scratch_.clear();
  normal_.Map(d_n, point_, &scratch_);
  AddVertices(scratch_);
  for (int j = 0; j < count_; ++j) {
    AddVertices(scatters_[j].ds_dvertices, excluded_[j].cwiseProduct(f_q));
  }
  if (surface.slides) {
    const BsdfDerivatives d = EvalBsdfDerivatives(surface.params, n, wo, wi, ctx_.specular_scale);
    scratch_.clear();
    MapSlide(prefix.cwiseProduct(q).asDiagonal() * MaterialSlide(surface, d), &scratch_);
    AddVertices(scratch_);
  }
}

void PathDerivatives::AddEnvironmentTexels(const int* texel, const double* weight, int count,
                                           const Eigen::Vector3d& base) {
  const int offset = ctx_.layout->EnvironmentOffset();
  for (int k = 0; k < count; ++k) {
    if (weight[k] == 0.0) continue;
    for (int c = 0; c < 3; ++c) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      v[c] = base[c] * weight[k];
      Add(offset + 3 * texel[k] + c, v);
    }
  }
}

Eigen::Matrix3d PathDerivatives::MaterialSlide(const SurfaceMaterial& surface,
                                               const BsdfDerivatives& d) {
  return d.d_albedo * surface.d_albedo_d_delta +
         Eigen::Vector3d::Constant(d.d_roughness) * surface.d_roughness_d_delta;
}

void PathDerivatives::MapSlide(const Eigen::Matrix3d& g, VertexGradients* out) const {
  if (!point_.valid) return;
  for (int j = 0; j < 3; ++j) out->emplace_back(corners_[j], -barycentrics_[j] * g);
  for (int e = 0; e < point_.count; ++e) out->emplace_back(point_.vertex[e], g * point_.m[e]);
}

void PathDerivatives::AddBoundary(const Eigen::Vector3d& weight, const int* vertices,
                                  const Eigen::Vector3d* rows, int count,
                                  const Eigen::Vector3d& x_row, int light_param,
                                  const Eigen::Vector3d& light_row) {
  if (!vertices_ && light_param < 0) return;
  if (!weight.allFinite()) {
    Add(light_param >= 0 ? light_param
        : count > 0      ? 3 * vertices[0]
                         : 0,
        weight);  // marks the path not finite.
    return;
  }
  const size_t first = pending_.size();
  if (light_param >= 0) {
    for (int k = 0; k < 3; ++k) Emit(light_param + k, weight * light_row[k]);
  }
  if (!vertices_) {
    if (boundary_out_ != nullptr) boundary_ranges_.emplace_back(first, pending_.size());
    return;
  }
  for (int j = 0; j < count; ++j) {
    for (int k = 0; k < 3; ++k) Emit(3 * vertices[j] + k, weight * rows[j][k]);
  }
  if (point_.valid) {
    for (int e = 0; e < point_.count; ++e) {
      const Eigen::RowVector3d g = x_row.transpose() * point_.m[e];
      for (int k = 0; k < 3; ++k) Emit(3 * point_.vertex[e] + k, weight * g[k]);
    }
  }
  if (boundary_out_ != nullptr) boundary_ranges_.emplace_back(first, pending_.size());
}

void PathDerivatives::AddScatter(const Eigen::Vector3d& prefix, const SurfaceMaterial& surface,
                                 const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                                 const Eigen::Vector3d& wi, const Eigen::Vector3d& f, double pdf) {
  CHECK_LT(count_, kMaxScatters);
  const double cos_over_pdf = n.dot(wi) / pdf;
  const Eigen::Vector3d s = f * cos_over_pdf;
  for (int j = 0; j < count_; ++j) excluded_[j] = excluded_[j].cwiseProduct(s);
  excluded_[count_] = prefix;
  Scatter& scatter = scatters_[count_];
  scatter.surface = surface;
  scatter.d_s = EvalBsdfDerivatives(surface.params, n, wo, wi, ctx_.specular_scale);
  scatter.d_s.d_albedo *= cos_over_pdf;
  scatter.d_s.d_roughness *= cos_over_pdf;
  scatter.d_s.d_specular *= cos_over_pdf;
  if (vertices_) {
    // ∂s/∂n = (f·wiᵀ + (n·wi)·1·∂g/∂nᵀ)/pdf.
    Eigen::Vector3d dg_dn, dg_dwi;
    EvalGlossyWithGradient(surface.params, n, wo, wi, &dg_dn, &dg_dwi);
    const Eigen::Matrix3d ds_dn =
        (f * wi.transpose() + n.dot(wi) * Eigen::Vector3d::Ones() * dg_dn.transpose()) / pdf;
    scatter.ds_dvertices.clear();
    normal_.Map(ds_dn, point_, &scatter.ds_dvertices);
    if (surface.slides) MapSlide(MaterialSlide(surface, scatter.d_s), &scatter.ds_dvertices);
  }
  ++count_;
}

void PathDerivatives::AddMaterial(const SurfaceMaterial& surface, const BsdfDerivatives& d,
                                  const Eigen::Vector3d& base) {
  const ParameterSelection& sel = ctx_.request->params;
  const ParameterLayout& layout = *ctx_.layout;
  // ∂/∂texel = the texel's weight × ∂/∂(the blended parameter) (context.h, TexelWeights).
  if (sel.albedo && d.d_albedo != 0.0) {
    const TexelWeights& texels = surface.albedo_texels;
    for (int k = 0; k < texels.count; ++k) {
      const int first = layout.AlbedoOffset() + 3 * texels.texel[k];
      for (int c = 0; c < 3; ++c) {
        Eigen::Vector3d v = Eigen::Vector3d::Zero();
        v[c] = base[c] * (texels.weight[k] * d.d_albedo);
        Add(first + c, v);
      }
    }
  }
  if (sel.roughness && d.d_roughness != 0.0) {
    const TexelWeights& texels = surface.roughness_texels;
    for (int k = 0; k < texels.count; ++k) {
      Add(layout.RoughnessOffset() + texels.texel[k], base * (texels.weight[k] * d.d_roughness));
    }
  }
  if (sel.specular && d.d_specular != 0.0) {
    Add(layout.SpecularIndex(), base * d.d_specular);
  }
}

}  // namespace render_internal
}  // namespace sft
