#include "src/optim/render_cache.h"

#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace sft {
namespace {

// Scene identities (RenderState::scene_id), unique within the process.
std::atomic<int64_t> g_next_scene_id{1};

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The view's active level-0 pixels: its mask dilated by `dilation` pixels, or every pixel.
Status ActivePixels(const Dataset& dataset, int view, int width, int height, int dilation,
                    std::vector<uint8_t>* active, bool* has_mask) {
  *has_mask = !dataset.views[view].mask.empty();
  if (!*has_mask) {
    active->assign(static_cast<size_t>(width) * height, 1);
    return Status::Ok();
  }
  Image mask;
  SFT_RETURN_IF_ERROR(LoadViewMask(dataset, view, &mask));
  cv::Mat m(height, width, CV_8U);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) m.at<uint8_t>(y, x) = mask.at(x, y) > 0.5f ? 1 : 0;
  }
  if (dilation > 0) {
    cv::dilate(
        m, m,
        cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * dilation + 1, 2 * dilation + 1)));
  }
  active->assign(m.begin<uint8_t>(), m.end<uint8_t>());
  return Status::Ok();
}

// The relative loss's per-pixel weights of each level (render_cache.h, ImageLoss::kRelative):
// √w_p = 2m / (m + ȳ_p) with m the median of ȳ over the active level-0 pixels that are not
// black (so that a black background without a mask does not set the scale). A black view keeps
// weights 1.
void SetRelativeWeights(const std::vector<uint8_t>& active0,
                        std::vector<std::unique_ptr<LevelCache>>* levels) {
  auto mean_rgb = [](const Image& image, int p) {
    const int x = p % image.width, y = p / image.width;
    return (static_cast<double>(image.at(x, y, 0)) + image.at(x, y, 1) + image.at(x, y, 2)) / 3.0;
  };
  const Image& target0 = (*levels)[0]->target;
  std::vector<double> values;
  for (size_t p = 0; p < active0.size(); ++p) {
    const double y = active0[p] ? mean_rgb(target0, static_cast<int>(p)) : 0.0;
    if (y > 0.0) values.push_back(y);
  }
  if (values.empty()) return;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double m = values[values.size() / 2];
  if (!(m > 0.0)) return;
  for (auto& level : *levels) {
    const int n = level->target.width * level->target.height;
    level->pixel_sqrt_weight.resize(n);
    for (int p = 0; p < n; ++p) {
      const double y = std::max(0.0, mean_rgb(level->target, p));
      level->pixel_sqrt_weight[p] = static_cast<float>(2.0 * m / (m + y));
    }
  }
}

// Multiplies channel c of every pixel of an RGB image by gain[c].
void ApplyGains(const Eigen::Vector3d& gain, Image* rgb) {
  for (size_t i = 0; i < rgb->data.size(); ++i) rgb->data[i] *= static_cast<float>(gain[i % 3]);
}

// The rows of the gained image g ⊙ I of one view (render_cache.h, "Exposure gains"): every entry
// ∂I_c/∂θ becomes g_c·∂I_c/∂θ and, when `gain_offset` ≥ 0, each pixel gets the three entries
// ∂(g_c I_c)/∂g_c = I_c (channel c only) at gain_offset + c — after the pixel's other entries,
// since the gains have the highest indices. `ungained` is I (RGB, level 0); zero entries are left
// out.
LevelRows GainedRows(const LevelRows& rows, const Image& ungained, const Eigen::Vector3d& gain,
                     int gain_offset) {
  LevelRows out;
  out.width = rows.width;
  out.height = rows.height;
  const size_t pixels = static_cast<size_t>(rows.width) * rows.height;
  out.offsets.reserve(pixels + 1);
  out.entries.reserve(rows.entries.size() + (gain_offset >= 0 ? 3 * pixels : 0));
  out.offsets.push_back(0);
  for (size_t p = 0; p < pixels; ++p) {
    for (uint64_t i = rows.offsets[p]; i < rows.offsets[p + 1]; ++i) {
      RowEntry e = rows.entries[i];
      for (int c = 0; c < 3; ++c) e.d[c] *= gain[c];
      out.entries.push_back(e);
    }
    if (gain_offset >= 0) {
      for (int c = 0; c < 3; ++c) {
        const double value = ungained.data[3 * p + c];
        if (value == 0.0) continue;
        RowEntry e{gain_offset + c, {0.0, 0.0, 0.0}};
        e.d[c] = value;
        out.entries.push_back(e);
      }
    }
    out.offsets.push_back(out.entries.size());
  }
  return out;
}

}  // namespace

bool ImageLossFromName(const std::string& name, ImageLoss* loss) {
  if (name == "l2") {
    *loss = ImageLoss::kL2;
  } else if (name == "relative") {
    *loss = ImageLoss::kRelative;
  } else {
    return false;
  }
  return true;
}

const char* ImageLossName(ImageLoss loss) {
  return loss == ImageLoss::kRelative ? "relative" : "l2";
}

bool RenderCacheOptions::Check(std::string* why) const {
  if (!render.Check(why)) return false;
  if (!edges.Check(why)) return false;
  if (pyramid_levels < 1 || pyramid_levels > 12) {
    *why = "pyramid_levels: must be in [1, 12]";
    return false;
  }
  if (!(level_weight > 0.0 && level_weight <= 64.0)) {
    *why = "level_weight: must be in (0, 64]";
    return false;
  }
  if (!(image_weight >= 0.0 && image_weight <= 1e6)) {
    *why = "image_weight: must be in [0, 1e6]";
    return false;
  }
  if (mask_dilation < 0 || mask_dilation > 64) {
    *why = "mask_dilation: must be in [0, 64]";
    return false;
  }
  if (image_scale_log2 < 0 || image_scale_log2 > 6) {
    *why = "image_scale: must be 1, 1/2, 1/4, ... or 1/64";
    return false;
  }
  if (pyramid_filter != PyramidFilter::kBox && pyramid_filter != PyramidFilter::kBinomial) {
    *why = "pyramid_filter: must be box or binomial";
    return false;
  }
  if (image_loss != ImageLoss::kL2 && image_loss != ImageLoss::kRelative) {
    *why = "image_loss: must be l2 or relative";
    return false;
  }
  return true;
}

Status RenderCache::Create(const Dataset& dataset, const DatasetViews* views,
                           const std::vector<int>& view_indices,
                           const std::vector<Eigen::Vector3i>& faces, const Material& material,
                           SceneParameters* params, const RenderCacheOptions& options,
                           std::unique_ptr<RenderCache>* cache) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  std::unique_ptr<RenderCache> c(new RenderCache());
  c->dataset_ = &dataset;
  c->views_ = views;
  c->view_indices_ = view_indices;
  c->params_ = params;
  c->options_ = options;
  c->material_ = material;
  params->Positions(&c->scene_positions_);
  c->scene_ = std::make_unique<RenderScene>(c->scene_positions_, faces);
  c->scene_id_ = g_next_scene_id++;
  c->faces_ = faces;
  c->scene_build_positions_ = c->scene_positions_;
  c->runner_ = CurrentViewRunner();
  for (int v : view_indices) {
    Image target;
    SFT_RETURN_IF_ERROR(LoadViewImage(dataset, v, &target));
    ViewTargets targets;
    std::vector<uint8_t> active;
    SFT_RETURN_IF_ERROR(ActivePixels(dataset, v, target.width, target.height, options.mask_dilation,
                                     &active, &targets.has_mask));
    Image scaled = ToRgb(target);
    if (options.image_scale_log2 > 0) {
      // A lower-resolution camera integrates over its larger pixels: always the box filter here.
      const int k = options.image_scale_log2;
      scaled = BuildPyramid(scaled, k + 1).back();
      active = MaskPyramid(active, target.width, target.height, k + 1).back();
    }
    const std::vector<Image> pyramid =
        BuildPyramid(scaled, options.pyramid_levels, options.pyramid_filter);
    targets.active = MaskPyramid(active, scaled.width, scaled.height,
                                 static_cast<int>(pyramid.size()), options.pyramid_filter);
    std::vector<std::unique_ptr<LevelCache>> levels;
    for (size_t l = 0; l < pyramid.size(); ++l) {
      auto level = std::make_unique<LevelCache>();
      level->target = pyramid[l];
      level->render = Image(pyramid[l].width, pyramid[l].height, 3);
      level->sqrt_weight =
          std::sqrt(options.image_weight) * std::pow(options.level_weight, 0.5 * l);
      levels.push_back(std::move(level));
    }
    if (options.image_loss == ImageLoss::kRelative) SetRelativeWeights(targets.active[0], &levels);
    c->targets_.push_back(std::move(targets));
    c->levels_.push_back(std::move(levels));
  }
  *cache = std::move(c);
  return Status::Ok();
}

void RenderCache::PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) {
  if (stale_ || new_evaluation_point || (evaluate_jacobians && !has_rows_)) Render(/*rows=*/true);
}

void RenderCache::UpdateScene() {
  std::vector<Eigen::Vector3d> positions;
  params_->Positions(&positions);
  if (positions != scene_positions_) {
    scene_->SetVertices(positions);
    scene_positions_ = std::move(positions);
  }
  params_->WriteMaterial(&material_);
  if (params_->has_environment()) {
    fitted_environment_.Update(params_->EnvironmentTexels(), *dataset_,
                               params_->layout().environment_light);
  }
  rotated_environments_.Update(params_->EnvironmentRotations(), *views_);
}

ViewSetup RenderCache::ScaledView(int v) const {
  ViewSetup view =
      ScaledViewSetup(*views_, view_indices_[v], options_.image_scale_log2, params_->LightScales(),
                      params_->LightPositions(), params_->LightDirections());
  const bool poses = params_->num_pose_views() > 0;
  const PoseDelta pose = poses ? params_->Pose(v) : PoseDelta::Zero();
  UseFittedLightingAndPose(rotated_environments_, params_->layout(), fitted_environment_,
                           view_indices_[v], poses ? &pose : nullptr, &view);
  return view;
}

bool RenderCache::FitsPose(int v) const { return active_.poses && params_->PoseFitted(v); }

PoseChain RenderCache::ChainOf(int v) const {
  return PoseChain(params_->layout(), ScaledView(v), params_->Pose(v), scene_positions_,
                   params_->LightDirections());
}

DerivativeRequest RenderCache::ActiveRequest() const {
  DerivativeRequest request = options_.edges;
  request.params = active_.ToSelection();
  // Pose rows are contracted from the rows of everything that moves with the scene.
  if (active_.poses && params_->num_pose_views() > 1) AddPoseChainSelection(&request.params);
  request.jacobian_rows = false;
  request.adjoint_weights = nullptr;
  return request;
}

RenderState RenderCache::CurrentState(const RenderOptions& render,
                                      const DerivativeRequest& request) const {
  RenderState state;
  state.scene_id = scene_id_;
  state.build_positions = scene_build_positions_;
  state.faces = faces_;
  state.positions = scene_positions_;
  state.material = material_;
  state.light_scales = params_->LightScales();
  state.light_positions = params_->LightPositions();
  state.light_directions = params_->LightDirections();
  state.environment_rotations = params_->EnvironmentRotations();
  for (int v = 0; v < params_->num_pose_views(); ++v) {
    state.pose_corrections.push_back(params_->Pose(v));
  }
  state.render = render;
  state.request = request;
  state.layout = params_->layout();
  state.image_scale_log2 = options_.image_scale_log2;
  state.view_indices = view_indices_;
  if (params_->has_environment()) {
    state.environment = fitted_environment_.texels();
    state.environment_frame = dataset_->lights.at(params_->layout().environment_light).frame;
  }
  return state;
}

void RenderCache::RunJobs(const std::vector<ViewJob>& jobs, const ViewRunner::Consume& consume) {
  RunJobs(jobs, options_.render, ActiveRequest(), consume);
}

void RenderCache::RunJobs(const std::vector<ViewJob>& jobs, const RenderOptions& render,
                          const DerivativeRequest& request, const ViewRunner::Consume& consume) {
  UpdateScene();
  const ParameterLayout& layout = params_->layout();
  const auto local = [&](const ViewJob& job, ViewResult* result) {
    RenderViewJob(*scene_, material_, ScaledView(job.view), render, request, layout, job, result);
  };
  double consume_seconds = 0.0;
  const auto timed_consume = [&](size_t k, ViewResult* result) {
    const auto start = std::chrono::steady_clock::now();
    consume(k, result);
    ++renders_;
    consume_seconds += Seconds(start);
  };
  const auto start = std::chrono::steady_clock::now();
  if (runner_ == nullptr || request.gradient_parts) {
    for (size_t k = 0; k < jobs.size(); ++k) {
      ViewResult result;
      local(jobs[k], &result);
      timed_consume(k, &result);
    }
  } else {
    runner_->Run(CurrentState(render, request), jobs, local, timed_consume);
  }
  render_seconds_ += std::max(0.0, Seconds(start) - consume_seconds);
}

Image RenderCache::RenderPassImage(int v, RenderPass pass) {
  UpdateScene();
  RenderOptions render = options_.render;
  render.seed = seed_;
  render.pass = pass;
  render.spp = 4;  // antialiasing only: the pass has no noise.
  ViewSetup view = ScaledView(v);
  view.camera = views_->views[view_indices_[v]].camera;  // the dataset's resolution.
  Image image;
  RenderStats stats;
  RenderView(*scene_, material_, view, render, &image, &stats);
  return image;
}

void RenderCache::Render(bool rows) {
  stale_ = false;
  finite_ = true;
  non_finite_ = 0;
  const bool with_rows = rows && active_.Any();
  std::vector<ViewJob> jobs(num_views());
  for (int v = 0; v < num_views(); ++v) {
    jobs[v].view = v;
    jobs[v].pass = with_rows ? ViewPass::kRows : ViewPass::kImage;
    jobs[v].seed = seed_;
  }
  // Samples or outputs lost to non-finite values make the evaluation fail (finite_), so that
  // the solver rejects the step instead of fitting to a biased or infinite render.
  RunJobs(jobs, [&](size_t k, ViewResult* result) {
    non_finite_ += result->non_finite;
    StoreRender(jobs[k].view, result->image, with_rows ? &result->rows : nullptr);
  });
  has_rows_ = with_rows;
}

bool RenderCache::RenderSome(const std::vector<int>& views) {
  finite_ = true;
  non_finite_ = 0;
  std::vector<ViewJob> jobs(views.size());
  for (size_t k = 0; k < views.size(); ++k) {
    jobs[k].view = views[k];
    jobs[k].seed = seed_;
  }
  RunJobs(jobs, [&](size_t k, ViewResult* result) {
    non_finite_ += result->non_finite;
    StoreRender(jobs[k].view, result->image, nullptr);
  });
  has_rows_ = false;
  stale_ = true;
  return finite_;
}

void RenderCache::StoreRender(int v, const Image& image, const JacobianRows* rows) {
  const auto start = std::chrono::steady_clock::now();
  Image rgb = ToRgb(image);
  const Eigen::Vector3d gain = params_->Gains(v);
  const bool fit_gains = active_.exposure && params_->GainFitted(v);
  const Image ungained = fit_gains ? rgb : Image();
  if (gain != Eigen::Vector3d::Ones()) ApplyGains(gain, &rgb);
  std::vector<Image> pyramid = BuildPyramid(rgb, num_levels(v), options_.pyramid_filter);
  LevelRows level_rows;
  if (rows != nullptr) {
    level_rows = RowsFromRenderer(*rows);
    const ParameterLayout& layout = params_->layout();
    for (RowEntry& e : level_rows.entries) {
      // The renderer differentiates light l at the rendered intensity I·s_l, i.e. it returns
      // s_l·∂I/∂s_l; the fit's parameter is s_l itself.
      if (layout.KindOf(e.param) == ParameterKind::kLight) {
        const double scale = params_->LightScale(e.param - layout.LightOffset());
        for (double& d : e.d) d /= scale;
      }
      for (double d : e.d) non_finite_ += !std::isfinite(d);  // a light-scale division.
    }
    if (fit_gains || gain != Eigen::Vector3d::Ones()) {
      level_rows =
          GainedRows(level_rows, ungained, gain, fit_gains ? params_->GainIndex(v, 0) : -1);
    }
    if (active_.poses && params_->num_pose_views() > 1) {
      // The rows of kinds the phase does not fit were only rendered for the pose chain.
      const auto keep = [&](int param) {
        return param >= layout.size() || active_.Includes(layout.KindOf(param));
      };
      const PoseChain chain = FitsPose(v) ? ChainOf(v) : PoseChain();
      level_rows = PoseRows(level_rows, chain, params_->PoseIndex(v, 0), keep);
    }
  }
  for (int l = 0; l < num_levels(v); ++l) {
    LevelCache& level = *levels_[v][l];
    level.render = std::move(pyramid[l]);
    if (rows == nullptr) {
      level.rows = LevelRows();
      continue;
    }
    if (l > 0) level_rows = DownsampleRows(levels_[v][l - 1]->rows, options_.pyramid_filter);
    level.rows = std::move(level_rows);
  }
  if (non_finite_ > 0) finite_ = false;
  pyramid_seconds_ += Seconds(start);
}

namespace {

// Σ over the active pixels and RGB of (render − target)² (times the pixel weights w_lp when
// `weighted`), and the count of terms.
void SquaredError(const LevelCache& level, const std::vector<uint8_t>& active, bool weighted,
                  double* sum, int64_t* count) {
  *sum = 0.0;
  *count = 0;
  for (int y = 0; y < level.render.height; ++y) {
    for (int x = 0; x < level.render.width; ++x) {
      const size_t p = static_cast<size_t>(y) * level.render.width + x;
      if (!active[p]) continue;
      const double w =
          weighted && !level.pixel_sqrt_weight.empty()
              ? static_cast<double>(level.pixel_sqrt_weight[p]) * level.pixel_sqrt_weight[p]
              : 1.0;
      for (int c = 0; c < 3; ++c) {
        const double r = level.render.at(x, y, c) - level.target.at(x, y, c);
        *sum += w * r * r;
      }
      *count += 3;
    }
  }
}

}  // namespace

double RenderCache::ViewImageCost(int v) const {
  double cost = 0.0;
  for (int l = 0; l < num_levels(v); ++l) {
    const LevelCache& level = *levels_[v][l];
    double sum = 0.0;
    int64_t count = 0;
    SquaredError(level, targets_[v].active[l], /*weighted=*/true, &sum, &count);
    cost += 0.5 * level.sqrt_weight * level.sqrt_weight * sum;
  }
  return cost;
}

Eigen::Vector3d RenderCache::GainCurvature(int v) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int l = 0; l < num_levels(v); ++l) {
    const LevelCache& level = *levels_[v][l];
    const std::vector<uint8_t>& active = targets_[v].active[l];
    for (size_t p = 0; p < active.size(); ++p) {
      if (!active[p]) continue;
      const double w =
          level.SqrtWeight(static_cast<int>(p)) * level.SqrtWeight(static_cast<int>(p));
      for (int c = 0; c < 3; ++c) {
        const double t = level.target.data[3 * p + c];
        sum[c] += w * t * t;
      }
    }
  }
  return sum;
}

Eigen::Matrix<double, 6, 1> RenderCache::PoseCurvature(int v,
                                                       const Eigen::Vector3d& object_centre) const {
  const ViewSetup& view = views_->views[view_indices_[v]];
  const Camera camera = DownscaledCamera(view.camera, options_.image_scale_log2);
  const double f = camera.Focal().mean();
  const Eigen::Vector2d principal = camera.Principal();
  double energy = 0.0;         // Σ sw² |∇T|² 4^-l: per squared level-0 pixel of shift.
  double radial_energy = 0.0;  // Σ sw² |∇T|² r_l²: per unit of roll.
  for (int l = 0; l < num_levels(v); ++l) {
    const LevelCache& level = *levels_[v][l];
    const std::vector<uint8_t>& active = targets_[v].active[l];
    const int w = level.target.width, h = level.target.height;
    const double level_scale = std::ldexp(1.0, -2 * l);  // 4^-l: level pixels per level-0 pixel.
    // The principal point in level-l pixel indices (pixel x's centre is at x + 0.5 in image
    // coordinates, and a level-l pixel covers 2^l level-0 pixels).
    const Eigen::Vector2d c_l = principal / std::ldexp(1.0, l) - Eigen::Vector2d::Constant(0.5);
    for (int y = 1; y + 1 < h; ++y) {
      for (int x = 1; x + 1 < w; ++x) {
        const int p = y * w + x;
        if (!active[p] || !active[p - 1] || !active[p + 1] || !active[p - w] || !active[p + w]) {
          continue;
        }
        double g2 = 0.0;
        for (int c = 0; c < 3; ++c) {
          const double gx = 0.5 * (level.target.at(x + 1, y, c) - level.target.at(x - 1, y, c));
          const double gy = 0.5 * (level.target.at(x, y + 1, c) - level.target.at(x, y - 1, c));
          g2 += gx * gx + gy * gy;
        }
        const double sw = level.SqrtWeight(p);
        energy += sw * sw * g2 * level_scale;
        radial_energy += sw * sw * g2 * (Eigen::Vector2d(x, y) - c_l).squaredNorm();
      }
    }
  }
  const double z2 = std::pow(std::max((view.cam_from_world * object_centre).z(), 1e-9), 2);
  const double pan = energy * f * f;
  Eigen::Matrix<double, 6, 1> curvature;
  curvature << pan, pan, radial_energy, pan / z2, pan / z2, radial_energy / z2;
  return curvature;
}

double RenderCache::ImageCost() const {
  double cost = 0.0;
  for (int v = 0; v < num_views(); ++v) cost += ViewImageCost(v);
  return cost;
}

std::vector<double> RenderCache::ViewMse() const {
  std::vector<double> mse(num_views(), 0.0);
  for (int v = 0; v < num_views(); ++v) {
    double sum = 0.0;
    int64_t count = 0;
    SquaredError(*levels_[v][0], targets_[v].active[0], /*weighted=*/false, &sum, &count);
    mse[v] = count > 0 ? sum / count : 0.0;
  }
  return mse;
}

size_t RenderCache::RowMemoryBytes() const {
  size_t bytes = 0;
  for (const auto& view : levels_) {
    for (const auto& level : view) bytes += level->rows.MemoryBytes();
  }
  return bytes;
}

Image RenderCache::AdjointWeights(int v) const {
  Image acc;
  for (int l = num_levels(v) - 1; l >= 0; --l) {
    const LevelCache& level = *levels_[v][l];
    if (!acc.empty()) {
      acc = DownsampleMeanAdjoint(acc, level.render.width, level.render.height,
                                  options_.pyramid_filter);
    }
    if (acc.empty()) acc = Image(level.render.width, level.render.height, 3);
    const std::vector<uint8_t>& active = targets_[v].active[l];
    for (int y = 0; y < level.render.height; ++y) {
      for (int x = 0; x < level.render.width; ++x) {
        const int p = y * level.render.width + x;
        if (!active[p]) continue;
        const double sqrt_w = level.SqrtWeight(p);
        const double w = sqrt_w * sqrt_w;
        for (int c = 0; c < 3; ++c) {
          acc.at(x, y, c) +=
              static_cast<float>(w * (level.render.at(x, y, c) - level.target.at(x, y, c)));
        }
      }
    }
  }
  return acc;
}

namespace {

// The seed of the adjoint pass at render seed `seed`: any fixed odd multiplier gives a seed stream
// disjoint in practice from the renders' seeds.
uint64_t AdjointSeed(uint64_t seed, bool independent) {
  return independent ? seed * 0xd1342543de82ef95ull + 1ull : seed;
}

// The residual is of g ⊙ I: the renderer's Jᵀw needs the weights times the gains.
Image GainedWeights(const Image& weights, const Eigen::Vector3d& gain) {
  if (gain == Eigen::Vector3d::Ones()) return weights;
  Image gained = ToRgb(weights);
  ApplyGains(gain, &gained);
  return gained;
}

}  // namespace

bool RenderCache::AddAdjointGradient(int v, const Image& weights, std::vector<double>* gradient) {
  return AddAdjointGradientWith(v, weights, plan(),
                                AdjointSeed(seed_, options_.independent_gradient), gradient);
}

bool RenderCache::AddAdjointGradients(const std::vector<int>& views,
                                      std::vector<double>* gradient) {
  std::vector<Image> weights(views.size());
  for (size_t k = 0; k < views.size(); ++k) weights[k] = AdjointWeights(views[k]);
  return RunAdjointJobs(views, weights, options_.render, ActiveRequest(),
                        AdjointSeed(seed_, options_.independent_gradient), gradient);
}

bool RenderCache::AddAdjointGradientWith(int v, const Image& weights, const EffectPlan& plan,
                                         uint64_t seed, std::vector<double>* gradient) {
  return AddAdjointGradientsWith({v}, {weights}, plan, seed, gradient);
}

bool RenderCache::AddAdjointGradientsWith(const std::vector<int>& views,
                                          const std::vector<Image>& weights, const EffectPlan& plan,
                                          uint64_t seed, std::vector<double>* gradient,
                                          GradientParts* parts) {
  RenderOptions render = options_.render;
  DerivativeRequest request = ActiveRequest();
  plan.ApplyTo(&render, &request);
  request.gradient_parts = parts != nullptr;
  return RunAdjointJobs(views, weights, render, request, seed, gradient, parts);
}

bool RenderCache::RunAdjointJobs(const std::vector<int>& views, const std::vector<Image>& weights,
                                 const RenderOptions& render, const DerivativeRequest& request,
                                 uint64_t seed, std::vector<double>* gradient,
                                 GradientParts* parts) {
  CHECK_EQ(views.size(), weights.size());
  RenderOptions adjoint = render;  // gradient_specular: the lobe out of the adjoint pass only.
  adjoint.effects.specular = render.effects.specular && options_.gradient_specular;
  std::vector<ViewJob> jobs(views.size());
  for (size_t k = 0; k < views.size(); ++k) {
    jobs[k].view = views[k];
    jobs[k].pass = ViewPass::kAdjoint;
    jobs[k].seed = seed;
    jobs[k].weights = GainedWeights(weights[k], params_->Gains(views[k]));
  }
  bool finite = true;
  RunJobs(jobs, adjoint, request, [&](size_t k, ViewResult* result) {
    finite = AddGradientResult(views[k], weights[k], *result, gradient, parts) && finite;
  });
  return finite;
}

bool RenderCache::AddGradientResult(int v, const Image& weights, const ViewResult& result,
                                    std::vector<double>* gradient, GradientParts* parts) const {
  const ParameterLayout& layout = params_->layout();
  bool finite = result.non_finite == 0;
  for (int i = 0; i < layout.size(); ++i) {
    const bool light = layout.KindOf(i) == ParameterKind::kLight;
    // The renderer's entry at light scale 1·s_l, as the derivative at the fitted scale.
    const auto unscaled = [&](double g) {
      return light ? g / params_->LightScale(i - layout.LightOffset()) : g;
    };
    const double g = unscaled(result.gradient[i]);
    finite = finite && std::isfinite(g);
    (*gradient)[i] += g;
    if (parts == nullptr) continue;
    for (int t = 0; t < kNumDerivativeTerms; ++t) {
      parts->parts[t][i] += unscaled(result.gradient_parts.parts[t][i]);
    }
  }
  if (FitsPose(v)) {
    const PoseDelta g = ChainOf(v).Contract(result.gradient);
    for (int k = 0; k < 6; ++k) {
      finite = finite && std::isfinite(g[k]);
      (*gradient)[params_->PoseIndex(v, k)] += g[k];
      if (parts != nullptr) parts->part(DerivativeTerm::kRest)[params_->PoseIndex(v, k)] += g[k];
    }
  }
  if (active_.exposure && params_->GainFitted(v)) {
    // ∂/∂g_c Σ_p w_pc g_c I_pc = Σ_p w_pc I_pc, with I this pass's own (ungained) render, so that
    // with independent_gradient the gains' gradient is as independent of the residual as the rest.
    const Image rgb = ToRgb(result.image);
    const Image w = ToRgb(weights);
    double sum[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < rgb.data.size(); ++i) {
      sum[i % 3] += static_cast<double>(w.data[i]) * rgb.data[i];
    }
    for (int c = 0; c < 3; ++c) {
      finite = finite && std::isfinite(sum[c]);
      (*gradient)[params_->GainIndex(v, c)] += sum[c];
      if (parts != nullptr) parts->part(DerivativeTerm::kRest)[params_->GainIndex(v, c)] += sum[c];
    }
  }
  return finite;
}

bool RenderCache::RenderWith(int v, const EffectPlan& plan, uint64_t seed, Image* image) {
  std::vector<Image> images;
  const bool finite = RenderWith(std::vector<int>{v}, plan, seed, &images);
  *image = std::move(images[0]);
  return finite;
}

bool RenderCache::RenderWith(const std::vector<int>& views, const EffectPlan& plan, uint64_t seed,
                             std::vector<Image>* images) {
  RenderOptions render = options_.render;
  DerivativeRequest request = ActiveRequest();  // not used by image jobs.
  plan.ApplyTo(&render, &request);
  std::vector<ViewJob> jobs(views.size());
  for (size_t k = 0; k < views.size(); ++k) {
    jobs[k].view = views[k];
    jobs[k].seed = seed;
  }
  images->assign(views.size(), Image());
  bool finite = true;
  RunJobs(jobs, render, request, [&](size_t k, ViewResult* result) {
    finite = finite && result->non_finite == 0;
    Image& image = (*images)[k];
    image = ToRgb(result->image);
    const Eigen::Vector3d gain = params_->Gains(views[k]);
    if (gain != Eigen::Vector3d::Ones()) ApplyGains(gain, &image);
  });
  return finite;
}

}  // namespace sft
