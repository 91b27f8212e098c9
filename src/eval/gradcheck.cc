#include "src/eval/gradcheck.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/scene_setup.h"
#include "src/render/scene.h"

namespace sft {
namespace {

// The material and view at θ + t·δ.
Material PerturbMaterial(const Material& base, const ParameterLayout& layout,
                         const std::vector<double>& delta, double t) {
  Material m = base;
  for (size_t i = 0; i < m.AlbedoValues().size(); ++i) {
    m.AlbedoValues()[i] += t * delta[layout.AlbedoOffset() + i];
  }
  for (size_t i = 0; i < m.RoughnessValues().size(); ++i) {
    m.RoughnessValues()[i] += t * delta[layout.RoughnessOffset() + i];
  }
  m.specular += t * delta[layout.SpecularIndex()];
  return m;
}

// The view with its lights at parameters + t·δ. An environment whose rotation is a parameter is
// turned by exp([t·δ]×) in its frame, `world_from_frame` (I for a world-fixed probe, Rᵀ of the
// camera for a camera-fixed one: Rᵀ·exp([t·δ]×)·R in the world), into *turned, which the view
// then points at. The frame comes from the dataset, not from the view's
// environment_rotation_jacobian, so that a wrong Jacobian shows.
ViewSetup PerturbView(const ViewSetup& base, const ParameterLayout& layout,
                      const std::vector<double>& delta, double t,
                      const Eigen::Matrix3d& world_from_frame,
                      std::unique_ptr<EnvironmentMap>* turned) {
  ViewSetup view = base;
  if (view.environment != nullptr && layout.FitsEnvironmentRotation(view.environment_light_index)) {
    const Eigen::Vector3d d(
        &delta[layout.EnvironmentRotationOffset() + 3 * view.environment_light_index]);
    *turned = std::make_unique<EnvironmentMap>(view.environment->Rotated(
        world_from_frame * RotationFromVector(t * d) * world_from_frame.transpose()));
    view.environment = turned->get();
  }
  for (PointLight& light : view.point_lights) {
    if (light.light_index >= 0) {
      light.intensity *= 1.0 + t * delta[layout.LightOffset() + light.light_index];
    }
  }
  for (DirectionalLight& light : view.directional_lights) {
    if (light.light_index >= 0) {
      light.irradiance *= 1.0 + t * delta[layout.LightOffset() + light.light_index];
    }
  }
  if (view.environment_light_index >= 0) {
    view.environment_scale *= 1.0 + t * delta[layout.LightOffset() + view.environment_light_index];
  }
  for (PointLight& light : view.point_lights) {
    if (!layout.FitsLightPosition(light.light_index)) continue;
    const Eigen::Vector3d d(&delta[layout.LightPositionOffset() + 3 * light.light_index]);
    light.position += t * (LightPositionJacobian(view, light) * d);
  }
  // A direction's parameters are the unit direction v0 in the light's frame: v0 + t·δ,
  // normalized (the layout's light_directions; at t = 0 |v| = 1, parameter_norm).
  const Eigen::Matrix3d cam_from_world = view.cam_from_world.rotation.toRotationMatrix();
  for (DirectionalLight& light : view.directional_lights) {
    if (!layout.FitsLightDirection(light.light_index)) continue;
    const Eigen::Vector3d d(&delta[layout.LightDirectionOffset() + 3 * light.light_index]);
    const Eigen::Vector3d v0 =
        light.camera_frame ? cam_from_world * light.direction : light.direction;
    const Eigen::Vector3d v = (v0 + t * d).normalized();
    light.direction = light.camera_frame ? cam_from_world.transpose() * v : v;
  }
  return view;
}

// The mesh at p + t·δ (vertex kind).
std::unique_ptr<RenderScene> DisplacedScene(const RenderScene& base,
                                            const std::vector<double>& delta, double t) {
  std::vector<Eigen::Vector3d> positions = base.positions();
  for (size_t v = 0; v < positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) positions[v][k] += t * delta[3 * v + k];
  }
  return std::make_unique<RenderScene>(positions, base.faces());
}

}  // namespace

std::vector<double> BlockSums(const std::vector<double>& image, int width, int height, int block) {
  const int bw = (width + block - 1) / block, bh = (height + block - 1) / block;
  std::vector<double> sums(3 * static_cast<size_t>(bw) * bh, 0.0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t b = static_cast<size_t>(y / block) * bw + x / block;
      for (int c = 0; c < 3; ++c) {
        sums[3 * b + c] += image[3 * (static_cast<size_t>(y) * width + x) + c];
      }
    }
  }
  return sums;
}

namespace {

// ‖error‖/‖reference‖ from squared norms; 1 when the reference vanishes but the error does not.
double RelativeError(double err2, double ref2) {
  return ref2 > 0 ? std::sqrt(err2 / ref2) : (err2 > 0 ? 1.0 : 0.0);
}

// The automatic vertex step, relative to the bounding-box diagonal (see GradcheckOptions::step).
constexpr double kAutomaticVertexStep = 5e-3;
// The automatic environment-rotation step, radians: small against a texel of a typical probe
// (2π/1024 ≈ 6e-3 rad), so that few lookups cross a texel centre's kink between the two renders.
constexpr double kAutomaticRotationStep = 1e-4;

// Factor on the automatic vertex step for a glossy lobe of width α = roughness² (the sharpest
// texel's): the step rotates face normals by up to ~0.05 rad, and the central difference of a
// highlight is only accurate while that stays well inside the lobe. Measured on
// bunny_point_ggx_gi (α = 0.12, one segment, 1024 spp, view 0): block error 13.5% at 2× the
// base step, 10% at 1×, 5.1% at ½, 3.1% at ¼ (1.7% at 4096 spp), linear in h, so 2α = ¼ there;
// no smaller than 1/16, where the finite difference's own noise (∝ 1/√h) takes over.
double GlossyStepFactor(const Material& material, const Effects& effects) {
  if (!effects.specular || !(material.specular > 0.0)) return 1.0;
  double min_roughness = 1.0;
  for (double r : material.RoughnessValues()) min_roughness = std::min(min_roughness, r);
  return std::clamp(2.0 * min_roughness * min_roughness, 1.0 / 16.0, 1.0);
}

// The smooth projection weights of the report: 1, cos(π(x + ½)/W), cos(π(y + ½)/H).
constexpr int kNumProjections = 3;
constexpr const char* kProjectionNames[kNumProjections] = {"one", "cos_x", "cos_y"};
double ProjectionWeight(int k, int x, int y, int width, int height) {
  if (k == 1) return std::cos(M_PI * (x + 0.5) / width);
  if (k == 2) return std::cos(M_PI * (y + 0.5) / height);
  return 1.0;
}

// Writes the analytic and finite-difference derivative images of one view (see
// GradcheckOptions::image_dir).
Status WriteGradcheckImages(const std::string& dir, int view, int width, int height,
                            const std::vector<double>& analytic, const std::vector<double>& fd) {
  const size_t pixels = static_cast<size_t>(width) * height;
  Image analytic_image(width, height, 3), fd_image(width, height, 3);
  std::vector<double> magnitudes;
  magnitudes.reserve(3 * pixels);
  for (size_t i = 0; i < 3 * pixels; ++i) {
    analytic_image.data[i] = static_cast<float>(analytic[i]);
    fd_image.data[i] = static_cast<float>(fd[i]);
    if (fd[i] != 0.0) magnitudes.push_back(std::abs(fd[i]));
  }
  // Scale: the 99th percentile of |fd|, so a few saturated edge pixels do not wash out the rest.
  double scale = 1.0;
  if (!magnitudes.empty()) {
    const size_t k = std::min(magnitudes.size() - 1, magnitudes.size() * 99 / 100);
    std::nth_element(magnitudes.begin(), magnitudes.begin() + k, magnitudes.end());
    scale = magnitudes[k] > 0.0 ? magnitudes[k] : 1.0;
  }
  Image compare(3 * width + 2, height, 3, 1.0f);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t p = static_cast<size_t>(y) * width + x;
      const double values[3] = {(analytic[3 * p] + analytic[3 * p + 1] + analytic[3 * p + 2]) / 3.0,
                                (fd[3 * p] + fd[3 * p + 1] + fd[3 * p + 2]) / 3.0, 0.0};
      const double diff = values[0] - values[1];
      for (int panel = 0; panel < 3; ++panel) {
        const double v = std::clamp((panel == 2 ? diff : values[panel]) / scale, -1.0, 1.0);
        const int px = panel * (width + 1) + x;
        compare.at(px, y, 0) = static_cast<float>(v > 0 ? 1.0 : 1.0 + v);
        compare.at(px, y, 1) = static_cast<float>(1.0 - std::abs(v));
        compare.at(px, y, 2) = static_cast<float>(v < 0 ? 1.0 : 1.0 - v);
      }
    }
  }
  const std::string stem = dir + "/view_" + std::to_string(view);
  SFT_RETURN_IF_ERROR(WriteExr(stem + "_analytic.exr", analytic_image));
  SFT_RETURN_IF_ERROR(WriteExr(stem + "_fd.exr", fd_image));
  return WritePng(stem + "_compare.png", compare, /*srgb=*/false);
}

}  // namespace

std::vector<double> SmoothDisplacementField(const std::vector<Eigen::Vector3d>& positions,
                                            uint64_t seed,
                                            const std::vector<Eigen::Vector3i>* faces) {
  std::vector<double> delta(3 * positions.size(), 0.0);
  if (positions.empty()) return delta;
  // The vertices the field is for (all without `faces`; unreferenced ones keep δ = 0).
  std::vector<char> used(positions.size(), faces == nullptr ? 1 : 0);
  if (faces != nullptr) {
    for (const Eigen::Vector3i& f : *faces) used[f[0]] = used[f[1]] = used[f[2]] = 1;
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (size_t v = 0; v < positions.size(); ++v) {
    if (!used[v]) continue;
    lo = lo.cwiseMin(positions[v]);
    hi = hi.cwiseMax(positions[v]);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double extent = (hi - lo).norm();
  if (!(extent > 0.0) || !std::isfinite(extent)) return delta;

  constexpr int kModes = 3;
  constexpr double kMaxWaveNumber = 1.5;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::Vector3d amplitude[kModes], wave[kModes];
  double phase[kModes];
  for (int m = 0; m < kModes; ++m) {
    for (int k = 0; k < 3; ++k) amplitude[m][k] = uniform(rng);
    for (int k = 0; k < 3; ++k) wave[m][k] = uniform(rng) * kMaxWaveNumber;
    if (wave[m].norm() > kMaxWaveNumber) wave[m] *= kMaxWaveNumber / wave[m].norm();
    phase[m] = M_PI * uniform(rng);
  }
  double max_norm = 0.0;
  for (size_t v = 0; v < positions.size(); ++v) {
    if (!used[v]) continue;
    const Eigen::Vector3d q = (positions[v] - centre) / extent;
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (int m = 0; m < kModes; ++m)
      d += amplitude[m] * std::sin(2.0 * M_PI * wave[m].dot(q) + phase[m]);
    for (int k = 0; k < 3; ++k) delta[3 * v + k] = d[k];
    max_norm = std::max(max_norm, d.norm());
  }
  if (max_norm > 0.0) {
    for (double& d : delta) d /= max_norm;
  }
  return delta;
}

std::vector<double> GradcheckDirection(const RenderScene& scene, const ParameterLayout& layout,
                                       ParameterKind kind, uint64_t direction_seed) {
  std::vector<double> delta(layout.size(), 0.0);
  if (kind == ParameterKind::kVertex) {
    const std::vector<double> field =
        SmoothDisplacementField(scene.positions(), direction_seed, &scene.faces());
    std::copy(field.begin(), field.end(), delta.begin() + layout.VertexOffset());
    return delta;
  }
  std::mt19937_64 rng(direction_seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int i = 0; i < layout.size(); ++i) {
    if (layout.KindOf(i) == kind) delta[i] = uniform(rng);
  }
  return delta;
}

std::vector<double> DirectionalDerivativeImage(const JacobianRows& rows,
                                               const std::vector<double>& delta) {
  const size_t pixels = static_cast<size_t>(rows.width) * rows.height;
  std::vector<double> image(3 * pixels, 0.0);
  for (size_t p = 0; p < pixels; ++p) {
    for (uint64_t e = rows.offsets[p]; e < rows.offsets[p + 1]; ++e) {
      const JacobianEntry& entry = rows.entries[e];
      for (int c = 0; c < 3; ++c) image[3 * p + c] += entry.d[c] * delta[entry.param];
    }
  }
  return image;
}

bool GradcheckOptions::Check(std::string* why) const {
  if (!render.Check(why)) return false;
  if (!derivatives.Check(why)) return false;
  if (!(step >= 0.0) || !std::isfinite(step)) {
    *why = "step: must be >= 0 (0 = automatic)";
    return false;
  }
  if (block < 0 || block > 4096) {
    *why = "block: must be in [0, 4096] (0 = automatic)";
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

Status PrepareGradcheck(const Dataset& dataset, const GradcheckOptions& options,
                        GradcheckSetup* setup) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  setup->request = options.derivatives;
  setup->request.params = ParameterSelection::Only(options.kind);
  setup->request.jacobian_rows = true;
  setup->request.adjoint_weights = nullptr;
  if (!setup->request.Check(&why)) return Status::Error(why);
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &setup->views));
  SFT_RETURN_IF_ERROR(
      SelectViews(options.views, static_cast<int>(setup->views.views.size()), &setup->selected));
  setup->block = options.block > 0 ? options.block
                                   : (options.kind == ParameterKind::kVertex ||
                                              options.kind == ParameterKind::kLightPosition ||
                                              options.kind == ParameterKind::kLightDirection
                                          ? 8
                                          : 1);
  if (options.kind == ParameterKind::kEnvironmentRotation) {
    bool any = false;
    for (int v : setup->selected) any |= setup->views.views[v].environment != nullptr;
    if (!any) {
      return Status::Error(
          "--param environment_rotation: no selected view has an environment light");
    }
  }
  return Status::Ok();
}

Status RunGradcheck(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                    const GradcheckOptions& options, GradcheckResult* result) {
  GradcheckSetup setup;
  SFT_RETURN_IF_ERROR(PrepareGradcheck(dataset, options, &setup));
  DerivativeRequest& request = setup.request;
  const DatasetViews& views = setup.views;
  const std::vector<int>& selected = setup.selected;
  const int block = setup.block;
  const RenderScene scene(mesh);
  ParameterLayout layout =
      MakeParameterLayout(scene, material, static_cast<int>(dataset.lights.size()));
  layout.light_positions = options.kind == ParameterKind::kLightPosition;
  layout.light_directions = options.kind == ParameterKind::kLightDirection;
  layout.environment_rotations = options.kind == ParameterKind::kEnvironmentRotation;
  const bool vertices = options.kind == ParameterKind::kVertex;

  std::vector<double> delta =
      GradcheckDirection(scene, layout, options.kind, options.direction_seed);
  // The adjoint check's random pixel weights (drawn after the direction's own stream).
  std::mt19937_64 rng(options.direction_seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  if (!vertices) {
    for (int i = 0; i < layout.size(); ++i) {
      if (layout.KindOf(i) == options.kind) uniform(rng);
    }
  }
  double step = options.step;
  if (step == 0.0) {
    double mean_roughness = 0.0;
    for (double r : material.RoughnessValues()) mean_roughness += r;
    mean_roughness /= std::max<size_t>(1, material.RoughnessValues().size());
    step = options.kind == ParameterKind::kRoughness ? 1e-4 * std::max(mean_roughness, 0.01)
           : vertices ? kAutomaticVertexStep * GlossyStepFactor(material, options.render.effects) *
                            scene.extent()
           : options.kind == ParameterKind::kLightPosition  ? kAutomaticVertexStep * scene.extent()
           : options.kind == ParameterKind::kLightDirection ? kAutomaticVertexStep
           : options.kind == ParameterKind::kEnvironmentRotation ? kAutomaticRotationStep
                                                                 : 1e-3;
  }

  RenderOptions render = options.render;
  render.sampling_material = &material;
  // The specular weight is clamped at 0 (no glossy lobe below it), so at 0 the image has a kink
  // and the analytic derivative is the one-sided one: compare with a forward difference into the
  // valid side there (exact: the image is linear in the specular weight).
  const bool one_sided = options.kind == ParameterKind::kSpecular && material.specular < step;
  if (one_sided) {
    delta[layout.SpecularIndex()] = std::abs(delta[layout.SpecularIndex()]);
  }
  const Material plus_material = PerturbMaterial(material, layout, delta, step);
  const Material minus_material = PerturbMaterial(material, layout, delta, one_sided ? 0.0 : -step);
  const double fd_span = one_sided ? step : 2.0 * step;
  // Vertex kind: the displaced meshes; other kinds render the unchanged scene.
  std::unique_ptr<RenderScene> plus_scene, minus_scene;
  if (vertices) {
    plus_scene = DisplacedScene(scene, delta, step);
    minus_scene = DisplacedScene(scene, delta, -step);
  }

  if (!options.image_dir.empty()) SFT_RETURN_IF_ERROR(MakeDirectories(options.image_dir));
  result->kind = ParameterKindName(options.kind);
  result->block = block;
  result->step = step;
  result->views.clear();
  result->nonfinite_samples = result->nonfinite_outputs = 0;
  double total_err2 = 0.0, total_ref2 = 0.0;              // block sums.
  double total_pixel_err2 = 0.0, total_pixel_ref2 = 0.0;  // pixels.
  double total_proj_err2 = 0.0, total_proj_ref2 = 0.0;    // projections.
  for (int v : selected) {
    const ViewSetup& view = views.views[v];
    const int width = view.camera.width, height = view.camera.height;
    Image weights(width, height, 3);
    for (float& w : weights.data) w = static_cast<float>(uniform(rng));
    request.adjoint_weights = &weights;
    Image image, plus, minus;
    DerivativeOutput out;
    RenderStats stats[3];
    // A turned environment is sampled as the unturned one (detached sampling): the three renders
    // follow the same paths.
    RenderOptions view_render = render;
    if (view.environment != nullptr) view_render.sampling_environment = view.environment;
    RenderViewWithDerivatives(scene, material, view, view_render, request, layout, &image, &out,
                              &stats[0]);
    std::unique_ptr<EnvironmentMap> plus_map, minus_map;
    const Eigen::Matrix3d world_from_frame =
        views.view_environments[v] != nullptr
            ? view.cam_from_world.rotation.conjugate().toRotationMatrix()
            : Eigen::Matrix3d::Identity();
    RenderView(vertices ? *plus_scene : scene, plus_material,
               PerturbView(view, layout, delta, step, world_from_frame, &plus_map), view_render,
               &plus, &stats[1]);
    RenderView(vertices ? *minus_scene : scene, minus_material,
               PerturbView(view, layout, delta, -step, world_from_frame, &minus_map), view_render,
               &minus, &stats[2]);

    // The directional derivative images, RGB per pixel.
    const size_t pixels = static_cast<size_t>(width) * height;
    const std::vector<double> analytic = DirectionalDerivativeImage(out.rows, delta);
    std::vector<double> fd(3 * pixels, 0.0);
    double weighted = 0.0, weighted_abs = 0.0;
    for (size_t p = 0; p < pixels; ++p) {
      for (int c = 0; c < 3; ++c) {
        fd[3 * p + c] =
            (static_cast<double>(plus.data[4 * p + c]) - minus.data[4 * p + c]) / fd_span;
        weighted += weights.data[3 * p + c] * analytic[3 * p + c];
        weighted_abs += std::abs(weights.data[3 * p + c] * analytic[3 * p + c]);
      }
    }
    if (!options.image_dir.empty()) {
      SFT_RETURN_IF_ERROR(WriteGradcheckImages(options.image_dir, v, width, height, analytic, fd));
    }
    double pixel_err2 = 0.0, pixel_ref2 = 0.0;
    for (size_t i = 0; i < 3 * pixels; ++i) {
      pixel_err2 += (analytic[i] - fd[i]) * (analytic[i] - fd[i]);
      pixel_ref2 += fd[i] * fd[i];
    }
    double err2 = pixel_err2, ref2 = pixel_ref2;
    if (block > 1) {
      const std::vector<double> analytic_blocks = BlockSums(analytic, width, height, block);
      const std::vector<double> fd_blocks = BlockSums(fd, width, height, block);
      err2 = ref2 = 0.0;
      for (size_t i = 0; i < fd_blocks.size(); ++i) {
        err2 += (analytic_blocks[i] - fd_blocks[i]) * (analytic_blocks[i] - fd_blocks[i]);
        ref2 += fd_blocks[i] * fd_blocks[i];
      }
    }
    GradcheckViewResult view_result;
    double proj_err2 = 0.0, proj_ref2 = 0.0;
    for (int k = 0; k < kNumProjections; ++k) {
      GradcheckProjection projection;
      projection.weight = kProjectionNames[k];
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          const double w = ProjectionWeight(k, x, y, width, height);
          const size_t p = static_cast<size_t>(y) * width + x;
          for (int c = 0; c < 3; ++c) {
            projection.analytic += w * analytic[3 * p + c];
            projection.fd += w * fd[3 * p + c];
          }
        }
      }
      proj_err2 += (projection.analytic - projection.fd) * (projection.analytic - projection.fd);
      proj_ref2 += projection.fd * projection.fd;
      view_result.projections.push_back(projection);
    }
    double adjoint = 0.0;
    for (int i = 0; i < layout.size(); ++i) adjoint += out.gradient[i] * delta[i];
    view_result.view = v;
    view_result.fd_norm = std::sqrt(pixel_ref2);
    view_result.relative_error = RelativeError(err2, ref2);
    view_result.pixel_relative_error = RelativeError(pixel_err2, pixel_ref2);
    view_result.projection_error = RelativeError(proj_err2, proj_ref2);
    view_result.adjoint_mismatch =
        weighted_abs > 0 ? std::abs(adjoint - weighted) / weighted_abs : 0.0;
    view_result.jacobian_entries = out.rows.entries.size();
    for (const RenderStats& s : stats) {
      view_result.nonfinite_samples += s.nonfinite_samples;
      view_result.nonfinite_outputs += s.nonfinite_outputs;
    }
    result->nonfinite_samples += view_result.nonfinite_samples;
    result->nonfinite_outputs += view_result.nonfinite_outputs;
    result->views.push_back(view_result);
    total_err2 += err2;
    total_ref2 += ref2;
    total_pixel_err2 += pixel_err2;
    total_pixel_ref2 += pixel_ref2;
    total_proj_err2 += proj_err2;
    total_proj_ref2 += proj_ref2;
  }
  if (!(total_pixel_ref2 > 0.0)) {
    return Status::Error(std::string("--param ") + result->kind +
                         ": the perturbation does not change any selected view (nothing to check)");
  }
  result->relative_error = RelativeError(total_err2, total_ref2);
  result->pixel_relative_error = RelativeError(total_pixel_err2, total_pixel_ref2);
  result->projection_error = RelativeError(total_proj_err2, total_proj_ref2);
  bool adjoint_ok = true;
  for (const GradcheckViewResult& r : result->views) adjoint_ok &= r.adjoint_mismatch <= 1e-4;
  result->passed = result->relative_error <= options.tolerance && adjoint_ok;
  return Status::Ok();
}

}  // namespace sft
