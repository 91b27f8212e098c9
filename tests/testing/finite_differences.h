// Finite-difference checks of vertex derivatives shared by the renderer's tests: the directional
// derivative image from Jacobian rows, central differences of displaced meshes (same seeds,
// detached sampling) and their comparison on 8×8 block sums.
#ifndef SFT_TESTS_TESTING_FINITE_DIFFERENCES_H_
#define SFT_TESTS_TESTING_FINITE_DIFFERENCES_H_

#include <vector>

#include "src/geometry/material.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"
#include "tests/testing/meshes.h"

namespace sft {
namespace testing {

// δ·(p) → the directional derivative image Σ_θ J_θ·δ_θ (RGB per pixel) from the rows.
std::vector<double> RowsTimes(const DerivativeOutput& out, const std::vector<double>& delta);

// (I(p + hδ) − I(p − hδ))/(2h), RGB per pixel, same seeds, detached sampling.
std::vector<double> CentralDifference(const Triangles& g, const std::vector<double>& delta,
                                      double h, const Material& material, const ViewSetup& view,
                                      const RenderOptions& options);

// Sums of block × block tiles of a res × res RGB image.
std::vector<double> BlockSums(const std::vector<double>& image, int res, int block);
// ‖a − ref‖/‖ref‖ (1 when ref vanishes and a does not).
double RelativeError(const std::vector<double>& a, const std::vector<double>& ref);
double Sum(const std::vector<double>& v);

struct Comparison {
  double block_error = 0.0;  // 8×8 block sums, RGB.
  double sum_error = 0.0;    // |Σ analytic − Σ fd| / |Σ fd| over the image and RGB.
  double adjoint_mismatch = 0.0;
  bool finite = true;
};

// Renders the derivative rows (and the adjoint for random weights) at p and the central difference
// along δ with step h; compares them on 8×8 block sums (prints the numbers under `name`).
//
// `nodes` > 1: the analytic side is instead the mean of the derivative images at the midpoints
// t_j = −h + (j + ½)·2h/nodes of the meshes p + t_j·δ, each rendered with spp/nodes samples and
// its own seed. In expectation the central difference is exactly the mean of the derivative over
// [−h, h] (I(h) − I(−h) = ∫ I′), and this midpoint rule estimates that mean, also where I′ is
// not smooth: the expected image of a polyhedron has a kink whenever one of its faces turns edge
// on to the camera (the set of silhouette edges changes), so a central difference over a step
// containing such events is not the derivative at p.
Comparison CompareWithFiniteDifferences(const Triangles& g, const std::vector<double>& delta,
                                        double h, const Material& material, const ViewSetup& view,
                                        RenderOptions options, const char* name, int nodes = 1);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_FINITE_DIFFERENCES_H_
