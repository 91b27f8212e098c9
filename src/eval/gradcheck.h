// Gradient check of the renderer's derivatives against central finite differences of the
// expected image, for one parameter kind over chosen views (`sft gradcheck`, issue 3).
//
// Per view: a random direction δ over the parameters of the kind (seeded), the analytic
// directional derivative image Σ_θ J_θ·δ_θ from the Jacobian rows, and the central difference
// (I(θ + hδ) − I(θ − hδ))/(2h) rendered with the same seeds and detached sampling (the sampling
// material stays at θ), so both sides differentiate the same estimator. Reports the relative L2
// error ‖analytic − fd‖/‖fd‖ per view and over all views, and the consistency of the adjoint
// gradient with the rows.
//
// Material and light kinds (albedo, roughness, specular, light): δ is uniform in [−1, 1] per
// parameter; nothing moves, so the estimator is smooth in θ and the comparison is per pixel
// (block 1). Errors of ~1e-4 are typical; anything near the 5% tolerance is a bug.
//
// Vertices: δ is a smooth random displacement field over the mesh, a sum of three low-frequency
// modes δ(p) = Σ_m a_m·sin(2π k_m·(p − c)/e + φ_m) (c the bounding-box centre, e its diagonal,
// random amplitude vectors a_m, wave vectors |k_m| ≤ 1.5, phases φ_m), scaled so that
// max_v |δ(v)| = 1; the step h is a length (automatic: 5e-3·e, shortened for glossy lobes so
// that the normals turn by much less than the lobe's width α: ×clamp(2α, 1/16, 1), ¼ at
// roughness 0.35; at 5e-3·e a roughness-0.35 highlight's truncation error alone was 10%).
// The finite differences render the displaced meshes p ± h·δ with the same seeds. Moving geometry
// moves silhouettes, shadow boundaries and (faces are flat-shaded) every edge between non-coplanar
// faces; the renderer estimates such derivatives by edge sampling, a Monte Carlo estimate that
// lands at random pixels along the edges, while the finite difference counts the camera and shadow
// samples that switch sides (its noise grows like 1/√(h·spp), its truncation error like h because
// block sums kink as edges cross pixel and block boundaries). Both are noisy per pixel, so the
// images are compared after summing over B×B pixel blocks (`block`, automatic 8 for vertices and
// light positions, whose shadow boundaries move too), and
// the report adds `projection_error`, the relative error of three smooth global projections Σ_p Σ_c
// w(p)·I_pc with w = 1, cos(π(x + ½)/W) and cos(π(y + ½)/H) (ill-conditioned when these sums nearly
// cancel, e.g. an object moving sideways; informative, not part of the pass criterion). The pass
// criterion is the block relative error.
//
// Finite differences of geometry need many samples; recommended: `--spp 64` or more for
// Lambertian direct light, 1024 with a glossy lobe (the shorter step is noisier) or a bounce. The
// finite difference's own block error (seed-to-seed, 8×8 blocks, h = 5e-3·e, 128² Cycles bunny
// views) is 1–2.5% for Lambert and direct light at 64 spp (0.6–1.4% at h = 1e-2·e, 2.5–4% at
// 3e-3·e), 4% with a glossy lobe (specular 0.5, roughness 0.35) at 64 spp and 2% at 256 spp, and
// 17% (64 spp) or 9% (256 spp) with an indirect bounce. With the glossy step (h = 1.25e-3·e) and
// a bounce it is 9% at 1024 spp (2.6% without the bounce): bounce rays passing near silhouettes
// switch what they hit as those move (sampling the bounce directions around the undisplaced
// normals left it at 9.1%). The analytic side is noisy too with a bounce (edge samples; at 1024
// spp on that view: primary edges 4.8%, secondary edges 8%). Check bounces > 1 with many more
// samples (errors fall like 1/√spp), or check direct light and bounces separately.
#ifndef SFT_EVAL_GRADCHECK_H_
#define SFT_EVAL_GRADCHECK_H_

#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"
#include "src/render/scene.h"

namespace sft {

struct GradcheckOptions {
  ParameterKind kind = ParameterKind::kAlbedo;  // which parameters are perturbed.
  RenderOptions render;                         // spp, bounces, effects, seed, threads.
  std::vector<int> views;                       // view indices; empty = all.
  double step = 0.0;  // finite-difference step h; 0 = automatic per kind (1e-3, 1e-4·r for
                      // roughness r, 5e-3 × the bounding-box diagonal for vertices, times
                      // clamp(2α, 1/16, 1) with a glossy lobe of width α = r²_min; 5e-3 × the
                      // diagonal for light positions, which move each point light by h·δ_l in
                      // its own frame, ParameterLayout::light_positions; 5e-3 for light
                      // directions, about 5e-3 rad of each directional light's unit direction
                      // in its frame; 1e-4 rad for environment rotations, which turn each probe
                      // by exp([h·δ_l]×) in its frame).
  // Side B of the pixel blocks summed before comparing; 0 = automatic: 8 for vertices, light
  // positions and light directions (edge
  // sampling puts silhouette and shadow-boundary derivatives at random pixels along the edge, and
  // the finite difference of a moving edge is quantised by the camera samples that cross it:
  // both are unbiased but noisy per pixel, and agree on block sums), 1 (per pixel) otherwise.
  int block = 0;
  double tolerance = 0.05;      // pass when the overall (block) relative error is at most this.
  uint64_t direction_seed = 1;  // seed of the random direction δ.
  // Edge-sampling budgets of the analytic side (primary/shadow/texel edge ratios, secondary edge
  // samples; see DerivativeRequest). Setting one to 0 isolates the other terms; `params` and the
  // outputs are set by the check itself.
  DerivativeRequest derivatives;
  // When not empty: per view, writes DIR/view_<v>_analytic.exr, view_<v>_fd.exr (RGB directional
  // derivative images, linear float) and view_<v>_compare.png (analytic | finite difference |
  // difference, red positive, blue negative, all on one scale), to see where they disagree.
  std::string image_dir;

  bool Check(std::string* why) const;
};

// A smooth global projection P = Σ_p Σ_c w(p)·(directional derivative)_pc of one view.
struct GradcheckProjection {
  std::string weight;     // "one", "cos_x", "cos_y".
  double analytic = 0.0;  // from the Jacobian rows.
  double fd = 0.0;        // from the finite difference.
};

struct GradcheckViewResult {
  int view = 0;
  double relative_error = 0.0;  // ‖analytic − fd‖₂ / ‖fd‖₂ over the view's B×B block sums and
                                // RGB (per pixel when the block is 1).
  double pixel_relative_error = 0.0;  // the same per pixel (equals relative_error at block 1).
  double projection_error = 0.0;  // ‖P_analytic − P_fd‖₂ / ‖P_fd‖₂ over the projections.
  std::vector<GradcheckProjection> projections;
  double fd_norm = 0.0;           // ‖fd‖₂ per pixel.
  double adjoint_mismatch = 0.0;  // |δ·Jᵀw − Σ w·(Jδ)| / Σ|w·(Jδ)| for a random w.
  size_t jacobian_entries = 0;
  // Of the derivative render and the two finite-difference renders (RenderStats).
  int64_t nonfinite_samples = 0;
  int64_t nonfinite_outputs = 0;
};

struct GradcheckResult {
  std::string kind;
  int block = 1;      // the block side used.
  double step = 0.0;  // the finite-difference step used.
  std::vector<GradcheckViewResult> views;
  double relative_error = 0.0;        // over all views (block sums).
  double pixel_relative_error = 0.0;  // over all views, per pixel.
  double projection_error = 0.0;      // over all views' projections.
  int64_t nonfinite_samples = 0;      // over all views (RenderStats).
  int64_t nonfinite_outputs = 0;
  bool passed = false;
};

Status RunGradcheck(const Dataset& dataset, const TriMesh& mesh, const Material& material,
                    const GradcheckOptions& options, GradcheckResult* result);

// What a check and a consistency measurement (derivative_consistency.h) both start from: the
// derivative request of the options' kind (Jacobian rows, no adjoint weights), the dataset's
// per-view setups, the selected views and the block side (0 in the options = 8 for vertices
// and light positions, 1 otherwise).
struct GradcheckSetup {
  DerivativeRequest request;
  DatasetViews views;
  std::vector<int> selected;
  int block = 1;
};
// Checks `options` and fills `setup`; errors name the option.
Status PrepareGradcheck(const Dataset& dataset, const GradcheckOptions& options,
                        GradcheckSetup* setup);

// The direction δ of a check of `kind` (file comment): the smooth displacement field for
// vertices, uniform in [−1, 1] per parameter of the kind otherwise; zero elsewhere.
std::vector<double> GradcheckDirection(const RenderScene& scene, const ParameterLayout& layout,
                                       ParameterKind kind, uint64_t direction_seed);

// Σ_θ J_θ·δ_θ per pixel and channel (pixel-major, RGB) from a view's Jacobian rows.
std::vector<double> DirectionalDerivativeImage(const JacobianRows& rows,
                                               const std::vector<double>& delta);

// Sums a width × height × 3 image (pixel-major, RGB) over block × block tiles (partial tiles at
// the right and bottom borders).
std::vector<double> BlockSums(const std::vector<double>& image, int width, int height, int block);

// The displacement field of a vertex gradcheck (see the file comment): 3·positions.size()
// values, vertex v coordinate k at 3v + k, with max_v |δ(v)| = 1 (all zero when every position
// is the same point). Deterministic in `seed`. With `faces`, the field's frame (centre, size) is
// that of the vertices the faces use, so unreferenced vertices do not stretch it.
std::vector<double> SmoothDisplacementField(const std::vector<Eigen::Vector3d>& positions,
                                            uint64_t seed,
                                            const std::vector<Eigen::Vector3i>* faces = nullptr);

}  // namespace sft

#endif  // SFT_EVAL_GRADCHECK_H_
