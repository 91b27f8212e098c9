// The solvers over one objective (docs/reconstruct.md): ½ Σ r² of the pyramid pixel residuals of
// every view (plus regularizers), minimised over the active parameter kinds within the feasible
// set.
//   lm, dogleg  Ceres trust region over the ReconstructionProblem (Jacobian rows from the render
//               cache; bounds as Ceres parameter bounds). Linear solver CGNR + Jacobi with capped
//               iterations by default; sparse normal Cholesky or dense QR for small problems.
//   lbfgs       Ceres line search (GradientProblemSolver) over an AdjointObjective: each
//               evaluation renders every view forward, then again with the adjoint gradient
//               Jᵀr (same seed, so the same image), storing no Jacobian. Bounds by projection:
//               the objective is evaluated at the projection P(x) of the iterate, with the
//               gradient components that push through an active bound set to zero.
//   adam        Adam (Kingma & Ba 2015) on the same adjoint gradient, projected onto the bounds
//               after every step; the baseline of first-order inverse renderers.
// One call runs one outer iteration of one phase: a fixed seed (common random numbers) and at most
// `steps` iterations.
#ifndef SFT_OPTIM_SOLVERS_H_
#define SFT_OPTIM_SOLVERS_H_

#include <ceres/ceres.h>

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "src/optim/parameters.h"
#include "src/optim/problem.h"
#include "src/optim/render_cache.h"

namespace sft {

enum class SolverKind { kLevenbergMarquardt, kDogleg, kLbfgs, kAdam };
bool SolverKindFromName(const std::string& name, SolverKind* kind);
const char* SolverKindName(SolverKind kind);

struct AdamOptions {
  double learning_rate_vertices = 1e-3;  // step size of vertex coordinates, scene units, > 0.
  double learning_rate_material = 2e-2;  // step size of texels, specular, light scales, > 0.
  double beta1 = 0.9;                    // first-moment decay, [0, 1).
  double beta2 = 0.999;                  // second-moment decay, [0, 1).
  double epsilon = 1e-8;                 // denominator guard, > 0.
  // λ of the large-steps reparameterisation of the vertices (src/optim/large_steps.h): Adam moves
  // u = (I + λL)x. 0 = plain Adam on the positions; [0, 1e4]. Nicolet et al. use 19–49.
  double large_steps_lambda = 0.0;
  // The vertices' second moment is the largest over all vertex coordinates (Nicolet et al.'s
  // "uniform" Adam: one step length for the whole surface, so the smoothing of large steps is not
  // undone by per-coordinate scaling). Other kinds keep per-parameter moments.
  bool uniform_vertices = false;
  // A new seed at every step (stochastic gradients whose noise averages out over the steps)
  // instead of one seed per outer iteration (common random numbers).
  bool resample = false;
  // Views rendered per step (a minibatch, cycling through a fixed shuffled order of the fitted
  // views; the image part of the cost and gradient is scaled by views / batch); 0 = all views.
  int views_per_step = 0;
  // Tail averaging (Polyak and Juditsky 1992): the run ends at the mean of the iterates of its
  // last `average_tail` fraction of steps instead of at the last iterate, which removes most of
  // the gradient noise that a constant step size leaves; [0, 1), 0 = the last iterate.
  double average_tail = 0.0;
};

struct SolverOptions {
  SolverKind kind = SolverKind::kLevenbergMarquardt;
  int steps = 5;  // iterations per outer iteration and phase, [1, 1000].
  // Trust-region options (lm, dogleg). Defaults set by the constructor: CGNR + Jacobi, at most
  // 20 CG iterations, initial trust-region radius 10, 2 threads. The minimizer and strategy follow
  // `kind`; max_num_iterations follows `steps`.
  ceres::Solver::Options trust_region;
  // Line-search options (lbfgs); max_num_iterations follows `steps`.
  ceres::GradientProblemSolver::Options line_search;
  AdamOptions adam;

  SolverOptions();
  bool Check(std::string* why) const;
};

// What one iteration reports.
struct IterationInfo {
  int iteration = 0;      // within the call.
  double cost = 0.0;      // objective after the iteration (of the accepted point).
  bool accepted = false;  // the step was taken.
  // Not a step: Adam's closing evaluation of every view at the point it ends at (its step
  // records carry minibatch estimates at the points before their steps).
  bool full = false;
};

// Hooks of a run: `on_iteration` after every iteration (return false to stop early, e.g. on
// Ctrl-C); `add_regularizers` adds regularizer residual blocks for the active kinds to a problem
// whose parameter blocks point into the SceneParameters.
struct SolverHooks {
  std::function<bool(const IterationInfo&)> on_iteration;
  std::function<void(ceres::Problem*)> add_regularizers;
};

// Where one call's wall time went, in seconds (`sft bench reconstruct`). The parts add up to
// SolverRunStats::seconds; `other` is the remainder (minimizer bookkeeping, trust-region or line
// search logic, callbacks).
struct SolverTimeSplit {
  double superset_renders = 0.0;  // the problem build's superset renders (trust region).
  double problem_assembly = 0.0;  // the rest of the problem build: blocks, bounds, regularizers.
  double solve_startup = 0.0;     // Ceres' preprocessor (program, evaluator, linear solver setup).
  double render = 0.0;            // renders in the evaluations (forward + rows, or adjoint).
  double pyramid = 0.0;           // pyramid levels of images and rows.
  double evaluation = 0.0;        // the rest of the evaluations: rows copied into Ceres' Jacobian
                                  // in double, regularizers, gradients.
  double linear_solver = 0.0;     // the trust-region step's linear solve (CGNR, Cholesky, QR).
  double other = 0.0;             // the remainder.
};

// The split's parts in report order with their names ("superset_renders", ..., "other").
std::vector<std::pair<const char*, double>> TimeSplitParts(const SolverTimeSplit& time);

// Counters of one call, for the report.
struct SolverRunStats {
  int iterations = 0;
  int evaluations = 0;  // renders of every view at new points (function evaluations).
  double seconds = 0.0;
  double setup_seconds = 0.0;  // problem build (supersets included), trust region only.
  SolverTimeSplit time;
  double dropped_jacobian_fraction = 0.0;  // trust region: at the last linearization.
  ProblemStats problem;
  std::string termination;  // Ceres' message or "steps".
};

// The objective evaluated by adjoint renders over the active parameters (lbfgs, adam).
class AdjointObjective : public ceres::FirstOrderFunction {
 public:
  AdjointObjective(RenderCache* cache, SceneParameters* params, const ParameterBounds& bounds,
                   ceres::Problem* regularizers);
  bool Evaluate(const double* x, double* cost, double* gradient) const override;
  // Like Evaluate over the cache views `views` only (a minibatch): the image part of the cost and
  // gradient is scaled by num_views / views.size(), so that it estimates the full objective.
  // All views when `views` is empty.
  bool EvaluateViews(const double* x, const std::vector<int>& views, double* cost,
                     double* gradient) const;
  int NumParameters() const override { return static_cast<int>(active_.size()); }
  // The active parameters' current values (from the SceneParameters).
  std::vector<double> Current() const;
  // Flat indices of the active parameters, increasing (x[k] is parameter active_indices()[k]).
  const std::vector<int>& active_indices() const { return active_; }
  // Projects `x` and writes it into the SceneParameters.
  void Store(const double* x) const;

 private:
  RenderCache* cache_;
  SceneParameters* params_;
  ParameterBounds bounds_;
  ceres::Problem* regularizers_;  // may be null or empty.
  std::vector<int> active_;       // flat indices of the active parameters.
};

// Runs one outer iteration of one phase (the cache's active kinds and seed are set by the caller).
Status RunSolver(const SolverOptions& options, const ProblemOptions& problem_options,
                 RenderCache* cache, SceneParameters* params, const SolverHooks& hooks,
                 SolverRunStats* stats);

// Adam's moments, kept across outer iterations (indexed like the flat parameter vector).
// With large steps the vertices' moments are of u = (I + λL)x; they restart when λ changes, and
// all moments restart when the layout's size changes (a topology change).
struct AdamState {
  std::vector<double> m, v;
  int64_t t = 0;
  double lambda = 0.0;  // the large-steps λ the vertex moments belong to.
};
// `vertex_neighbours` (VertexNeighbours of the current mesh) is needed when vertices are active
// and options.adam.large_steps_lambda > 0; otherwise it may be empty.
Status RunAdam(const SolverOptions& options, const ProblemOptions& problem_options,
               RenderCache* cache, SceneParameters* params, const SolverHooks& hooks,
               const std::vector<std::vector<int>>& vertex_neighbours, AdamState* state,
               SolverRunStats* stats);

}  // namespace sft

#endif  // SFT_OPTIM_SOLVERS_H_
