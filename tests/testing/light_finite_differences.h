// Finite-difference checks of light-parameter derivatives (point-light positions, directional-
// light directions, environment rotations): the light's three parameters x moved along a fixed δ,
// images rendered at x ± h·δ with the same seeds (the light does not change the sampled paths; an
// environment's sampling map held, RenderOptions::sampling_environment), against the Jacobian
// rows and the adjoint gradient at x, per pixel, on 8×8 block sums and on the image sum.
#ifndef SFT_TESTS_TESTING_LIGHT_FINITE_DIFFERENCES_H_
#define SFT_TESTS_TESTING_LIGHT_FINITE_DIFFERENCES_H_

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "src/geometry/material.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {
namespace testing {

struct LightComparison {
  double pixel_error = 0.0;  // relative L2 error per pixel and channel.
  double block_error = 0.0;  // the same on 8×8 block sums.
  double sum_error = 0.0;    // |Σ analytic − Σ fd| / |Σ fd|.
  double fd_sum = 0.0;       // Σ fd over the image and RGB.
  // The adjoint gradient along δ and Σ w·(rows·δ) for the same weights, and Σ |w·(rows·δ)|.
  double adjoint = 0.0;
  double weighted = 0.0;
  double weighted_abs = 0.0;
  bool image_unchanged = true;  // the derivative pass rendered RenderView's image.
  bool rows_of_kind = true;     // every row entry is of the checked kind.
};

class LightDerivativeCheck {
 public:
  // `view_at(x)`: the view with the light at parameters x (its light_index 0). `kind`:
  // kLightPosition, kLightDirection or kEnvironmentRotation, the layout's one light's parameters.
  // Renders the central
  // difference (I(x0 + hδ) − I(x0 − hδ))/(2h) once, here.
  LightDerivativeCheck(const RenderScene& scene, const Material& material,
                       const RenderOptions& options,
                       std::function<ViewSetup(const Eigen::Vector3d&)> view_at,
                       const Eigen::Vector3d& x0, const Eigen::Vector3d& delta, double h,
                       ParameterKind kind);

  // The analytic derivative at x0 with `shadow_edge_ratio` and `secondary_edge_samples` (the
  // request's other settings: defaults, rows and random adjoint weights) against the difference.
  LightComparison Compare(double shadow_edge_ratio, double secondary_edge_samples) const;

  // Compares at the default budgets, prints the errors under `name` and expects them below the
  // tolerances (one ≤ 0: not checked), the image unchanged by the derivative pass, rows of the
  // checked kind only and the adjoint equal to the weighted rows. With `shadows` also compares
  // without the shadow edges seen directly — the block error must at least double, so that the
  // tolerance tests that term — and, with more than one bounce, without secondary edges (B)
  // (printed only: a small part on the test scenes, docs/design-notes.md).
  void ExpectMatches(const char* name, double pixel_tolerance, double block_tolerance,
                     double sum_tolerance, bool shadows, int bounces) const;

 private:
  const RenderScene& scene_;
  const Material& material_;
  RenderOptions options_;
  std::function<ViewSetup(const Eigen::Vector3d&)> view_at_;
  Eigen::Vector3d x0_;
  ParameterKind kind_;
  ParameterLayout layout_;
  std::vector<double> direction_;  // δ in the layout's index space.
  std::vector<double> fd_;
  int width_ = 0;
};

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_LIGHT_FINITE_DIFFERENCES_H_
