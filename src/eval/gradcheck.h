// Gradient check of the renderer's derivatives against central finite differences of the
// expected image, for one parameter kind over chosen views (`sft gradcheck`, issue 3).
//
// Per view: a random direction δ over the parameters of the kind (seeded), the analytic
// directional derivative image Σ_θ J_θ·δ_θ from the Jacobian rows, and the central difference
// (I(θ + hδ) − I(θ − hδ))/(2h) rendered with the same seeds and detached sampling (the sampling
// material stays at θ), so both sides differentiate the same estimator. Reports the relative L2
// error ‖analytic − fd‖/‖fd‖ per view and over all views, and the consistency of the adjoint
// gradient with the rows.
#ifndef SFT_EVAL_GRADCHECK_H_
#define SFT_EVAL_GRADCHECK_H_

#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"

namespace sft {

struct GradcheckOptions {
  ParameterKind kind = ParameterKind::kAlbedo;  // which parameters are perturbed.
  RenderOptions render;                         // spp, bounces, effects, seed, threads.
  std::vector<int> views;                       // view indices; empty = all.
  double step = 0.0;        // finite-difference step h; 0 = automatic per kind (1e-3, or 1e-4·r
                            // for roughness r).
  double tolerance = 0.05;  // pass when the overall relative error is at most this.
  uint64_t direction_seed = 1;  // seed of the random direction δ.

  bool Check(std::string* why) const;
};

struct GradcheckViewResult {
  int view = 0;
  double relative_error = 0.0;  // ‖analytic − fd‖₂ / ‖fd‖₂ over the view's pixels and RGB.
  double fd_norm = 0.0;         // ‖fd‖₂.
  double adjoint_mismatch = 0.0;  // |δ·Jᵀw − Σ w·(Jδ)| / Σ|w·(Jδ)| for a random w.
  size_t jacobian_entries = 0;
};

struct GradcheckResult {
  std::string kind;
  std::vector<GradcheckViewResult> views;
  double relative_error = 0.0;  // over all views.
  bool passed = false;
};

Status RunGradcheck(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                    const GradcheckOptions& options, GradcheckResult* result);

}  // namespace sft

#endif  // SFT_EVAL_GRADCHECK_H_
