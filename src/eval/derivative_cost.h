// The cost of the renderer's derivatives (`sft bench gradient`, issue 3 item 6): in one run on the
// same scene, the wall-clock time over all views of
//   (1) the forward render alone (RenderView),
//   (2) forward + sparse Jacobian rows (RenderViewWithDerivatives, jacobian_rows) for every
//       parameter kind — vertex coordinates (interior terms and edge sampling at the default
//       DerivativeRequest edge ratios), albedo, roughness, specular, light scales,
//   (3) forward + adjoint gradient of the same kinds (adjoint_weights only; the weights are a
//       fixed random image),
// each at the same spp, bounces, seed and thread count, with the ratio of (2) and (3) to (1)
// (the aim: ≤ 3), the number of Jacobian entries and the memory of the rows.
//
// Scene: `views` pinhole cameras (40° field of view) on a Fibonacci sphere around the mesh's
// bounding-box centre (world +z up), at the distance where the bounding sphere fills 60% of the
// half image, each with a camera-attached point light as `sft synth` places it (offset 0.15 of the
// bounding-box diagonal along the camera's +x, intensity 0.5π·distance²); a material with random
// per-texel albedo in [0.2, 0.9] (mesh colors resolution 2), roughness 0.4, specular 0.3.
//
// Memory: the rows of a view are freed before the next view is rendered unless keep_rows is set,
// in which case every view's rows stay alive until the end of the pass (the resident total is
// then the sum). The process's peak resident set (Linux /proc; reset before each pass when the
// kernel allows it) is reported per pass as well, since building the rows needs transient
// per-pixel buffers beyond the final rows.
#ifndef SFT_EVAL_DERIVATIVE_COST_H_
#define SFT_EVAL_DERIVATIVE_COST_H_

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"

namespace sft {

struct DerivativeCostOptions {
  int views = 64;          // cameras on the Fibonacci sphere, in [1, 10000].
  int resolution = 128;    // image width = height in pixels, in [1, 4096].
  int spp = 16;            // samples per pixel of every pass, as RenderOptions::spp.
  int bounces = 2;         // path segments of every pass, as RenderOptions::bounces.
  int threads = 0;         // renderer threads; 0 = all cores.
  uint64_t seed = 0;       // sample seed of every pass; also seeds the albedo and the weights.
  bool keep_rows = false;  // hold every view's Jacobian rows until the end of the rows pass.
  bool progress = false;   // print a progress line per pass on stderr.
  // Seeds of the noise measurement, 0 (off) or in [2, 64]: the adjoint pass is repeated with
  // render seeds seed + 1 … seed + noise_seeds (same weights) and the seed-to-seed spread of the
  // vertex part of Σ_views Jᵀw is reported (DerivativeCostReport::vertex_noise).
  int noise_seeds = 0;
  // Edge-sampling budgets of both derivative passes (DerivativeRequest defaults unless changed);
  // its parameter selection and outputs are set by the benchmark.
  DerivativeRequest derivatives;

  bool Check(std::string* why) const;
};

// One pass over all views.
struct DerivativePassCost {
  double seconds = 0.0;          // wall clock of the render calls, summed over the views.
  double ratio = 0.0;            // seconds / the forward pass's seconds.
  RenderStats rays;              // ray counts summed over the views (seconds = the renderer's own).
  int64_t rss_before_bytes = 0;  // process resident set before the pass; 0 when unknown.
  int64_t peak_rss_bytes = 0;    // process peak resident set during the pass; 0 when unknown.
};

struct DerivativeCostReport {
  int num_faces = 0;
  int num_vertices = 0;
  int threads = 0;  // actual thread count (0 in the options resolved to the core count).
  int views = 0, width = 0, height = 0, spp = 0, bounces = 0;
  bool keep_rows = false;
  DerivativeRequest derivatives;  // the edge budgets used (outputs unset).
  bool peak_rss_reset = false;    // the kernel let us reset the peak before each pass.
  int num_parameters = 0;         // the full index space (ParameterLayout::size()).
  int num_differentiated = 0;  // of those, the differentiated ones (all kinds: = num_parameters).
  int64_t covered_pixels = 0;  // pixels with coverage > 0, summed over the views.

  DerivativePassCost forward;        // RenderView.
  DerivativePassCost jacobian_rows;  // + Jacobian rows (vertices, albedo, roughness, specular,
                                     // lights).
  DerivativePassCost adjoint;        // + adjoint gradient.

  int64_t jacobian_entries = 0;      // Σ over views of rows.entries.size().
  int64_t rows_bytes_total = 0;      // Σ over views of JacobianRows::MemoryBytes().
  int64_t rows_bytes_peak_view = 0;  // max over views of MemoryBytes().
  int64_t rows_bytes_resident = 0;   // the most rows memory alive at once: the peak view, or the
                                     // total with keep_rows.
  // Adjoint terms held before their reduction into the gradient (RenderStats::gradient_terms):
  // summed over the views, and the largest view's.
  int64_t gradient_terms = 0;
  int64_t gradient_terms_peak_view = 0;
  double gradient_norm = 0.0;  // ‖Σ_views Jᵀw‖₂ of the adjoint pass (a sanity value).

  // With noise_seeds: the vertex gradient's noise √(T/S) over the N seeds' vertex gradients g_k,
  // T = Σ_k ‖g_k − ḡ‖²/(N − 1) (the trace of one seed's covariance) and S = ‖ḡ‖² − T/N (the
  // unbiased estimate of ‖E g‖²; 0 when that is not positive), the mean seconds of those adjoint
  // passes and of a forward pass run with each seed between them, and the efficiency
  // (mean adjoint seconds / mean forward seconds) × noise²: the
  // time, in forward passes, to reach unit relative variance (lower is better; halving it halves
  // the time to reach any given noise).
  int noise_seeds = 0;
  double vertex_noise = 0.0;
  double noise_adjoint_seconds = 0.0;
  double noise_forward_seconds = 0.0;
  double cost_times_variance = 0.0;
};

// Runs the three passes on `mesh` (see the file comment). Errors: invalid options, a mesh without
// faces or with zero extent.
Status MeasureDerivativeCost(const DerivativeCostOptions& options, const TriMesh& mesh,
                             DerivativeCostReport* report);

// The same three passes on a dataset's own cameras, lights and views (`view_indices`; empty = all),
// with `mesh` and `material` (`sft bench gradient --dataset`); options.views and resolution are
// not used, width and height in the report are the first view's. Errors: invalid options, a mesh
// without faces, a view index out of range, unreadable environment maps.
Status MeasureDatasetDerivativeCost(const DerivativeCostOptions& options, const Dataset& dataset,
                                    const std::vector<int>& view_indices, const TriMesh& mesh,
                                    const Material& material, DerivativeCostReport* report);

// The report as JSON (bytes, seconds) and as a small human-readable table (MiB, s).
nlohmann::json DerivativeCostReportToJson(const DerivativeCostReport& report);
std::string DerivativeCostReportTable(const DerivativeCostReport& report);

}  // namespace sft

#endif  // SFT_EVAL_DERIVATIVE_COST_H_
