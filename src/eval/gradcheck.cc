#include "src/eval/gradcheck.h"

#include <cmath>
#include <random>

#include "src/io/scene_setup.h"
#include "src/render/scene.h"

namespace sft {
namespace {

// The material and view at θ + t·δ.
Material PerturbMaterial(const Material& base, const ParameterLayout& layout,
                         const std::vector<double>& delta, double t) {
  Material m = base;
  for (size_t i = 0; i < m.albedo.values().size(); ++i) {
    m.albedo.values()[i] += t * delta[layout.AlbedoOffset() + i];
  }
  for (size_t i = 0; i < m.roughness.values().size(); ++i) {
    m.roughness.values()[i] += t * delta[layout.RoughnessOffset() + i];
  }
  m.specular += t * delta[layout.SpecularIndex()];
  return m;
}

ViewSetup PerturbView(const ViewSetup& base, const ParameterLayout& layout,
                      const std::vector<double>& delta, double t) {
  ViewSetup view = base;
  for (PointLight& light : view.point_lights) {
    if (light.light_index >= 0) {
      light.intensity *= 1.0 + t * delta[layout.LightOffset() + light.light_index];
    }
  }
  if (view.environment_light_index >= 0) {
    view.environment_scale *= 1.0 + t * delta[layout.LightOffset() + view.environment_light_index];
  }
  return view;
}

}  // namespace

bool GradcheckOptions::Check(std::string* why) const {
  if (!render.Check(why)) return false;
  if (!(step >= 0.0) || !std::isfinite(step)) {
    *why = "step: must be >= 0 (0 = automatic)";
    return false;
  }
  if (!(tolerance > 0.0)) {
    *why = "tolerance: must be > 0";
    return false;
  }
  if (render.pass != RenderPass::kColor) {
    *why = "pass: derivatives are of the color pass";
    return false;
  }
  return true;
}

Status RunGradcheck(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                    const GradcheckOptions& options, GradcheckResult* result) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  DerivativeRequest request;
  request.params = ParameterSelection::Only(options.kind);
  request.jacobian_rows = true;
  if (!request.Check(&why)) return Status::Error("--param " + why);
  DatasetViews views;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &views));
  std::vector<int> selected;
  SFT_RETURN_IF_ERROR(SelectViews(options.views, static_cast<int>(views.views.size()), &selected));
  const RenderScene scene(mesh);
  const ParameterLayout layout =
      MakeParameterLayout(scene, material, static_cast<int>(dataset.lights.size()));

  std::mt19937_64 rng(options.direction_seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> delta(layout.size(), 0.0);
  for (int i = 0; i < layout.size(); ++i) {
    if (layout.KindOf(i) == options.kind) delta[i] = uniform(rng);
  }
  double step = options.step;
  if (step == 0.0) {
    double mean_roughness = 0.0;
    for (double r : material.roughness.values()) mean_roughness += r;
    mean_roughness /= std::max<size_t>(1, material.roughness.values().size());
    step = options.kind == ParameterKind::kRoughness ? 1e-4 * std::max(mean_roughness, 0.01) : 1e-3;
  }

  RenderOptions render = options.render;
  render.sampling_material = &material;
  const Material plus_material = PerturbMaterial(material, layout, delta, step);
  const Material minus_material = PerturbMaterial(material, layout, delta, -step);

  result->kind = ParameterKindName(options.kind);
  result->views.clear();
  double total_err2 = 0.0, total_ref2 = 0.0;
  for (int v : selected) {
    const ViewSetup& view = views.views[v];
    const int width = view.camera.width, height = view.camera.height;
    Image weights(width, height, 3);
    for (float& w : weights.data) w = static_cast<float>(uniform(rng));
    request.adjoint_weights = &weights;
    Image image, plus, minus;
    DerivativeOutput out;
    RenderViewWithDerivatives(scene, material, view, render, request,
                              static_cast<int>(dataset.lights.size()), &image, &out);
    RenderView(scene, plus_material, PerturbView(view, layout, delta, step), render, &plus);
    RenderView(scene, minus_material, PerturbView(view, layout, delta, -step), render, &minus);

    double err2 = 0.0, ref2 = 0.0, weighted = 0.0, weighted_abs = 0.0;
    for (int p = 0; p < width * height; ++p) {
      double analytic[3] = {0, 0, 0};
      for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
        const JacobianEntry& entry = out.rows.entries[e];
        for (int c = 0; c < 3; ++c) analytic[c] += entry.d[c] * delta[entry.param];
      }
      for (int c = 0; c < 3; ++c) {
        const double fd =
            (static_cast<double>(plus.data[4 * p + c]) - minus.data[4 * p + c]) / (2.0 * step);
        err2 += (analytic[c] - fd) * (analytic[c] - fd);
        ref2 += fd * fd;
        weighted += weights.data[3 * p + c] * analytic[c];
        weighted_abs += std::abs(weights.data[3 * p + c] * analytic[c]);
      }
    }
    double adjoint = 0.0;
    for (int i = 0; i < layout.size(); ++i) adjoint += out.gradient[i] * delta[i];
    GradcheckViewResult view_result;
    view_result.view = v;
    view_result.fd_norm = std::sqrt(ref2);
    view_result.relative_error = ref2 > 0 ? std::sqrt(err2 / ref2) : (err2 > 0 ? 1.0 : 0.0);
    view_result.adjoint_mismatch =
        weighted_abs > 0 ? std::abs(adjoint - weighted) / weighted_abs : 0.0;
    view_result.jacobian_entries = out.rows.entries.size();
    result->views.push_back(view_result);
    total_err2 += err2;
    total_ref2 += ref2;
  }
  if (!(total_ref2 > 0.0)) {
    return Status::Error(std::string("--param ") + result->kind +
                         ": the perturbation does not change any selected view (nothing to check)");
  }
  result->relative_error = std::sqrt(total_err2 / total_ref2);
  bool adjoint_ok = true;
  for (const GradcheckViewResult& r : result->views) adjoint_ok &= r.adjoint_mismatch <= 1e-4;
  result->passed = result->relative_error <= options.tolerance && adjoint_ok;
  return Status::Ok();
}

}  // namespace sft
