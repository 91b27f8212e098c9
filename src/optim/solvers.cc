#include "src/optim/solvers.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "src/optim/large_steps.h"

namespace sft {
namespace {

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The render cache's cumulative clocks at one moment; the difference of two is what a stretch of
// the run spent rendering.
struct CacheClock {
  explicit CacheClock(const RenderCache& cache)
      : render(cache.render_seconds()),
        pyramid(cache.pyramid_seconds()),
        renders(cache.renders()),
        views(std::max(1, cache.num_views())) {}
  // Adds the render and pyramid time since `start` to *time and the evaluations to *evaluations.
  void AddSince(const CacheClock& start, SolverTimeSplit* time, int* evaluations) const {
    time->render += render - start.render;
    time->pyramid += pyramid - start.pyramid;
    *evaluations += static_cast<int>((renders - start.renders) / views);
  }
  double render, pyramid;
  int64_t renders;
  int views;
};

// Sets the remainder of the split so that the parts add up to the call's wall time.
void FinishTimeSplit(SolverRunStats* stats) {
  stats->time.other = 0.0;
  double parts = 0.0;
  for (const auto& part : TimeSplitParts(stats->time)) parts += part.second;
  stats->time.other = std::max(0.0, stats->seconds - parts);
}

// Forwards Ceres iterations to the hooks. Ceres reports a rejected step with the cost of the
// rejected trial point; the hooks get the cost of the point the solver stands on.
class HookCallback : public ceres::IterationCallback {
 public:
  explicit HookCallback(const SolverHooks& hooks) : hooks_(hooks) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration == 0 || summary.step_is_successful) accepted_cost_ = summary.cost;
    if (summary.iteration == 0 || !hooks_.on_iteration) return ceres::SOLVER_CONTINUE;
    IterationInfo info;
    info.iteration = summary.iteration;
    info.cost = accepted_cost_;
    info.accepted = summary.step_is_successful;
    return hooks_.on_iteration(info) ? ceres::SOLVER_CONTINUE
                                     : ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }

 private:
  const SolverHooks& hooks_;
  double accepted_cost_ = 0.0;
};

// The regularizers alone, for the adjoint objective.
std::unique_ptr<ceres::Problem> RegularizerProblem(const SolverHooks& hooks) {
  ceres::Problem::Options options;
  auto problem = std::make_unique<ceres::Problem>(options);
  if (hooks.add_regularizers) hooks.add_regularizers(problem.get());
  return problem;
}

// The Ceres options of a trust-region run: the strategy follows the kind; dogleg needs an exact
// factorization, so the default CGNR becomes sparse normal Cholesky for it (small problems only).
ceres::Solver::Options TrustRegionOptions(const SolverOptions& options) {
  ceres::Solver::Options tr = options.trust_region;
  tr.minimizer_type = ceres::TRUST_REGION;
  tr.trust_region_strategy_type =
      options.kind == SolverKind::kDogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
  if (options.kind == SolverKind::kDogleg && tr.linear_solver_type == ceres::CGNR) {
    tr.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  }
  tr.max_num_iterations = options.steps;
  return tr;
}

}  // namespace

std::vector<std::pair<const char*, double>> TimeSplitParts(const SolverTimeSplit& t) {
  return {{"superset_renders", t.superset_renders},
          {"problem_assembly", t.problem_assembly},
          {"solve_startup", t.solve_startup},
          {"render", t.render},
          {"pyramid", t.pyramid},
          {"evaluation", t.evaluation},
          {"linear_solver", t.linear_solver},
          {"other", t.other}};
}

bool SolverKindFromName(const std::string& name, SolverKind* kind) {
  if (name == "lm") {
    *kind = SolverKind::kLevenbergMarquardt;
  } else if (name == "dogleg") {
    *kind = SolverKind::kDogleg;
  } else if (name == "lbfgs") {
    *kind = SolverKind::kLbfgs;
  } else if (name == "adam") {
    *kind = SolverKind::kAdam;
  } else {
    return false;
  }
  return true;
}

const char* SolverKindName(SolverKind kind) {
  switch (kind) {
    case SolverKind::kLevenbergMarquardt:
      return "lm";
    case SolverKind::kDogleg:
      return "dogleg";
    case SolverKind::kLbfgs:
      return "lbfgs";
    case SolverKind::kAdam:
      return "adam";
  }
  return "?";
}

SolverOptions::SolverOptions() {
  trust_region.linear_solver_type = ceres::CGNR;
  trust_region.preconditioner_type = ceres::JACOBI;
  trust_region.max_linear_solver_iterations = 20;
  // Ceres' default (1e4) starts close to Gauss–Newton; with Monte Carlo Jacobians and the fold
  // barrier that first step folds faces and is rejected several times over. 10 measured best
  // of 1e4 and 10 on the 32-view bunny (docs/design-notes.md).
  trust_region.initial_trust_region_radius = 10.0;
  trust_region.num_threads = 2;
  trust_region.logging_type = ceres::SILENT;
  line_search.line_search_direction_type = ceres::LBFGS;
  line_search.logging_type = ceres::SILENT;
}

bool SolverOptions::Check(std::string* why) const {
  if (steps < 1 || steps > 1000) {
    *why = "steps: must be in [1, 1000]";
    return false;
  }
  const ceres::Solver::Options tr = TrustRegionOptions(*this);
  std::string error;
  if (kind != SolverKind::kLbfgs && kind != SolverKind::kAdam && !tr.IsValid(&error)) {
    *why = "solver: " + error;
    return false;
  }
  if (kind == SolverKind::kLbfgs && !line_search.IsValid(&error)) {
    *why = "solver: " + error;
    return false;
  }
  const AdamOptions& a = adam;
  if (!(a.learning_rate_vertices > 0 && a.learning_rate_material > 0 && a.beta1 >= 0 &&
        a.beta1 < 1 && a.beta2 >= 0 && a.beta2 < 1 && a.epsilon > 0)) {
    *why = "adam: learning rates and epsilon must be > 0, beta1 and beta2 in [0, 1)";
    return false;
  }
  if (!(a.large_steps_lambda >= 0 && a.large_steps_lambda <= 1e4)) {
    *why = "adam_large_steps: must be in [0, 10000]";
    return false;
  }
  if (a.views_per_step < 0) {
    *why = "adam_views_per_step: must be >= 0";
    return false;
  }
  if (!(a.average_tail >= 0 && a.average_tail < 1)) {
    *why = "adam_average: must be in [0, 1)";
    return false;
  }
  return true;
}

AdjointObjective::AdjointObjective(RenderCache* cache, SceneParameters* params,
                                   const ParameterBounds& bounds, ceres::Problem* regularizers)
    : cache_(cache), params_(params), bounds_(bounds), regularizers_(regularizers) {
  const ParameterLayout& layout = params->layout();
  for (int i = 0; i < layout.size(); ++i) {
    if (cache->active().Includes(layout.KindOf(i))) active_.push_back(i);
  }
  if (cache->active().exposure) {
    for (int v = 0; v < params->num_gain_views(); ++v) {
      if (!params->GainFitted(v)) continue;
      for (int c = 0; c < 3; ++c) active_.push_back(params->GainIndex(v, c));
    }
  }
  if (cache->active().poses) {
    for (int v = 0; v < params->num_pose_views(); ++v) {
      if (!params->PoseFitted(v)) continue;
      for (int k = 0; k < 6; ++k) active_.push_back(params->PoseIndex(v, k));
    }
  }
}

std::vector<double> AdjointObjective::Current() const {
  std::vector<double> x(active_.size());
  for (size_t k = 0; k < active_.size(); ++k) x[k] = params_->values()[active_[k]];
  return x;
}

void AdjointObjective::Store(const double* x) const {
  for (size_t k = 0; k < active_.size(); ++k) {
    const int i = active_[k];
    params_->values()[i] = std::clamp(x[k], params_->Lower(i, bounds_), params_->Upper(i, bounds_));
  }
}

bool AdjointObjective::Evaluate(const double* x, double* cost, double* gradient) const {
  return EvaluateViews(x, {}, cost, gradient);
}

bool AdjointObjective::EvaluateViews(const double* x, const std::vector<int>& views, double* cost,
                                     double* gradient) const {
  Store(x);
  std::vector<int> batch = views;
  if (batch.empty()) {
    cache_->Render(/*rows=*/false);
    if (!*cache_->finite()) return false;
    for (int v = 0; v < cache_->num_views(); ++v) batch.push_back(v);
  } else if (!cache_->RenderSome(batch)) {
    return false;
  }
  const double scale = static_cast<double>(cache_->num_views()) / batch.size();
  *cost = 0.0;
  for (int v : batch) *cost += scale * cache_->ViewImageCost(v);
  std::vector<double> full;
  if (gradient != nullptr) {
    full.assign(params_->size(), 0.0);
    // Summed in view order, wherever the views were rendered (view_jobs.h).
    if (!cache_->AddAdjointGradients(batch, &full)) return false;
    if (scale != 1.0) {
      for (double& g : full) g *= scale;
    }
  }
  if (regularizers_ != nullptr && regularizers_->NumResidualBlocks() > 0) {
    std::vector<double*> blocks;
    regularizers_->GetParameterBlocks(&blocks);
    ceres::Problem::EvaluateOptions options;
    options.parameter_blocks = blocks;
    double reg_cost = 0.0;
    std::vector<double> reg_gradient;
    if (!regularizers_->Evaluate(options, &reg_cost, nullptr,
                                 gradient != nullptr ? &reg_gradient : nullptr, nullptr)) {
      return false;
    }
    *cost += reg_cost;
    if (gradient != nullptr) {
      size_t k = 0;
      for (double* block : blocks) {
        const int offset = static_cast<int>(block - params_->data());
        const int size = regularizers_->ParameterBlockSize(block);
        for (int i = 0; i < size; ++i) full[offset + i] += reg_gradient[k++];
      }
    }
  }
  if (!std::isfinite(*cost)) return false;
  if (gradient != nullptr) {
    for (size_t k = 0; k < active_.size(); ++k) {
      const int i = active_[k];
      double g = full[i];
      const double value = params_->values()[i];
      // Projected gradient: no descent direction through an active bound.
      if ((value <= params_->Lower(i, bounds_) && g > 0) ||
          (value >= params_->Upper(i, bounds_) && g < 0)) {
        g = 0.0;
      }
      gradient[k] = g;
    }
  }
  return true;
}

Status RunSolver(const SolverOptions& options, const ProblemOptions& problem_options,
                 RenderCache* cache, SceneParameters* params, const SolverHooks& hooks,
                 SolverRunStats* stats) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  const auto start = std::chrono::steady_clock::now();
  HookCallback callback(hooks);
  if (options.kind == SolverKind::kLbfgs) {
    std::unique_ptr<ceres::Problem> regularizers = RegularizerProblem(hooks);
    auto* objective =
        new AdjointObjective(cache, params, problem_options.bounds, regularizers.get());
    std::vector<double> x = objective->Current();
    ceres::GradientProblem problem(objective);  // takes ownership.
    ceres::GradientProblemSolver::Options solver = options.line_search;
    solver.max_num_iterations = options.steps;
    solver.callbacks.push_back(&callback);
    ceres::GradientProblemSolver::Summary summary;
    const CacheClock before(*cache);
    ceres::Solve(solver, problem, x.data(), &summary);
    objective->Store(x.data());
    stats->iterations = static_cast<int>(summary.iterations.size()) - 1;
    stats->termination = summary.message;
    CacheClock(*cache).AddSince(before, &stats->time, &stats->evaluations);
    stats->time.evaluation = std::max(0.0, summary.cost_evaluation_time_in_seconds +
                                               summary.gradient_evaluation_time_in_seconds -
                                               stats->time.render - stats->time.pyramid);
  } else {
    std::unique_ptr<ReconstructionProblem> problem;
    const CacheClock before_build(*cache);
    SFT_RETURN_IF_ERROR(ReconstructionProblem::Build(cache, params, problem_options, &problem));
    if (hooks.add_regularizers) hooks.add_regularizers(problem->problem());
    stats->problem = problem->stats();
    SolverTimeSplit build;
    int superset_renders = 0;
    CacheClock(*cache).AddSince(before_build, &build, &superset_renders);
    stats->time.superset_renders = build.render + build.pyramid;
    stats->time.problem_assembly = std::max(0.0, Since(start) - stats->time.superset_renders);
    stats->setup_seconds = Since(start);
    ceres::Solver::Options solver = TrustRegionOptions(options);
    solver.callbacks.push_back(&callback);
    ceres::Solver::Summary summary;
    const CacheClock before(*cache);
    ceres::Solve(solver, problem->problem(), &summary);
    stats->iterations = static_cast<int>(summary.iterations.size()) - 1;
    stats->termination = summary.message;
    CacheClock(*cache).AddSince(before, &stats->time, &stats->evaluations);
    stats->time.solve_startup = summary.preprocessor_time_in_seconds;
    stats->time.linear_solver = summary.linear_solver_time_in_seconds;
    stats->time.evaluation = std::max(0.0, summary.residual_evaluation_time_in_seconds +
                                               summary.jacobian_evaluation_time_in_seconds -
                                               stats->time.render - stats->time.pyramid);
    stats->dropped_jacobian_fraction = problem->DroppedJacobianFraction(*cache);
  }
  stats->seconds = Since(start);
  FinishTimeSplit(stats);
  return Status::Ok();
}

namespace {

// The views 0 .. num_views − 1 in an order shuffled by `seed`.
std::vector<int> ShuffledViews(int num_views, uint64_t seed) {
  std::vector<int> order(num_views);
  for (int v = 0; v < num_views; ++v) order[v] = v;
  std::mt19937_64 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  return order;
}

// The minibatch of Adam step t (1-based): `per_step` views of `order`, consecutive batches taking
// consecutive slices (wrapping around). All views (empty) when per_step is 0 or not below the
// view count.
std::vector<int> AdamBatch(const std::vector<int>& order, int per_step, int64_t t) {
  const int num_views = static_cast<int>(order.size());
  if (per_step <= 0 || per_step >= num_views) return {};
  std::vector<int> batch;
  for (int k = 0; k < per_step; ++k) {
    batch.push_back(order[static_cast<size_t>(((t - 1) * per_step + k) % num_views)]);
  }
  std::sort(batch.begin(), batch.end());
  return batch;
}

// One Adam update of the active parameters x (moments in `state`, indexed by flat index) for the
// gradient `g`; with large steps the first `vertex_count` entries of x and g are replaced by u and
// its gradient by the caller. `uniform_count` leading entries share one second moment (their
// largest).
void AdamUpdate(const AdamOptions& adam, const SceneParameters& params,
                const std::vector<int>& index, const std::vector<double>& g, int uniform_count,
                AdamState* state, std::vector<double>* x) {
  ++state->t;
  const double c1 = 1.0 - std::pow(adam.beta1, static_cast<double>(state->t));
  const double c2 = 1.0 - std::pow(adam.beta2, static_cast<double>(state->t));
  double uniform_v = 0.0;
  for (size_t k = 0; k < g.size(); ++k) {
    const int i = index[k];
    state->m[i] = adam.beta1 * state->m[i] + (1.0 - adam.beta1) * g[k];
    state->v[i] = adam.beta2 * state->v[i] + (1.0 - adam.beta2) * g[k] * g[k];
    if (static_cast<int>(k) < uniform_count) uniform_v = std::max(uniform_v, state->v[i]);
  }
  for (size_t k = 0; k < g.size(); ++k) {
    const int i = index[k];
    const double v = static_cast<int>(k) < uniform_count ? uniform_v : state->v[i];
    const bool vertex =
        !params.IsExposure(i) && params.layout().KindOf(i) == ParameterKind::kVertex;
    const double lr = vertex ? adam.learning_rate_vertices : adam.learning_rate_material;
    (*x)[k] -= lr * (state->m[i] / c1) / (std::sqrt(v / c2) + adam.epsilon);
  }
}

// Sizes the moments for `size` parameters (all restart when the size changes: a topology
// change). Vertex moments of x and of u = (I + λL)x are not interchangeable: they restart (only
// they, so that a texture phase between two geometry phases keeps its own) when λ changes.
void PrepareAdamState(size_t size, int vertex_count, double lambda, AdamState* state) {
  if (state->m.size() != size) {
    state->m.assign(size, 0.0);
    state->v.assign(size, 0.0);
    state->t = 0;
  }
  if (vertex_count > 0 && state->lambda != lambda) {
    std::fill(state->m.begin(), state->m.begin() + vertex_count, 0.0);
    std::fill(state->v.begin(), state->v.begin() + vertex_count, 0.0);
    state->lambda = lambda;
  }
}

}  // namespace

Status RunAdam(const SolverOptions& options, const ProblemOptions& problem_options,
               RenderCache* cache, SceneParameters* params, const SolverHooks& hooks,
               const std::vector<std::vector<int>>& vertex_neighbours, AdamState* state,
               SolverRunStats* stats) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  const auto start = std::chrono::steady_clock::now();
  const AdamOptions& adam = options.adam;
  std::unique_ptr<ceres::Problem> regularizers = RegularizerProblem(hooks);
  AdjointObjective objective(cache, params, problem_options.bounds, regularizers.get());
  const int n = objective.NumParameters();
  const int num_vertices = params->layout().num_vertices;
  // Active parameters are in increasing flat order, so active vertices are the first 3V.
  const int vertex_count = cache->active().vertices ? 3 * num_vertices : 0;
  std::unique_ptr<LargeSteps> large_steps;
  if (vertex_count > 0 && adam.large_steps_lambda > 0) {
    if (static_cast<int>(vertex_neighbours.size()) != num_vertices) {
      return Status::Error("adam: large steps need the mesh's vertex neighbours");
    }
    SFT_RETURN_IF_ERROR(
        LargeSteps::Create(vertex_neighbours, adam.large_steps_lambda, &large_steps));
  }
  PrepareAdamState(params->size(), vertex_count, large_steps ? adam.large_steps_lambda : 0.0,
                   state);
  std::vector<double> x = objective.Current(), gradient(n), y(n);
  const std::vector<int>& index = objective.active_indices();
  const int uniform_count = adam.uniform_vertices ? vertex_count : 0;
  const uint64_t base_seed = cache->seed();
  const std::vector<int> order =
      ShuffledViews(cache->num_views(), base_seed ^ 0x2545f4914f6cdd1dull);
  double cost = 0.0;
  stats->termination = "steps";
  // Iterates after step `average_from` are summed for tail averaging.
  const int average_from =
      options.steps - static_cast<int>(std::floor(adam.average_tail * options.steps));
  std::vector<double> sum(average_from < options.steps ? n : 0, 0.0);
  int summed = 0;
  const CacheClock before(*cache);
  for (int step = 1; step <= options.steps; ++step) {
    const int64_t t = state->t + 1;
    if (adam.resample) cache->SetSeed(base_seed + 0x9e3779b97f4a7c15ull * static_cast<uint64_t>(t));
    const std::vector<int> batch = AdamBatch(order, adam.views_per_step, t);
    if (!objective.EvaluateViews(x.data(), batch, &cost, gradient.data())) {
      stats->termination = "non-finite render";
      break;
    }
    // y: the variables Adam moves (u = Mx for the vertices with large steps, x otherwise).
    y = x;
    if (large_steps) {
      large_steps->ToU(x.data(), y.data());
      large_steps->GradientToU(gradient.data(), gradient.data());
    }
    AdamUpdate(adam, *params, index, gradient, uniform_count, state, &y);
    if (large_steps) large_steps->ToX(y.data(), y.data());
    x = y;
    for (int k = 0; k < n; ++k) {
      const int i = index[k];
      x[k] = std::clamp(x[k], params->Lower(i, problem_options.bounds),
                        params->Upper(i, problem_options.bounds));
    }
    objective.Store(x.data());
    stats->iterations = step;
    if (step > average_from) {
      for (int k = 0; k < n; ++k) sum[k] += x[k];
      ++summed;
    }
    // Adam reports the cost at the point where its gradient was taken (before the step).
    if (hooks.on_iteration && !hooks.on_iteration({step, cost, true})) {
      stats->termination = "stopped";
      break;
    }
  }
  if (summed > 0 && stats->termination == "steps") {
    // The mean of iterates within the bounds is within them. A stopped run keeps its last iterate.
    for (int k = 0; k < n; ++k) x[k] = sum[k] / summed;
    objective.Store(x.data());
  }
  // The end point's cost over all views (forward renders only), so that the run's last record
  // is the objective where it ends rather than a minibatch estimate before the last step.
  if (stats->termination == "steps" && options.steps > 0) {
    if (!objective.EvaluateViews(x.data(), {}, &cost, nullptr)) {
      stats->termination = "non-finite render";
    } else if (hooks.on_iteration &&
               !hooks.on_iteration({options.steps, cost, true, /*full=*/true})) {
      stats->termination = "stopped";
    }
  }
  CacheClock(*cache).AddSince(before, &stats->time, &stats->evaluations);
  stats->seconds = Since(start);
  // Adam's evaluations are its whole loop apart from the renders.
  stats->time.evaluation = std::max(0.0, stats->seconds - stats->time.render - stats->time.pyramid);
  FinishTimeSplit(stats);
  return Status::Ok();
}

}  // namespace sft
