#include "src/optim/effect_planner.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "src/optim/render_cache.h"

namespace sft {
namespace {

using json = nlohmann::json;

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

const std::vector<std::string>& ImageSwitches() {
  static const std::vector<std::string> names = {"environment", "specular", "shadows", "bounces"};
  return names;
}

const std::vector<std::string>& StepSwitches() {
  static const std::vector<std::string> names = {"primary_edges", "shadow_edges", "texel_edges",
                                                 "secondary_edges"};
  return names;
}

// The values a measurement compares, for two seeds: images (RGB of the measured views' active
// pixels, scaled by the loss's pixel weights) or vertex gradients.
using Sample = std::vector<double>;
// A vertex gradient split by derivative term (GradientParts), indexed by DerivativeTerm.
using Parts = std::array<Sample, kNumDerivativeTerms>;

// The two-seed estimates of the file comment for a reference A and a variant B.
struct Comparison {
  double change = 0.0;  // sqrt(max(0, mean[(A1 − B1)(A2 − B2)])).
  // sqrt(2 × the standard error of that mean): smaller changes are not distinguishable from 0.
  double floor = 0.0;
  double noise = 0.0;          // sqrt(mean[(A1 − A2)²] / 2).
  double noise_without = 0.0;  // sqrt(mean[(B1 − B2)²] / 2).
  double signal = 0.0;         // sqrt(max(0, mean[A1 · A2])).
};

Comparison Compare(const Sample (&a)[2], const Sample (&b)[2]) {
  double cross = 0.0, cross2 = 0.0, diff2 = 0.0, diff2_without = 0.0, product = 0.0;
  const size_t n = a[0].size();
  for (size_t i = 0; i < n; ++i) {
    const double p = (a[0][i] - b[0][i]) * (a[1][i] - b[1][i]);
    cross += p;
    cross2 += p * p;
    diff2 += (a[0][i] - a[1][i]) * (a[0][i] - a[1][i]);
    diff2_without += (b[0][i] - b[1][i]) * (b[0][i] - b[1][i]);
    product += a[0][i] * a[1][i];
  }
  Comparison c;
  if (n == 0) return c;
  const double mean = cross / n;
  const double standard_error = std::sqrt(std::max(0.0, cross2 / n - mean * mean) / n);
  c.change = std::sqrt(std::max(0.0, mean));
  c.floor = std::sqrt(2.0 * standard_error);
  c.noise = std::sqrt(diff2 / (2.0 * n));
  c.noise_without = std::sqrt(diff2_without / (2.0 * n));
  c.signal = std::sqrt(std::max(0.0, product / n));
  return c;
}

// Measures the fit's images (or vertex gradients) under one plan at the planner's two seeds.
class Measurer {
 public:
  Measurer(RenderCache* cache, const std::vector<int>& views, uint64_t seed)
      : cache_(cache), views_(views), seeds_{seed, seed + 1} {}

  Status Images(const EffectPlan& plan, Sample (&out)[2]) {
    for (int k = 0; k < 2; ++k) {
      out[k].clear();
      // One call for every view, so that under mpirun the views render on every rank.
      std::vector<Image> images;
      if (!cache_->RenderWith(views_, plan, seeds_[k], &images)) {
        return Status::Error("effect planner: a render was not finite (" + plan.Summary() + ")");
      }
      for (size_t i = 0; i < views_.size(); ++i) {
        const int v = views_[i];
        const Image& image = images[i];
        const LevelCache& level = cache_->level(v, 0);
        const std::vector<uint8_t>& active = cache_->targets(v).active[0];
        for (int p = 0; p < image.width * image.height; ++p) {
          if (!active[p]) continue;
          const double w = level.pixel_sqrt_weight.empty() ? 1.0 : level.pixel_sqrt_weight[p];
          for (int c = 0; c < 3; ++c) {
            out[k].push_back(w * image.at(p % image.width, p / image.width, c));
          }
        }
      }
    }
    return Status::Ok();
  }

  // The adjoint weights of the measured views at the current state under `plan` (one render of
  // each: the weights come from the pyramid of the residuals).
  void PrepareWeights(const EffectPlan& plan) {
    cache_->SetPlan(plan);
    cache_->SetSeed(seeds_[0] ^ 0x5bd1e995ull);
    cache_->RenderSome(views_);
    weights_.clear();
    for (int v : views_) weights_.push_back(cache_->AdjointWeights(v));
  }

  // The vertex gradients under `plan` at both seeds, and from the same passes their parts.
  Status Gradients(const EffectPlan& plan, Sample (&out)[2], Parts (&parts)[2]) {
    const int n = 3 * cache_->params().layout().num_vertices;
    for (int k = 0; k < 2; ++k) {
      std::vector<double> gradient(cache_->params().size(), 0.0);
      GradientParts split;
      split.Reset(gradient.size());
      if (!cache_->AddAdjointGradientsWith(views_, weights_, plan, seeds_[k], &gradient, &split)) {
        return Status::Error("effect planner: a gradient was not finite (" + plan.Summary() + ")");
      }
      out[k].assign(gradient.begin(), gradient.begin() + n);
      for (int t = 0; t < kNumDerivativeTerms; ++t) {
        parts[k][t].assign(split.parts[t].begin(), split.parts[t].begin() + n);
      }
    }
    return Status::Ok();
  }

 private:
  RenderCache* cache_;
  std::vector<int> views_;
  uint64_t seeds_[2];
  std::vector<Image> weights_;
};

// noise_factor × σ / √K (the file comment of effect_planner.h).
double Threshold(const EffectPlannerOptions& options, const PlannerContext& context, double noise) {
  return options.noise_factor * noise / std::sqrt(std::max(1, context.outer_iterations));
}

// The reason a switch is decided without a measurement, or "" when it must be measured.
std::string Unmeasured(const std::string& name, const EffectPlan& plan,
                       const PlannerContext& context) {
  if (!plan.IsOn(name)) return "absent";
  if (name == "environment" && !context.has_environment) return "absent";
  if (name == "specular" && context.fit_specular) return "fitted";
  if (name == "specular" && !context.specular_nonzero) return "absent";
  if (name == "shadows" && !context.has_point_lights && !context.has_environment) return "absent";
  if (name == "shadow_edges" && (!context.has_point_lights || !plan.effects.shadows)) {
    return "absent";
  }
  const bool environment_occlusion =
      context.has_environment && plan.effects.environment && plan.effects.shadows;
  if (name == "secondary_edges" && !plan.IsOn("bounces") && !environment_occlusion) {
    return "absent";
  }
  return "";
}

// The current plan's samples (images, and gradients with their parts, at both seeds), computed
// on demand and carried over when a drop makes a variant the current plan.
struct References {
  Sample image[2], step[2];
  Parts step_parts[2];
  bool have_image = false, have_step = false;
  void Invalidate() { have_image = have_step = false; }
  // Switches derivative term `term` off: at the same seed the gradient without it is the
  // gradient minus its part (GradientParts: the edge terms draw from streams of their own). The
  // images do not depend on derivative terms and stay.
  void DropTerm(DerivativeTerm term) {
    if (!have_step) return;
    for (int k = 0; k < 2; ++k) {
      Sample& part = step_parts[k][static_cast<int>(term)];
      for (size_t i = 0; i < step[k].size(); ++i) step[k][i] -= part[i];
      std::fill(part.begin(), part.end(), 0.0);
    }
  }
};

// The derivative term a switch turns off, or null for an image effect.
const DerivativeTerm* TermOf(const std::string& name) {
  static const DerivativeTerm kTerms[] = {DerivativeTerm::kPrimaryEdges,
                                          DerivativeTerm::kShadowEdges, DerivativeTerm::kTexelEdges,
                                          DerivativeTerm::kSecondaryEdges};
  for (const DerivativeTerm& term : kTerms) {
    if (name == DerivativeTermName(term)) return &term;
  }
  return nullptr;
}

// Compares `plan` with `variant` on the images (when `image`), then on the gradients (when
// `step` and the images did not already show that the switch matters); afterwards
// `variant_refs` holds the variant's samples. A variant that only switches derivative term
// `term` off (non-null) needs no passes of its own: its gradients are the plan's minus the
// term's part (References::DropTerm). Returns whether the switch matters.
Status Measure(const EffectPlannerOptions& options, const PlannerContext& context,
               const EffectPlan& plan, const EffectPlan& variant, const DerivativeTerm* term,
               bool image, bool step, Measurer* measurer, References* refs,
               References* variant_refs, EffectDecision* decision, bool* matters) {
  auto fill = [&](const Sample(&a)[2], const Sample(&b)[2], double scale, EffectMeasurement* m) {
    const Comparison c = Compare(a, b);
    m->measured = true;
    m->change = c.change;
    m->floor = c.floor;
    m->noise = c.noise;
    m->noise_without = c.noise_without;
    m->signal = c.signal;
    m->threshold = Threshold(options, context, c.noise);
    m->share_limit = options.max_share * std::max(c.signal, scale);
    m->outer_iterations = std::max(1, context.outer_iterations);
  };
  variant_refs->Invalidate();
  decision->image = decision->step = EffectMeasurement();
  decision->reason = "measured";
  if (image) {
    if (!refs->have_image) SFT_RETURN_IF_ERROR(measurer->Images(plan, refs->image));
    refs->have_image = true;
    SFT_RETURN_IF_ERROR(measurer->Images(variant, variant_refs->image));
    variant_refs->have_image = true;
    fill(refs->image, variant_refs->image, context.image_signal_scale, &decision->image);
  }
  *matters = decision->image.Matters();
  if (step && !*matters) {
    if (!refs->have_step) {
      SFT_RETURN_IF_ERROR(measurer->Gradients(plan, refs->step, refs->step_parts));
    }
    refs->have_step = true;
    if (term != nullptr) {
      *variant_refs = *refs;
      variant_refs->DropTerm(*term);
    } else {
      SFT_RETURN_IF_ERROR(
          measurer->Gradients(variant, variant_refs->step, variant_refs->step_parts));
    }
    variant_refs->have_step = true;
    fill(refs->step, variant_refs->step, context.step_signal_scale, &decision->step);
    *matters = decision->step.Matters();
  }
  return Status::Ok();
}

// A pin or a reason not to measure; returns true when it decided (the plan follows).
bool DecideWithoutMeasuring(const std::string& name, const EffectPlannerOptions& options,
                            const PlannerContext& context, EffectPlan* plan, References* refs,
                            EffectDecision* decision) {
  const auto pin = options.pins.find(name);
  if (pin != options.pins.end()) {
    decision->reason = "pinned";
    decision->on = pin->second && plan->IsOn(name);
  } else {
    decision->reason = Unmeasured(name, *plan, context);
    if (decision->reason.empty()) return false;
    decision->on = decision->reason == "fitted";
  }
  if (!decision->on && plan->IsOn(name)) {
    *plan = plan->Without(name);
    if (const DerivativeTerm* term = TermOf(name)) {
      refs->DropTerm(*term);
    } else {
      refs->Invalidate();
    }
  }
  return true;
}

// Decides one switch (not "bounces"): measured against the current plan, dropped from it when
// it matters neither in the images nor in the step.
Status DecideSwitch(const std::string& name, const std::string& kind,
                    const EffectPlannerOptions& options, const PlannerContext& context,
                    Measurer* measurer, References* refs, EffectPlan* plan,
                    EffectDecision* decision) {
  decision->name = name;
  decision->kind = kind;
  if (kind == "step" && !context.geometry_phase && Unmeasured(name, *plan, context).empty() &&
      options.pins.count(name) == 0) {
    decision->reason = "no geometry phase";
    decision->on = plan->IsOn(name);
    return Status::Ok();
  }
  if (DecideWithoutMeasuring(name, options, context, plan, refs, decision)) return Status::Ok();
  const EffectPlan without = plan->Without(name);
  References variant;
  bool matters = false;
  SFT_RETURN_IF_ERROR(Measure(options, context, *plan, without, TermOf(name), kind == "image",
                              context.geometry_phase, measurer, refs, &variant, decision,
                              &matters));
  decision->on = matters;
  if (!decision->on) {
    *plan = without;
    *refs = std::move(variant);
  }
  return Status::Ok();
}

// Lowers the bounce count while the last bounce matters neither in the images nor in the step.
Status DecideBounces(const EffectPlannerOptions& options, const PlannerContext& context,
                     Measurer* measurer, References* refs, EffectPlan* plan,
                     EffectDecision* decision) {
  decision->name = "bounces";
  decision->kind = "image";
  if (!DecideWithoutMeasuring("bounces", options, context, plan, refs, decision)) {
    while (plan->bounces > 1) {
      EffectPlan fewer = *plan;
      --fewer.bounces;
      References variant;
      bool matters = false;
      SFT_RETURN_IF_ERROR(Measure(options, context, *plan, fewer, nullptr, true,
                                  context.geometry_phase, measurer, refs, &variant, decision,
                                  &matters));
      if (matters) break;
      *plan = fewer;
      *refs = std::move(variant);
    }
    decision->on = plan->IsOn("bounces");
  }
  decision->bounces = plan->effects.bounces ? plan->bounces : 1;
  return Status::Ok();
}

}  // namespace

const std::vector<std::string>& PlannerSwitches() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = ImageSwitches();
    all.insert(all.end(), StepSwitches().begin(), StepSwitches().end());
    return all;
  }();
  return names;
}

bool EffectPlannerOptions::Check(std::string* why) const {
  for (const auto& [name, on] : pins) {
    const auto& names = PlannerSwitches();
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      *why = "pin: unknown effect '" + name +
             "' (known: environment, specular, shadows, bounces, primary_edges, shadow_edges, "
             "texel_edges, secondary_edges)";
      return false;
    }
  }
  if (views < 1 || views > 1000) {
    *why = "planner_views: must be in [1, 1000]";
    return false;
  }
  if (!(noise_factor >= 0.0 && noise_factor <= 100.0)) {
    *why = "planner_noise_factor: must be in [0, 100]";
    return false;
  }
  if (!(max_share >= 0.0 && max_share <= 1.0)) {
    *why = "planner_max_share: must be in [0, 1]";
    return false;
  }
  return true;
}

EffectPlan EffectPlan::From(const RenderOptions& render, const DerivativeRequest& edges) {
  EffectPlan plan;
  plan.effects = render.effects;
  plan.bounces = render.bounces;
  plan.primary_edge_ratio = edges.primary_edge_ratio;
  plan.shadow_edge_ratio = edges.shadow_edge_ratio;
  plan.texel_edge_ratio = edges.texel_edge_ratio;
  plan.secondary_edge_samples = edges.secondary_edge_samples;
  return plan;
}

void EffectPlan::ApplyTo(RenderOptions* render, DerivativeRequest* edges) const {
  render->effects = effects;
  render->bounces = bounces;
  edges->primary_edge_ratio = primary_edge_ratio;
  edges->shadow_edge_ratio = shadow_edge_ratio;
  edges->texel_edge_ratio = texel_edge_ratio;
  edges->secondary_edge_samples = secondary_edge_samples;
}

bool EffectPlan::IsOn(const std::string& name) const {
  if (name == "environment") return effects.environment;
  if (name == "specular") return effects.specular;
  if (name == "shadows") return effects.shadows;
  if (name == "bounces") return effects.bounces && bounces > 1;
  if (name == "primary_edges") return primary_edge_ratio > 0.0;
  if (name == "shadow_edges") return shadow_edge_ratio > 0.0;
  if (name == "texel_edges") return texel_edge_ratio > 0.0;
  if (name == "secondary_edges") return secondary_edge_samples > 0.0;
  return false;
}

EffectPlan EffectPlan::Without(const std::string& name) const {
  EffectPlan plan = *this;
  if (name == "environment") plan.effects.environment = false;
  if (name == "specular") plan.effects.specular = false;
  if (name == "shadows") plan.effects.shadows = false;
  if (name == "bounces") plan.bounces = 1;
  if (name == "primary_edges") plan.primary_edge_ratio = 0.0;
  if (name == "shadow_edges") plan.shadow_edge_ratio = 0.0;
  if (name == "texel_edges") plan.texel_edge_ratio = 0.0;
  if (name == "secondary_edges") plan.secondary_edge_samples = 0.0;
  return plan;
}

std::string EffectPlan::Summary() const {
  std::string image, step;
  auto add = [](std::string* s, bool on, const std::string& word) {
    if (!on) return;
    if (!s->empty()) *s += " ";
    *s += word;
  };
  add(&image, effects.direct, "direct");
  add(&image, effects.environment, "env");
  add(&image, effects.specular, "spec");
  add(&image, effects.shadows, "shadows");
  add(&image, true, std::to_string(effects.bounces ? bounces : 1) + "seg");
  add(&step, primary_edge_ratio > 0.0, "primary");
  add(&step, shadow_edge_ratio > 0.0, "shadow");
  add(&step, texel_edge_ratio > 0.0, "texel");
  add(&step, secondary_edge_samples > 0.0, "secondary");
  return image + " | edges: " + (step.empty() ? "none" : step);
}

bool EffectPlan::operator==(const EffectPlan& o) const {
  return effects.ToString() == o.effects.ToString() && bounces == o.bounces &&
         primary_edge_ratio == o.primary_edge_ratio && shadow_edge_ratio == o.shadow_edge_ratio &&
         texel_edge_ratio == o.texel_edge_ratio &&
         secondary_edge_samples == o.secondary_edge_samples;
}

json EffectPlanReport::ToJson() const {
  json decisions_json = json::array();
  for (const EffectDecision& d : decisions) {
    json entry = {{"name", d.name}, {"kind", d.kind}, {"on", d.on}, {"reason", d.reason}};
    for (const auto& [key, m] :
         {std::make_pair("image", &d.image), std::make_pair("step", &d.step)}) {
      if (!m->measured) continue;
      entry[key] = {{"change", m->change},
                    {"noise", m->noise},
                    {"threshold", m->threshold},
                    {"share_limit", m->share_limit},
                    {"noise_without", m->noise_without},
                    {"floor", m->floor},
                    {"share", m->signal > 0.0 ? m->change / m->signal : 0.0},
                    {"matters", m->Matters()}};
    }
    if (d.name == "bounces") entry["bounces"] = d.bounces;
    decisions_json.push_back(entry);
  }
  return {{"plan", plan.Summary()},
          {"effects", plan.effects.ToString()},
          {"bounces", plan.bounces},
          {"primary_edge_ratio", plan.primary_edge_ratio},
          {"shadow_edge_ratio", plan.shadow_edge_ratio},
          {"texel_edge_ratio", plan.texel_edge_ratio},
          {"secondary_edge_samples", plan.secondary_edge_samples},
          {"seconds", seconds},
          {"views", views},
          {"decisions", decisions_json}};
}

Status PlanEffects(const EffectPlannerOptions& options, const PlannerContext& context,
                   RenderCache* cache, EffectPlanReport* report) {
  const double start = NowSeconds();
  const ActiveParameters saved_active = cache->active();
  const uint64_t saved_seed = cache->seed();
  // Evenly spaced fitted views (all of them when there are no more than options.views).
  std::vector<int> views;
  const int n = cache->num_views(), count = std::min(options.views, n);
  for (int i = 0; i < count; ++i)
    views.push_back(static_cast<int>((2LL * i + 1) * n / (2 * count)));
  Measurer measurer(cache, views, context.seed);
  if (context.geometry_phase) {
    ActiveParameters vertices;
    vertices.vertices = true;
    vertices.albedo = vertices.roughness = vertices.specular = vertices.lights = false;
    cache->SetActive(vertices);
    measurer.PrepareWeights(context.ceiling);
  }
  EffectPlan plan = context.ceiling;
  report->decisions.clear();
  References refs;
  for (const std::string& name : PlannerSwitches()) {
    EffectDecision decision;
    const bool image =
        std::find(ImageSwitches().begin(), ImageSwitches().end(), name) != ImageSwitches().end();
    if (name == "bounces") {
      SFT_RETURN_IF_ERROR(DecideBounces(options, context, &measurer, &refs, &plan, &decision));
    } else {
      SFT_RETURN_IF_ERROR(DecideSwitch(name, image ? "image" : "step", options, context, &measurer,
                                       &refs, &plan, &decision));
    }
    report->image_signal = std::max(report->image_signal, decision.image.signal);
    report->step_signal = std::max(report->step_signal, decision.step.signal);
    report->decisions.push_back(decision);
  }
  cache->SetActive(saved_active);
  cache->SetSeed(saved_seed);
  cache->SetPlan(plan);
  report->plan = plan;
  report->views = count;
  report->seconds = NowSeconds() - start;
  return Status::Ok();
}

std::vector<std::string> PlanChangeLines(const EffectPlanReport& report,
                                         const EffectPlanReport* previous) {
  std::vector<std::string> lines;
  for (size_t i = 0; i < report.decisions.size(); ++i) {
    const EffectDecision& d = report.decisions[i];
    const EffectDecision* p =
        previous && i < previous->decisions.size() ? &previous->decisions[i] : nullptr;
    if (p && p->on == d.on && p->bounces == d.bounces) continue;
    // The first plan: only what it switches off or measures (the rest is as configured).
    if (!p && previous == nullptr && d.on && !(d.name == "bounces" && d.reason == "measured")) {
      continue;
    }
    if (!p && previous == nullptr && (d.reason == "absent" || d.reason == "no geometry phase")) {
      continue;
    }
    const std::string state =
        d.name == "bounces" ? std::to_string(d.bounces) + " segments" : (d.on ? "on" : "off");
    std::string line = "effects: " + d.name + " " + state + " (";
    if (d.reason == "measured") {
      std::string parts;
      for (const auto& [key, m] :
           {std::make_pair("image", &d.image), std::make_pair("step", &d.step)}) {
        if (!m->measured) continue;
        char part[160];
        std::snprintf(part, sizeof(part),
                      "%s change %.3g: noise threshold %.3g, %.1f%% of the signal, added noise "
                      "%.3g, floor %.3g",
                      key, m->change, m->threshold,
                      m->signal > 0.0 ? 100.0 * m->change / m->signal : 0.0, m->AddedNoise(),
                      m->floor);
        parts += (parts.empty() ? "" : "; ") + std::string(part);
      }
      line += parts + ")";
    } else {
      line += d.reason + ")";
    }
    lines.push_back(line);
  }
  return lines;
}

}  // namespace sft
