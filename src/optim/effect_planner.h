// The effect planner (`"effects": "auto"`, docs/reconstruct.md "The effect planner"): before an
// outer iteration it measures, at the current state and the fit's own spp, what each effect adds
// and switches off what is below the Monte Carlo noise.
//
//   - Image effects (environment, specular, shadows, each bounce beyond the first): the change of
//     the fit's images when the effect is switched off, on up to `views` evenly spaced fitted
//     views at the fit's image scale, over their active pixels.
//   - Derivative terms (primary, shadow, texel and secondary edges), only for a fit with a
//     geometry phase: the change of the vertex gradient of the image term (the steepest-descent
//     direction of the first-order solvers and the large-damping limit of the LM step, which the
//     planner does not solve for), with the image effects already chosen.
//
// The rule: an effect is dropped when switching it off changes the images (or the gradient) by
// less than noise_factor × the seed-to-seed standard deviation of what the stage's fit averages,
// and by less than max_share of the values' own RMS (the largest measured in the stage so far). A
// stage of K outer iterations renders with K independent seeds, so a bias below σ/√K (σ the
// per-value standard deviation at the fit's spp) is hidden by noise the fit still has at its end.
// The share limit keeps what the noise rule alone would drop at high per-value noise although it
// shifts the expected values substantially: the gradient at 16 spp has a per-entry σ about its own
// RMS, while a term that carries a quarter of the expected gradient steers every step
// (docs/design-notes.md, "The effect planner"). All quantities are estimated without the
// noise inflating them: with two seeds s1, s2,
//   change² = mean[(A(s1) − B(s1)) · (A(s2) − B(s2))]   (an unbiased estimate of the squared
//                                                         mean change: the seeds are independent)
//   σ²      = mean[(A(s1) − A(s2))²] / 2                 (the per-value variance of A)
//   signal² = mean[A(s1) · A(s2)]                        (the squared mean values)
// where A is the current plan and B the plan without the effect. A switch whose samples are noisy
// (edge terms) is also dropped when it adds more variance than it removes bias from what the stage
// averages: change² · K ≤ σ_A² − σ_B² (the expected squared error of the stage's average is
// bias² + σ²/K). Finally the change must be distinguishable from 0: change² above two standard
// errors of its own estimate (the mean of n products), else a switch that changes nothing but
// which random numbers a path uses shows a spurious change of a few percent of the signal. Image
// effects are judged on the images first and, when those do not show that the effect matters, on
// the gradient. Decisions are greedy: each effect is measured against the plan with the earlier
// drops applied, so that two effects that are each negligible but not together are not both
// dropped. The bounce count goes down from the configured one while the last bounce does not
// matter.
//
// Derivative terms cost no passes of their own: every gradient pass of the planner returns its
// parts per term (GradientParts), and since each edge term draws its own random numbers, the
// gradient without term T at a seed is the gradient minus T's part from the same pass. The
// derivative terms are therefore measured on the current plan's two reference passes, and after
// a drop the next reference is again that gradient minus the dropped parts.
//
// An effect whose parameters the stage fits is kept (specular when fit_specular: without the
// lobe its weight has no derivative); an effect absent from the scene (no environment light, a
// specular weight of 0 everywhere) is off without a measurement; pins override everything.
#ifndef SFT_OPTIM_EFFECT_PLANNER_H_
#define SFT_OPTIM_EFFECT_PLANNER_H_

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"

namespace sft {

class RenderCache;

// The switches the planner decides, in the order it decides them.
// Image effects: "environment", "specular", "shadows", "bounces" (on = the configured count or
// what the planner keeps of it; off = direct light only). Derivative terms: "primary_edges",
// "shadow_edges", "texel_edges", "secondary_edges".
const std::vector<std::string>& PlannerSwitches();

struct EffectPlannerOptions {
  bool enabled = true;  // "effects": "auto"; false = the effects and budgets as configured.
  // Switches forced on (true) or off (false), by name (PlannerSwitches). Pinning "bounces" on
  // keeps the configured count. Pinning a derivative term on keeps its configured budget.
  std::map<std::string, bool> pins;
  int views = 2;  // fitted views measured (evenly spaced), [1, 1000].
  // Keep an effect whose change exceeds this × the noise of the stage's average, [0, 100].
  double noise_factor = 1.0;
  // Keep an effect whose change exceeds this fraction of the mean values' RMS, [0, 1].
  double max_share = 0.05;

  bool Check(std::string* why) const;
};

// One resolved set of effects and derivative budgets: what every render of an outer iteration
// uses (RenderCache::SetPlan). Built from the configured options, then reduced by the planner.
struct EffectPlan {
  Effects effects;
  int bounces = 2;  // RenderOptions::bounces (path segments), used when effects.bounces.
  double primary_edge_ratio = 0.25;  // DerivativeRequest's budgets; 0 = the term is off.
  double shadow_edge_ratio = 0.125;
  double texel_edge_ratio = 0.125;
  double secondary_edge_samples = 1.0;

  // The configured plan of a render and edge request.
  static EffectPlan From(const RenderOptions& render, const DerivativeRequest& edges);
  // Writes the plan into a render and edge request (other fields unchanged).
  void ApplyTo(RenderOptions* render, DerivativeRequest* edges) const;
  // Whether a switch (PlannerSwitches) is on.
  bool IsOn(const std::string& name) const;
  // The plan with switch `name` off.
  EffectPlan Without(const std::string& name) const;
  // "env spec shadows 2 bounces | primary shadow texel secondary": one console word per switch on.
  std::string Summary() const;
  bool operator==(const EffectPlan& other) const;
};

// One comparison of a plan with and without a switch (the file comment's estimates).
struct EffectMeasurement {
  bool measured = false;
  double change = 0.0;         // RMS change when switched off (radiance, or gradient units).
  double noise = 0.0;          // seed-to-seed standard deviation σ of the same values.
  double threshold = 0.0;      // noise_factor × σ / √K.
  double signal = 0.0;         // RMS of the mean values themselves (the change's share: / signal).
  double share_limit = 0.0;    // max_share × max(signal, the stage's signal scale).
  double noise_without = 0.0;  // σ of the values without the switch.
  int outer_iterations = 1;    // K.
  // Above the noise or too large a share to leave out, and larger than the noise the switch
  // itself adds (the file comment).
  double floor = 0.0;  // changes up to this are not distinguishable from 0 (2 SE).
  bool Matters() const {
    return measured && change > floor && (change > threshold || change > share_limit) &&
           change > AddedNoise();
  }
  // sqrt(max(0, σ² − σ_without²) / K): the noise the switch adds to the stage's average.
  double AddedNoise() const {
    return std::sqrt(std::max(0.0, noise * noise - noise_without * noise_without) /
                     std::max(1, outer_iterations));
  }
};

// The planner's finding for one switch.
struct EffectDecision {
  std::string name;  // PlannerSwitches.
  std::string kind;  // "image" (an image effect) or "step" (a derivative term).
  bool on = true;
  // "measured", "pinned", "fitted" (the stage fits its parameters), "absent" (not in the scene or
  // not configured), "no geometry phase" (derivative terms of a texture-only fit).
  std::string reason;
  // Image effects: the change of the images; in a stage with a geometry phase also of the vertex
  // gradient (an effect that barely shows can still carry the step, e.g. shadows whose edges
  // move with the geometry). Derivative terms: the gradient only. On when either matters.
  EffectMeasurement image, step;
  int bounces = 0;  // "bounces": the count chosen.
};

struct EffectPlanReport {
  EffectPlan plan;
  std::vector<EffectDecision> decisions;
  double seconds = 0.0;  // the planner's own wall time.
  // The largest signal measured, for the images and the gradient (PlannerContext's scales).
  double image_signal = 0.0;
  double step_signal = 0.0;
  int views = 0;  // views measured.

  nlohmann::json ToJson() const;
};

// What the planner needs to know of the stage besides the cache.
struct PlannerContext {
  EffectPlan ceiling;           // the configured effects and budgets: the planner only drops.
  bool geometry_phase = false;  // the fit moves vertices: derivative terms are measured.
  bool fit_specular = false;    // the texture phase fits the specular weight.
  bool has_environment = false;
  bool has_point_lights =
      false;  // point or directional lights (delta lights that cast shadow edges).
  bool specular_nonzero = true;  // some specular weight of the material is > 0.
  // K: the number of independent seeds the stage's noise averages over, >= 1: its outer
  // iterations (one seed each), or for Adam with `resample` its steps in full-view renders.
  int outer_iterations = 1;
  // The largest signal (RMS of the mean values) measured earlier in the stage on the same
  // topology, for the images and the gradient; 0 = none. The share limit is taken of the larger
  // of it and the current signal: near convergence the gradient shrinks towards its noise, and a
  // share of what is left would bring back terms that do not move the fit.
  double image_signal_scale = 0.0;
  double step_signal_scale = 0.0;
  uint64_t seed = 0;  // base seed of the planner's renders (two seeds from it).
};

// Measures and decides (see the file comment); leaves the cache's plan set to the result and its
// active parameters and seed as they were. Fails only when a render is not finite.
Status PlanEffects(const EffectPlannerOptions& options, const PlannerContext& context,
                   RenderCache* cache, EffectPlanReport* report);

// One console line per switch whose state differs from `previous` ("effects: shadows off (image
// change 0.0019 <= threshold 0.0021, 1.0% of the signal)"); when `previous` is
// null, the switches the plan turned off and the measured bounce count.
std::vector<std::string> PlanChangeLines(const EffectPlanReport& report,
                                         const EffectPlanReport* previous);

}  // namespace sft

#endif  // SFT_OPTIM_EFFECT_PLANNER_H_
