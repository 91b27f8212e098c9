#include "src/render/internal/integrator.h"

#include <cmath>

#include "src/render/bsdf.h"
#include "src/render/internal/path_derivatives.h"
#include "src/render/internal/secondary_edges.h"

namespace sft {
namespace render_internal {
namespace {

// Side hits whose normals are closer than this (cosine) share one path (TraceSharedSideJump):
// the same face, or coplanar ones.
constexpr double kSharedSideMinCosine = 1.0 - 1e-9;

// The shading frame of a path vertex at ray hit `hit` of the ray along `dir`.
struct ShadingPoint {
  Eigen::Vector3d p;
  // The unit shading normal (the face's, or the interpolated smooth one) flipped to the side of
  // wo that the face's geometric normal faces (two-sided shading).
  Eigen::Vector3d n;
  Eigen::Vector3d wo;
  double sign = 1.0;  // n = sign·(unflipped shading normal).
};

// False for a degenerate triangle (no defined surface). The side is the geometric one: where an
// interpolated normal turns away from wo (near silhouettes) the BSDF sees wo below its
// hemisphere and reflects nothing.
bool Shade(const Context& ctx, const Eigen::Vector3d& dir, const RayHit& hit, ShadingPoint* sp) {
  sp->p = ctx.scene.Point(hit.face, hit.u, hit.v);
  const Eigen::Vector3d face_normal = ctx.scene.FaceNormal(hit.face);
  sp->n = ctx.options.shading == Shading::kSmooth ? ctx.scene.SmoothNormal(hit.face, hit.u, hit.v)
                                                  : face_normal;
  sp->wo = -dir;
  sp->sign = face_normal.dot(sp->wo) < 0.0 ? -1.0 : 1.0;
  sp->n *= sp->sign;
  return !sp->n.isZero();
}

// The light term (and its geometric derivatives when `derivatives`) of a point-light sample.
LightTerm PointLightTerm(const PointLightSample& ls, const PointLight& light,
                         const Eigen::Vector3d& n, bool derivatives) {
  LightTerm term;
  term.q = light.intensity;
  term.c = ls.cos_i / (ls.dist * ls.dist);
  if (derivatives) {
    const double dist2 = ls.dist * ls.dist;
    term.dc_dn = ls.wi / dist2;
    term.follows_point = true;
    term.dc_dx = (3.0 * ls.cos_i * ls.wi - n) / (dist2 * ls.dist);
    term.dwi_dx = -(Eigen::Matrix3d::Identity() - ls.wi * ls.wi.transpose()) / ls.dist;
  }
  return term;
}

// Marks `term` as differentiated with respect to the light's position when the request and the
// layout have that light's position parameters.
void SetLightPositionParams(const Context& ctx, const PointLight& light, LightTerm* term) {
  if (!ctx.request->params.light_positions || !ctx.layout->FitsLightPosition(light.light_index)) {
    return;
  }
  term->position_param = ctx.layout->LightPositionOffset() + 3 * light.light_index;
  term->d_light_d_param = LightPositionJacobian(ctx.view, light);
}

// One vertex of a path being traced, and the path's running sums.
struct PathVertex {
  int depth = 0;
  int face = -1;
  ShadingPoint sp;
  SurfaceMaterial surface;
  BsdfParams sampling;    // the parameters directions are sampled with (detached sampling).
  bool detached = false;  // sampling differs from surface.params.
  double offset = 0.0;    // ray offset at p.
  bool lit = false;       // light reaching this vertex directly counts.
};
struct PathState {
  Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
  Eigen::Vector3d throughput = Eigen::Vector3d::Ones();
  PathDerivatives* path = nullptr;
  RenderStats* stats = nullptr;
};

// Adds throughput ⊙ f ⊙ (q·c) to the radiance (and its derivatives).
void Contribute(const PathVertex& v, const Eigen::Vector3d& wi, const Eigen::Vector3d& f,
                const LightTerm& light, int light_index, PathState* state) {
  state->radiance += state->throughput.cwiseProduct(f).cwiseProduct(light.q) * light.c;
  if (state->path) {
    state->path->AddContribution(state->throughput, v.surface, v.sp.n, v.sp.wo, wi, f, light,
                                 light_index);
  }
}

void AddPointLights(const Context& ctx, const PathVertex& v, PathState* state) {
  for (const PointLight& light : ctx.view.point_lights) {
    PointLightSample ls;
    if (!SamplePointLightVisible(ctx, light, v.face, v.sp.p, v.sp.n, v.sp.wo, v.surface.params,
                                 v.offset, ctx.options.effects.shadows,
                                 /*skip_black=*/state->path == nullptr, state->stats, &ls)) {
      continue;
    }
    LightTerm term = PointLightTerm(ls, light, v.sp.n, state->path != nullptr);
    if (state->path != nullptr) SetLightPositionParams(ctx, light, &term);
    Contribute(v, ls.wi, ls.f, term, light.light_index, state);
  }
}

void AddDirectionalLights(const Context& ctx, const PathVertex& v, PathState* state) {
  for (const DirectionalLight& light : ctx.view.directional_lights) {
    PointLightSample ls;
    if (!SampleDirectionalLightVisible(ctx, light, v.sp.p, v.sp.n, v.sp.wo, v.surface.params,
                                       v.offset, ctx.options.effects.shadows,
                                       /*skip_black=*/state->path == nullptr, state->stats, &ls)) {
      continue;
    }
    LightTerm term;
    term.q = light.irradiance;
    term.c = ls.cos_i;
    term.dc_dn = ls.wi;
    if (state->path != nullptr && ctx.request->params.light_directions &&
        ctx.layout->FitsLightDirection(light.light_index)) {
      term.direction_param = ctx.layout->LightDirectionOffset() + 3 * light.light_index;
      term.d_direction_d_param = LightDirectionJacobian(ctx.view, light);
    }
    Contribute(v, ls.wi, ls.f, term, light.light_index, state);
  }
}

// Fills `term`'s fitted-environment texels along wi when the path takes derivatives of them:
// `factor` multiplies the map's radiance in term.q (light scale, MIS weight, 1/pdf).
void SetEnvironmentTexels(const Context& ctx, const Eigen::Vector3d& wi, double factor,
                          const PathState& state, LightTerm* term) {
  if (state.path == nullptr || !ctx.request->params.environment ||
      !ctx.layout->FitsEnvironment(ctx.view.environment_light_index)) {
    return;
  }
  ctx.environment->TexelWeights(wi, term->env_texel, term->env_weight);
  for (double& w : term->env_weight) w *= factor * ctx.environment->scale();
  term->env_count = 4;
}

// The map's rotation parameters (ParameterLayout::environment_rotations) of the path's view, or
// −1 when the path takes no derivatives of them.
int EnvironmentRotationParam(const Context& ctx, const PathDerivatives* path) {
  if (path == nullptr || !ctx.request->params.environment_rotations ||
      !ctx.layout->FitsEnvironmentRotation(ctx.view.environment_light_index)) {
    return -1;
  }
  return ctx.layout->EnvironmentRotationOffset() + 3 * ctx.view.environment_light_index;
}

// Fills `term`'s derivative with respect to the environment's rotation along wi: `factor`
// multiplies the map's radiance in term.q (light scale, MIS weight, 1/pdf). The sampled direction,
// its pdf and the MIS weight are held at their values (detached), which is unbiased: each
// technique's estimate f·∂L·w/p has expectation ∫ f·∂L·w, and the held weights still sum to 1 at
// every direction, so the sum is ∫ f·∂L, the derivative of ∫ f·L (f, the cosine and the domain do
// not depend on θ). The environment is at infinity: turning it moves no visibility boundary, so
// there are no edge terms.
void SetEnvironmentRotation(const Context& ctx, const Eigen::Vector3d& wi, double factor,
                            const PathState& state, LightTerm* term) {
  term->env_rotation_param = EnvironmentRotationParam(ctx, state.path);
  if (term->env_rotation_param < 0) return;
  term->dq_d_rotation =
      factor * ctx.environment->RotationJacobian(wi) * ctx.view.environment_rotation_jacobian;
}

// Light-sampled environment term (MIS against BSDF sampling when shadows are on).
void AddEnvironmentLight(const Context& ctx, const PathVertex& v, Sampler* sampler,
                         PathState* state) {
  Eigen::Vector3d wi, le;
  double pdf_light = 0.0;
  double u1, u2;
  sampler->Next2D(&u1, &u2);
  if (!ctx.sampling_environment->Sample(u1, u2, &wi, &le, &pdf_light)) return;
  if (ctx.sampling_environment != ctx.environment) le = ctx.environment->Radiance(wi);
  const Eigen::Vector3d& n = v.sp.n;
  const double cos_i = n.dot(wi);
  if (!(cos_i > 0.0)) return;
  const Eigen::Vector3d f = EvalBsdf(v.surface.params, n, v.sp.wo, wi);
  bool visible = !f.isZero() || state->path != nullptr;
  if (visible && ctx.options.effects.shadows) {
    ++state->stats->shadow_rays;
    visible = !ctx.scene.Occluded(v.sp.p, wi, v.offset, kInfinity);
  }
  if (!visible || ctx.view.support.Hides(v.sp.p, wi)) return;
  // Without shadows the BSDF-sampled rays cannot tell whether the light is seen, so the
  // environment is lit by light sampling alone (weight 1).
  const double weight = ctx.options.effects.shadows
                            ? PowerHeuristic(pdf_light, BsdfPdf(v.sampling, n, v.sp.wo, wi))
                            : 1.0;
  LightTerm term;
  const double factor = ctx.view.environment_scale * weight / pdf_light;
  term.q = le * factor;
  term.c = cos_i;
  term.dc_dn = wi;
  SetEnvironmentTexels(ctx, wi, factor, *state, &term);
  SetEnvironmentRotation(ctx, wi, factor, *state, &term);
  Contribute(v, wi, f, term, ctx.view.environment_light_index, state);
}

// Light reaching v directly (when it counts there): the point and directional lights and a
// light-sampled environment direction.
void AddDirectLight(const Context& ctx, const PathVertex& v, Sampler* sampler, PathState* state) {
  if (!v.lit) return;
  AddPointLights(ctx, v, state);
  AddDirectionalLights(ctx, v, state);
  if (ctx.environment != nullptr) AddEnvironmentLight(ctx, v, sampler, state);
}

// Whether a segment follows v, and whether the environment seen along a BSDF sample at v counts
// there (MIS against AddEnvironmentLight's light samples).
bool ContinuesPath(const Context& ctx, const PathVertex& v) {
  return v.depth + 1 < ctx.max_segments;
}
bool BsdfLightsEnvironment(const Context& ctx, const PathVertex& v) {
  return ctx.environment != nullptr && v.lit && ctx.options.effects.shadows;
}

// A BSDF sample at a path vertex and the first hit of the ray it traces.
struct ScatterSample {
  BsdfSample bsdf;
  RayHit next;
};

// Samples the BSDF of v's sampling material and traces the ray. False when nothing follows
// from it (no further segment and no BSDF-sampled environment, or no valid sample).
bool SampleScatter(const Context& ctx, const PathVertex& v, Sampler* sampler, RenderStats* stats,
                   ScatterSample* out) {
  if (!ContinuesPath(ctx, v) && !BsdfLightsEnvironment(ctx, v)) return false;
  Eigen::Vector3d u;
  u.x() = sampler->Next1D();  // lobe choice
  sampler->Next2D(&u.y(), &u.z());
  if (!SampleBsdf(v.sampling, v.sp.n, v.sp.wo, u, &out->bsdf)) return false;
  if (!std::isfinite(v.sp.n.dot(out->bsdf.wi) / out->bsdf.pdf)) return false;
  out->next = ctx.scene.Intersect(v.sp.p + v.offset * v.sp.n, out->bsdf.wi, 0.0, kInfinity);
  ++stats->bounce_rays;
  return true;
}

// Applies sample s to the path at v, with v's own material: the environment seen along it on
// a miss (MIS), else the throughput of the next segment. False when the path ends.
bool ApplyScatter(const Context& ctx, const PathVertex& v, const ScatterSample& s,
                  PathState* state) {
  const Eigen::Vector3d& n = v.sp.n;
  const Eigen::Vector3d& wi = s.bsdf.wi;
  const Eigen::Vector3d f = v.detached ? EvalBsdf(v.surface.params, n, v.sp.wo, wi) : s.bsdf.f;
  if (!s.next.hit) {
    if (BsdfLightsEnvironment(ctx, v) && !ctx.view.support.Hides(v.sp.p, wi)) {
      const double weight = PowerHeuristic(s.bsdf.pdf, ctx.sampling_environment->Pdf(wi));
      LightTerm term;
      const double factor = ctx.view.environment_scale * weight / s.bsdf.pdf;
      term.q = ctx.environment->Radiance(wi) * factor;
      term.c = n.dot(wi);
      term.dc_dn = wi;
      SetEnvironmentTexels(ctx, wi, factor, *state, &term);
      SetEnvironmentRotation(ctx, wi, factor, *state, &term);
      Contribute(v, wi, f, term, ctx.view.environment_light_index, state);
    }
    return false;
  }
  if (!ContinuesPath(ctx, v)) return false;
  if (state->path) {
    state->path->AddScatter(state->throughput, v.surface, n, v.sp.wo, wi, f, s.bsdf.pdf);
  }
  state->throughput = state->throughput.cwiseProduct(f * (n.dot(wi) / s.bsdf.pdf));
  return true;
}

// Samples the BSDF at v: adds the environment seen along the sample (MIS) and, when the path
// continues, advances *dir and *hit and the throughput. False when the path ends.
bool Scatter(const Context& ctx, const PathVertex& v, Sampler* sampler, PathState* state,
             Eigen::Vector3d* dir, RayHit* hit) {
  ScatterSample s;
  if (!SampleScatter(ctx, v, sampler, state->stats, &s) || !ApplyScatter(ctx, v, s, state)) {
    return false;
  }
  *dir = s.bsdf.wi;
  *hit = s.next;
  return true;
}

// The path vertex at `hit` of the ray along `dir` at `depth`: shading frame, material, sampling
// material, ray offset. False for a degenerate triangle (nothing is reflected).
bool MakeVertex(const Context& ctx, const Eigen::Vector3d& dir, const RayHit& hit, int depth,
                PathVertex* v) {
  v->depth = depth;
  v->face = hit.face;
  if (!Shade(ctx, dir, hit, &v->sp)) return false;
  v->surface = LookUpMaterial(ctx, ctx.material, hit.face, hit.u, hit.v);
  v->detached = &ctx.sampling_material != &ctx.material;
  v->sampling = v->detached
                    ? LookUpMaterial(ctx, ctx.sampling_material, hit.face, hit.u, hit.v).params
                    : v->surface.params;
  v->offset = RayOffset(ctx, hit.face, v->sp.p);
  v->lit = depth > 0 || ctx.options.effects.direct;
  return true;
}

// The environment seen by a camera ray that misses the mesh (zero unless it is the background;
// zero where the black support disc is in the way, as the infinite floor's cut map is).
Eigen::Vector3d Background(const Context& ctx, const Eigen::Vector3d& dir, PathDerivatives* path) {
  if (ctx.environment == nullptr || !ctx.view.environment_background) {
    return Eigen::Vector3d::Zero();
  }
  if (ctx.view.support.radius > 0 &&
      ctx.view.support.Hides(ctx.view.cam_from_world.Inverse().translation, dir)) {
    return Eigen::Vector3d::Zero();
  }
  const Eigen::Vector3d radiance = ctx.view.environment_scale * ctx.environment->Radiance(dir);
  if (path != nullptr && ctx.request->params.lights && ctx.view.environment_light_index >= 0) {
    path->Add(ctx.layout->LightOffset() + ctx.view.environment_light_index, radiance);
  }
  if (path != nullptr && ctx.request->params.environment &&
      ctx.layout->FitsEnvironment(ctx.view.environment_light_index)) {
    int texel[4];
    double weight[4];
    ctx.environment->TexelWeights(dir, texel, weight);
    const double factor = ctx.view.environment_scale * ctx.environment->scale();
    path->AddEnvironmentTexels(texel, weight, 4, Eigen::Vector3d::Constant(factor));
  }
  const int rotation_param = EnvironmentRotationParam(ctx, path);
  if (rotation_param >= 0) {
    const Eigen::Matrix3d d = ctx.view.environment_scale * ctx.environment->RotationJacobian(dir) *
                              ctx.view.environment_rotation_jacobian;
    for (int k = 0; k < 3; ++k) {
      if (!d.col(k).isZero()) path->Add(rotation_param + k, d.col(k));
    }
  }
  return radiance;
}

}  // namespace

double PowerHeuristic(double pdf_a, double pdf_b) {
  const double a2 = pdf_a * pdf_a;
  const double b2 = pdf_b * pdf_b;
  if (!(a2 + b2 > 0.0) || !std::isfinite(a2 + b2)) return pdf_a >= pdf_b ? 1.0 : 0.0;
  return a2 / (a2 + b2);
}

namespace {

// The bilinear texels of `texture` at `uv` with non-zero weight, and the interpolated value
// (Σ weight·texel, channels() values into `value`); with `d_du`, `d_dv` also its gradient.
TexelWeights BilinearTexels(const UvTexture& texture, const Eigen::Vector2d& uv, double* value,
                            double* d_du = nullptr, double* d_dv = nullptr) {
  const BilinearFootprint footprint = texture.Footprint(uv);
  if (d_du != nullptr) texture.Gradient(footprint, d_du, d_dv);
  TexelWeights out;
  for (int c = 0; c < texture.channels(); ++c) value[c] = 0.0;
  for (int k = 0; k < 4; ++k) {
    if (footprint.weight[k] == 0.0) continue;
    out.texel[out.count] = footprint.texel[k];
    out.weight[out.count] = footprint.weight[k];
    ++out.count;
    const double* texel = texture.texel(footprint.texel[k]);
    for (int c = 0; c < texture.channels(); ++c) value[c] += footprint.weight[k] * texel[c];
  }
  return out;
}

// ∂uv/∂δ (2 × 3) on `face`: uv = Σ_j b_j·uv_j with db_k = g_k·δ (k = 1, 2), db_0 = −db_1 − db_2
// and the dual basis g1 = (e2 × N)/|N|², g2 = (N × e1)/|N|² (shading_normal.h). False for a
// degenerate face.
bool UvSlide(const RenderScene& scene, const UvMaterialMaps& maps, int face,
             Eigen::Matrix<double, 2, 3>* d_uv_d_delta) {
  const Eigen::Vector3i& corners = scene.faces()[face];
  const auto& p = scene.positions();
  const Eigen::Vector3d e1 = p[corners[1]] - p[corners[0]];
  const Eigen::Vector3d e2 = p[corners[2]] - p[corners[0]];
  const Eigen::Vector3d n = e1.cross(e2);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0.0) || !std::isfinite(n2)) return false;
  const Eigen::Vector3d g1 = e2.cross(n) / n2, g2 = n.cross(e1) / n2;
  const Eigen::Vector2d* uv = &maps.corner_uvs[3 * face];
  *d_uv_d_delta = (uv[1] - uv[0]) * g1.transpose() + (uv[2] - uv[0]) * g2.transpose();
  return true;
}

TexelWeights NearestTexel(int texel) {
  TexelWeights out;
  out.count = 1;
  out.texel[0] = texel;
  out.weight[0] = 1.0;
  return out;
}

}  // namespace

SurfaceMaterial LookUpMaterial(const Context& ctx, const Material& material, int face, double u,
                               double v) {
  SurfaceMaterial m;
  if (material.has_uv_textures()) {
    const Eigen::Vector2d uv = material.uv.Uv(face, u, v);
    Eigen::Matrix<double, 2, 3> d_uv_d_delta;
    if (ctx.request != nullptr && ctx.request->params.vertices &&
        UvSlide(ctx.scene, material.uv, face, &d_uv_d_delta)) {
      Eigen::Matrix<double, 3, 2> d_albedo_d_uv;
      Eigen::RowVector2d d_roughness_d_uv;
      double d_du[3], d_dv[3];
      m.albedo_texels = BilinearTexels(material.uv.albedo, uv, m.params.albedo.data(), d_du, d_dv);
      for (int c = 0; c < 3; ++c) d_albedo_d_uv.row(c) << d_du[c], d_dv[c];
      m.roughness_texels =
          BilinearTexels(material.uv.roughness, uv, &m.params.roughness, d_du, d_dv);
      d_roughness_d_uv << d_du[0], d_dv[0];
      m.slides = true;
      m.d_albedo_d_delta = d_albedo_d_uv * d_uv_d_delta;
      m.d_roughness_d_delta = d_roughness_d_uv * d_uv_d_delta;
    } else {
      m.albedo_texels = BilinearTexels(material.uv.albedo, uv, m.params.albedo.data());
      m.roughness_texels = BilinearTexels(material.uv.roughness, uv, &m.params.roughness);
    }
  } else {
    m.albedo_texels = NearestTexel(material.albedo.TexelIndex(face, u, v));
    m.roughness_texels = NearestTexel(material.roughness.TexelIndex(face, u, v));
    const double* albedo = material.albedo.texel(m.albedo_texels.texel[0]);
    m.params.albedo = Eigen::Vector3d(albedo[0], albedo[1], albedo[2]);
    m.params.roughness = *material.roughness.texel(m.roughness_texels.texel[0]);
  }
  m.params.specular = material.specular * ctx.specular_scale;
  m.params.fresnel = material.fresnel;
  return m;
}

bool SamplePointLightVisible(const Context& ctx, const PointLight& light, int face,
                             const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                             const Eigen::Vector3d& wo, const BsdfParams& params, double offset,
                             bool shadows, bool skip_black, RenderStats* stats,
                             PointLightSample* sample) {
  const Eigen::Vector3d to_light = light.position - p;
  const double dist2 = to_light.squaredNorm();
  const double min_dist = kMinRelativeLightDistance * SurfaceScale(ctx.scene, face, p);
  if (!(dist2 > min_dist * min_dist)) return false;
  sample->dist = std::sqrt(dist2);
  sample->wi = to_light / sample->dist;
  sample->cos_i = n.dot(sample->wi);
  if (sample->cos_i <= 0.0) return false;
  sample->f = EvalBsdf(params, n, wo, sample->wi);
  if (skip_black && sample->f.isZero()) return false;
  if (!shadows) return true;
  ++stats->shadow_rays;
  return !ctx.scene.Occluded(p, sample->wi, offset, sample->dist - offset);
}

bool SampleDirectionalLightVisible(const Context& ctx, const DirectionalLight& light,
                                   const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                   const Eigen::Vector3d& wo, const BsdfParams& params,
                                   double offset, bool shadows, bool skip_black, RenderStats* stats,
                                   PointLightSample* sample) {
  sample->wi = -light.direction;
  sample->dist = kInfinity;
  sample->cos_i = n.dot(sample->wi);
  if (!(sample->cos_i > 0.0)) return false;
  sample->f = EvalBsdf(params, n, wo, sample->wi);
  if (skip_black && sample->f.isZero()) return false;
  if (!shadows) return true;
  ++stats->shadow_rays;
  return !ctx.scene.Occluded(p, sample->wi, offset, kInfinity);
}

namespace {

// The first hit of the ray from `origin` along `dir` (from t_near on), shaded, with its material
// and ray offset.
struct Receiver {
  int face = -1;
  ShadingPoint sp;
  BsdfParams params;
  double offset = 0.0;
};

// False when the first hit is not on face `receiver`. A degenerate face has n = 0, so light
// samples fail there.
bool ShadeReceiver(const Context& ctx, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                   double t_near, int receiver, RenderStats* stats, Receiver* out) {
  const RayHit hit = ctx.scene.Intersect(origin, dir, t_near, kInfinity);
  ++stats->bounce_rays;
  if (!hit.hit || hit.face != receiver) return false;
  Shade(ctx, dir, hit, &out->sp);
  out->params = LookUpMaterial(ctx, ctx.material, hit.face, hit.u, hit.v).params;
  out->face = hit.face;
  out->offset = RayOffset(ctx, hit.face, out->sp.p);
  return true;
}

}  // namespace

bool DirectAtReceiver(const Context& ctx, const PointLight& light, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& dir, double t_near, int receiver, RenderStats* stats,
                      Eigen::Vector3d* radiance) {
  Receiver r;
  if (!ShadeReceiver(ctx, origin, dir, t_near, receiver, stats, &r)) return false;
  radiance->setZero();
  PointLightSample ls;
  if (SamplePointLightVisible(ctx, light, r.face, r.sp.p, r.sp.n, r.sp.wo, r.params, r.offset,
                              /*shadows=*/true, /*skip_black=*/false, stats, &ls)) {
    const LightTerm term = PointLightTerm(ls, light, r.sp.n, /*derivatives=*/false);
    *radiance = ls.f.cwiseProduct(term.q) * term.c;
  }
  return true;
}

bool DirectAtReceiver(const Context& ctx, const DirectionalLight& light,
                      const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_near,
                      int receiver, RenderStats* stats, Eigen::Vector3d* radiance) {
  Receiver r;
  if (!ShadeReceiver(ctx, origin, dir, t_near, receiver, stats, &r)) return false;
  radiance->setZero();
  PointLightSample ls;
  if (SampleDirectionalLightVisible(ctx, light, r.sp.p, r.sp.n, r.sp.wo, r.params, r.offset,
                                    /*shadows=*/true, /*skip_black=*/false, stats, &ls)) {
    *radiance = ls.f.cwiseProduct(light.irradiance) * ls.cos_i;
  }
  return true;
}

Eigen::Vector3d TraceRadiance(const Context& ctx, Sampler* sampler, Eigen::Vector3d dir, RayHit hit,
                              RenderStats* stats, PathDerivatives* path, int first_depth) {
  if (!hit.hit) return Background(ctx, dir, path);
  PathState state;
  state.path = path;
  state.stats = stats;
  for (int depth = first_depth;; ++depth) {
    PathVertex v;
    if (!MakeVertex(ctx, dir, hit, depth, &v)) break;
    if (path) {
      path->SetVertex(hit.face, Eigen::Vector3d(1.0 - hit.u - hit.v, hit.u, hit.v), dir, v.sp.sign,
                      !ctx.view.point_lights.empty() || ctx.secondary != nullptr);
    }
    AddDirectLight(ctx, v, sampler, &state);
    if (path != nullptr && ctx.secondary != nullptr) {
      AddSecondaryEdgeSamples(ctx, *sampler, depth, hit.face, state.throughput, v.sp.p, v.sp.n,
                              v.sp.wo, v.surface.params, path, stats);
    }
    if (!Scatter(ctx, v, sampler, &state, &dir, &hit)) break;
  }
  return state.radiance;
}

bool TraceSharedSideJump(const Context& ctx, const Sampler& sampler, const Eigen::Vector3d dirs[2],
                         const RayHit hits[2], RenderStats* stats, Eigen::Vector3d* jump) {
  if (!hits[0].hit || !hits[1].hit) return false;
  PathVertex v[2];
  PathState state[2];
  for (int k = 0; k < 2; ++k) {
    if (!MakeVertex(ctx, dirs[k], hits[k], /*depth=*/0, &v[k])) return false;
    state[k].stats = stats;
  }
  if (!(v[0].sp.n.dot(v[1].sp.n) > kSharedSideMinCosine)) return false;
  // Both sides sample directions with side 0's sampling material; it must cover the hemisphere.
  if (!(GlossySelectionProbability(v[0].sampling) < 1.0)) return false;
  v[1].sampling = v[0].sampling;
  v[1].detached = true;
  Sampler shared;
  for (int k = 0; k < 2; ++k) {
    shared = sampler;  // the same light samples on both sides.
    AddDirectLight(ctx, v[k], &shared, &state[k]);
  }
  ScatterSample s;
  if (SampleScatter(ctx, v[0], &shared, stats, &s)) {
    bool continues = false;
    for (int k = 0; k < 2; ++k) continues |= ApplyScatter(ctx, v[k], s, &state[k]);
    if (continues) {
      const Eigen::Vector3d rest =
          TraceRadiance(ctx, &shared, s.bsdf.wi, s.next, stats, nullptr, /*first_depth=*/1);
      for (int k = 0; k < 2; ++k) state[k].radiance += state[k].throughput.cwiseProduct(rest);
    }
  }
  *jump = state[0].radiance - state[1].radiance;
  return true;
}

Eigen::Vector3d TraceAuxiliary(const Context& ctx, const Eigen::Vector3d& dir, const RayHit& hit) {
  if (!hit.hit) return Eigen::Vector3d::Zero();
  const BsdfParams params = LookUpMaterial(ctx, ctx.material, hit.face, hit.u, hit.v).params;
  switch (ctx.options.pass) {
    case RenderPass::kAlbedo:
      return params.albedo;
    case RenderPass::kRoughness:
      return Eigen::Vector3d::Constant(params.roughness);
    case RenderPass::kNormal: {
      Eigen::Vector3d n = ctx.options.shading == Shading::kSmooth
                              ? ctx.scene.SmoothNormal(hit.face, hit.u, hit.v)
                              : ctx.scene.FaceNormal(hit.face);
      if (ctx.scene.FaceNormal(hit.face).dot(dir) > 0.0) n = -n;
      return n;
    }
    case RenderPass::kDepth: {
      const Eigen::Vector3d p = ctx.scene.Point(hit.face, hit.u, hit.v);
      return Eigen::Vector3d::Constant((ctx.view.cam_from_world * p).z());
    }
    case RenderPass::kColor:
      break;
  }
  return Eigen::Vector3d::Zero();
}

}  // namespace render_internal
}  // namespace sft
