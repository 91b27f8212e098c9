// Internal to src/render: the per-path bookkeeping of parameter derivatives (the "interior" terms
// of derivatives.h) and the per-pixel accumulator that sums them.
#ifndef SFT_RENDER_INTERNAL_PATH_DERIVATIVES_H_
#define SFT_RENDER_INTERNAL_PATH_DERIVATIVES_H_

#include <glog/logging.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "src/render/bsdf.h"
#include "src/render/derivatives.h"
#include "src/render/geometry_derivatives.h"
#include "src/render/internal/context.h"
#include "src/render/internal/shading_normal.h"

namespace sft {
namespace render_internal {

// (parameter, ∂RGB) pairs, in arrival order (edge terms of one pixel).
using DerivativeList = std::vector<std::pair<int, Eigen::Vector3d>>;

// Values summed per parameter as they arrive: an open-addressing hash table (linear probing,
// load ≤ 1/2) over the parameters touched so far. `Value` is Eigen::Vector3d (a pixel's ∂RGB) or
// double (adjoint terms w·∂RGB).
template <typename Value>
class ParamSums {
 public:
  ParamSums() { Resize(64); }

  void Add(int param, const Value& d) {
    uint32_t slot = Hash(param) & mask_;
    while (true) {
      const int key = keys_[slot];
      if (key == param) {
        values_[slot] += d;
        return;
      }
      if (key < 0) break;
      slot = (slot + 1) & mask_;
    }
    keys_[slot] = param;
    values_[slot] = d;
    used_.push_back(slot);
    if (2 * used_.size() > keys_.size()) Grow();
  }

  // The number of distinct parameters summed.
  size_t size() const { return used_.size(); }

  // Appends the (parameter, sum) pairs to *out in the order the parameters first arrived (a
  // deterministic order when the additions are), and empties the table.
  void MoveTo(std::vector<std::pair<int, Value>>* out) {
    out->reserve(out->size() + used_.size());
    for (const uint32_t slot : used_) {
      out->emplace_back(keys_[slot], values_[slot]);
      keys_[slot] = -1;
    }
    used_.clear();
  }

 protected:
  static uint32_t Hash(int param) { return static_cast<uint32_t>(param) * 2654435761u; }

  void Resize(size_t capacity) {
    keys_.assign(capacity, -1);
    values_.resize(capacity);
    mask_ = static_cast<uint32_t>(capacity - 1);
  }

  void Grow() {
    std::vector<std::pair<int, Value>> entries;
    MoveTo(&entries);
    Resize(2 * keys_.size());
    for (const auto& [param, d] : entries) Add(param, d);
  }

  std::vector<int> keys_;  // −1: empty.
  std::vector<Value> values_;
  std::vector<uint32_t> used_;  // occupied slots, in insertion order.
  uint32_t mask_ = 0;
};

// One pixel's derivatives, summed per parameter as they arrive. A pixel's paths touch the same
// few faces and texels over and over (every contribution re-emits the corners of the faces behind
// it), so summing on arrival keeps the work per entry O(1) and sorts only the distinct parameters.
class RowAccumulator : public ParamSums<Eigen::Vector3d> {
 public:
  // Writes the sums times `scale`, sorted by parameter, and empties the table. A sum that is not
  // finite or whose product with `scale` overflows float is dropped and counted in
  // *dropped.
  void Flush(double scale, std::vector<JacobianEntry>* merged, int64_t* dropped) {
    merged->clear();
    std::sort(used_.begin(), used_.end(),
              [this](uint32_t a, uint32_t b) { return keys_[a] < keys_[b]; });
    for (const uint32_t slot : used_) {
      const Eigen::Vector3d& sum = values_[slot];
      const JacobianEntry entry{
          keys_[slot],
          {static_cast<float>(sum[0] * scale), static_cast<float>(sum[1] * scale),
           static_cast<float>(sum[2] * scale)}};
      if (std::isfinite(entry.d[0]) && std::isfinite(entry.d[1]) && std::isfinite(entry.d[2])) {
        merged->push_back(entry);
      } else {
        ++*dropped;
      }
      keys_[slot] = -1;
    }
    used_.clear();
  }
};

// The light term Q of a contribution, split as Q = q·c with c the part that depends on the
// geometry of the shading point: point light q = I, c = (n·wi)/d² (wi and d follow the point x);
// directional light q = E, c = n·wi (wi fixed); environment (light- or BSDF-sampled, direction
// fixed) q = L·scale·w_MIS/pdf, c = n·wi.
struct LightTerm {
  Eigen::Vector3d q;
  double c = 0.0;
  Eigen::Vector3d dc_dn = Eigen::Vector3d::Zero();
  bool follows_point = false;                        // point light: the next three are set.
  Eigen::Vector3d dc_dx = Eigen::Vector3d::Zero();   // ∂c/∂x = (3(n·wi)wi − n)/d³.
  Eigen::Matrix3d dwi_dx = Eigen::Matrix3d::Zero();  // ∂wi/∂x = −(I − wi wiᵀ)/d.
  // A point light whose position is a parameter (ParameterLayout::FitsLightPosition): the first
  // of its three parameters, and ∂L/∂(parameters) — I for a world-frame light, Rᵀ (world from
  // camera) for a camera-frame one. c and wi depend on L − x only, so ∂/∂L = −∂/∂x.
  int position_param = -1;
  Eigen::Matrix3d d_light_d_param = Eigen::Matrix3d::Identity();
  // A directional light whose direction is a parameter (ParameterLayout::FitsLightDirection): the
  // first of its three parameters and ∂d/∂(parameters) (LightDirectionJacobian); wi = −d, and c
  // = n·wi and the BSDF depend on it.
  int direction_param = -1;
  Eigen::Matrix3d d_direction_d_param = Eigen::Matrix3d::Zero();
  // A fitted environment's term (ParameterLayout::FitsEnvironment): q's channel c is
  // Σ_k env_weight[k]·T_kc over the env_count texels T_k it blends, so ∂q_c/∂T_kc = env_weight[k]
  // (the bilinear weight times the map's and the light's scales, the MIS weight and 1/pdf).
  int env_count = 0;
  int env_texel[4] = {0, 0, 0, 0};
  double env_weight[4] = {0.0, 0.0, 0.0, 0.0};
  // An environment whose rotation is a parameter (ParameterLayout::FitsEnvironmentRotation): the
  // first of its three parameters and ∂q/∂(parameters) (rows: channels; the map's
  // RotationJacobian times the factor in q and ViewSetup::environment_rotation_jacobian).
  int env_rotation_param = -1;
  Eigen::Matrix3d dq_d_rotation = Eigen::Matrix3d::Zero();
};

// Bookkeeping of one path's derivatives. A path's light contributions have the form
//   C = (s_0 ⊙ … ⊙ s_{i−1}) ⊙ f_i(wo_i, wi) ⊙ Q,
// with s_k = f_k(wo_k, wi_k)·|n·wi_k|/pdf_k the scatter factor of vertex k (pdf detached) and Q
// the light term. ∂C/∂θ for a parameter of vertex j < i replaces s_j by ∂s_j/∂θ; for vertex i it
// replaces f_i by ∂f_i/∂θ. `excluded_[j]` keeps Π_{k<i, k≠j} s_k so that no division by a
// possibly zero factor is needed.
//
// Vertex coordinates enter (directions detached, so wo and sampled wi stay fixed) through the
// shading normal n_k of every vertex (ShadingNormalChain) — s_k, f_i and c depend on it — and, for
// point lights, through the position x_i (wi = (L − x_i)/d, c), which moves with the faces hit
// before (PointJacobian). Texel lookups are piecewise constant and contribute nothing.
class PathDerivatives {
 public:
  explicit PathDerivatives(const Context& ctx)
      : ctx_(ctx), vertices_(ctx.request->params.vertices) {}

  // Starts a new path (camera sample) whose derivatives go to `out` once committed. (One object
  // serves many paths: its per-scatter storage is large and needs no initialization.) With
  // `boundary_out` (the adjoint pass's secondary-edge part, DerivativeRequest::gradient_parts),
  // the boundary terms (AddBoundary) also go there as boundary_weight·∂RGB.
  void Reset(RowAccumulator* out, ParamSums<double>* boundary_out = nullptr,
             const Eigen::Vector3d& boundary_weight = Eigen::Vector3d::Zero()) {
    out_ = out;
    boundary_out_ = boundary_out;
    boundary_weight_ = boundary_weight;
    pending_.clear();
    boundary_ranges_.clear();
    count_ = 0;
    point_.count = 0;
    point_.valid = true;
  }

  // Adds one derivative term of the path: ∂(path's radiance)/∂(parameter `param`).
  void Add(int param, const Eigen::Vector3d& d) { pending_.emplace_back(param, d); }

  // Adds base_c·weight[k] to environment texel texel[k]'s channel c, for each k < count: the
  // terms of a fitted environment's radiance Σ_k weight[k]·T_k seen with factor `base`.
  void AddEnvironmentTexels(const int* texel, const double* weight, int count,
                            const Eigen::Vector3d& base);

  // Whether every term added since Reset is finite.
  bool Finite() const {
    for (const auto& term : pending_) {
      if (!term.second.allFinite()) return false;
    }
    return true;
  }
  // Adds the path's terms to the accumulator, in the order they were added (so the sums are
  // the same as if they had been added directly).
  void Commit() {
    for (const auto& [param, d] : pending_) out_->Add(param, d);
    if (boundary_out_ != nullptr) {
      for (const auto& [first, last] : boundary_ranges_) {
        for (size_t i = first; i < last; ++i) {
          const double g = boundary_weight_.dot(pending_[i].second);
          if (g != 0.0) boundary_out_->Add(pending_[i].first, g);
        }
      }
    }
    pending_.clear();
    boundary_ranges_.clear();
  }

  // The path reached a new vertex on face `face` (hit barycentrics `barycentrics`, ray direction
  // `dir`), shaded with sign times its flat or smooth normal (ctx.options.shading).
  // `track_point`: keep x's Jacobian (point lights or edge terms need it; smooth shading always
  // does).
  void SetVertex(int face, const Eigen::Vector3d& barycentrics, const Eigen::Vector3d& dir,
                 double sign, bool track_point);

  // A light contribution f ⊙ (q·c) at the current vertex (index = number of scatters so far),
  // with shading normal n and directions wo, wi.
  void AddContribution(const Eigen::Vector3d& prefix, const SurfaceMaterial& surface,
                       const Eigen::Vector3d& n, const Eigen::Vector3d& wo,
                       const Eigen::Vector3d& wi, const Eigen::Vector3d& f, const LightTerm& light,
                       int light_index);

  // A boundary (edge) term at the current vertex: Σ_j weight·(rows_j·∂y/∂p_{vertices_j}) for
  // the vertices that move the curve point, plus weight·(x_row·∂x/∂θ) for the motion of the
  // vertex itself (chained to the faces hit before; left out when that chain is undefined after
  // a grazing hit), plus, with light_param ≥ 0, weight·light_row_k for the point light's
  // position parameter light_param + k (a shadow boundary moving with the light). The vertex
  // terms are added only with vertex derivatives. Non-finite values are added as such (the
  // sample is then dropped).
  void AddBoundary(const Eigen::Vector3d& weight, const int* vertices, const Eigen::Vector3d* rows,
                   int count, const Eigen::Vector3d& x_row, int light_param = -1,
                   const Eigen::Vector3d& light_row = Eigen::Vector3d::Zero());

  // The path continues from the current vertex with scatter factor s = f·(n·wi)/pdf.
  void AddScatter(const Eigen::Vector3d& prefix, const SurfaceMaterial& surface,
                  const Eigen::Vector3d& n, const Eigen::Vector3d& wo, const Eigen::Vector3d& wi,
                  const Eigen::Vector3d& f, double pdf);

 private:
  struct Scatter {
    SurfaceMaterial surface;
    BsdfDerivatives d_s;
    VertexGradients ds_dvertices;  // ∂s/∂(vertex coordinates), rows = channels.
  };

  void Emit(int param, const Eigen::Vector3d& d) {
    if (d[0] != 0.0 || d[1] != 0.0 || d[2] != 0.0) Add(param, d);
  }
  // Emits g for every (vertex, g) of `gradients`.
  void AddVertices(const VertexGradients& gradients) {
    for (const auto& [vertex, g] : gradients) {
      for (int k = 0; k < 3; ++k) Emit(3 * vertex + k, g.col(k));
    }
  }
  // Emits weight ⊙ g for every (vertex, g) of `gradients` (weight: per channel).
  void AddVertices(const VertexGradients& gradients, const Eigen::Vector3d& weight) {
    for (const auto& [vertex, g] : gradients) {
      const Eigen::Matrix3d wg = weight.asDiagonal() * g;
      for (int k = 0; k < 3; ++k) Emit(3 * vertex + k, wg.col(k));
    }
  }

  // UV textures: ∂(factor)/∂δ (rows: channels) of a BSDF factor with derivatives `d` as the
  // texture slides under the hit (SurfaceMaterial::slides; δ = dx − Σ_j b_j·dp_j).
  static Eigen::Matrix3d MaterialSlide(const SurfaceMaterial& surface, const BsdfDerivatives& d);
  // Appends g·∂δ/∂(vertex coordinates) of the current vertex to *out (nothing when its point
  // Jacobian is undefined).
  void MapSlide(const Eigen::Matrix3d& g, VertexGradients* out) const;

  // Adds base ⊙ ∂(factor)/∂θ for the material parameters of `surface`, where ∂factor/∂θ is
  // described by `d` (albedo: own channel only; roughness and specular: all channels).
  void AddMaterial(const SurfaceMaterial& surface, const BsdfDerivatives& d,
                   const Eigen::Vector3d& base);

  // A path scatters at most bounces − 1 ≤ 15 times (RenderOptions::Check caps bounces at 16).
  static constexpr int kMaxScatters = 16;
  const Context& ctx_;
  RowAccumulator* out_ = nullptr;
  DerivativeList pending_;  // the current path's terms, until Commit.
  // Reset's boundary_out and its weight; the ranges of pending_ that AddBoundary added (only
  // recorded when boundary_out_ is set).
  ParamSums<double>* boundary_out_ = nullptr;
  Eigen::Vector3d boundary_weight_ = Eigen::Vector3d::Zero();
  std::vector<std::pair<size_t, size_t>> boundary_ranges_;
  const bool vertices_;
  int count_ = 0;
  Scatter scatters_[kMaxScatters];
  std::array<Eigen::Vector3d, kMaxScatters> excluded_;
  // The current vertex's normal chain and its position's Jacobian.
  ShadingNormalChain normal_;
  PointJacobian point_;
  Eigen::Vector3i corners_ = Eigen::Vector3i::Zero();       // the current vertex's face corners
  Eigen::Vector3d barycentrics_ = Eigen::Vector3d::Zero();  // and barycentrics.
  VertexGradients scratch_;  // the current contribution's normal terms.
};

}  // namespace render_internal
}  // namespace sft

#endif  // SFT_RENDER_INTERNAL_PATH_DERIVATIVES_H_
