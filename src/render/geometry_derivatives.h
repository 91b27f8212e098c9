// Building blocks of vertex derivatives: how a face's unit normal and a ray's hit point move when
// the face's vertices (and the ray's origin) move, with the ray's direction held fixed ("detached"
// sampling, see derivatives.h).
//
// Conventions: a face has corners p0, p1, p2 (counter-clockwise = front), edges e1 = p1 − p0,
// e2 = p2 − p0, N = e1 × e2 and unit normal n̂ = N/|N|; the renderer shades with n = σ·n̂,
// σ = ±1 flipping n̂ towards the viewer. Gradients are row vectors stored as Eigen matrices with
// one row per colour channel.
#ifndef SFT_RENDER_GEOMETRY_DERIVATIVES_H_
#define SFT_RENDER_GEOMETRY_DERIVATIVES_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace sft {

// Maps gradients with respect to the (flipped) unit normal n = σ·n̂ of a face to gradients with
// respect to its 9 corner coordinates (column 3·corner + k). With ĝ = σ(I − n̂n̂ᵀ)g/|N| (the
// normalisation's Jacobian), g·dn = ĝ·dN and dN = de1 × e2 + e1 × de2, so
//   ∂/∂p1 = e2 × ĝ,  ∂/∂p2 = ĝ × e1,  ∂/∂p0 = (e1 − e2) × ĝ  (they sum to zero: translation
// does not turn a face). A degenerate face (|N| = 0) has no normal; it is never shaded.
class NormalChain {
 public:
  NormalChain() = default;
  NormalChain(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
              double sign);

  // g: 3 rows (channels) × 3 (∂/∂n). Returns 3 rows × 9 (∂/∂corner coordinates).
  Eigen::Matrix<double, 3, 9> Map(const Eigen::Matrix3d& g) const;
  const Eigen::Vector3d& unit_normal() const { return unit_normal_; }  // n̂ (unflipped).

 private:
  Eigen::Vector3d e1_ = Eigen::Vector3d::Zero(), e2_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d unit_normal_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d projection_ = Eigen::Matrix3d::Zero();  // σ(I − n̂n̂ᵀ)/|N|.
};

// Derivatives of the point x where the ray o + t·d (d fixed) meets the plane of a face with
// unit normal n̂, the hit having barycentrics (b0, b1, b2) (x = Σ b_j p_j). Moving the plane by
// δ along n̂ at x moves the hit by δ/(n̂·d) along d (Li et al. 2018, the implicit function
// theorem on n̂·(x − p0) = 0), so
//   ∂x/∂p_j = b_j · d n̂ᵀ/(n̂·d),   ∂x/∂o = I − d n̂ᵀ/(n̂·d).
// Both grow like 1/cos of the ray's incidence angle: at grazing incidence (|n̂·d| below
// kMinHitCosine·|d|) the hit point has no usable derivative and Compute returns false.
constexpr double kMinHitCosine = 1e-6;
bool HitPointDerivatives(const Eigen::Vector3d& d, const Eigen::Vector3d& unit_normal,
                         const Eigen::Vector3d& barycentrics,
                         std::array<Eigen::Matrix3d, 3>* d_x_d_p, Eigen::Matrix3d* d_x_d_o);

// The vertex Jacobian of a path vertex position x: dx = Σ_e m_e · d(vertex[e]), over the
// corners of every face the path hit so far (duplicates allowed; they are merged downstream).
struct PointJacobian {
  static constexpr int kMaxEntries = 3 * 17;
  int count = 0;
  bool valid = true;  // false once a grazing hit made the chain undefined.
  std::array<int, kMaxEntries> vertex;
  std::array<Eigen::Matrix3d, kMaxEntries> m;

  // The next hit: x' = hit of the ray from x (this Jacobian, or a fixed origin when
  // `fixed_origin`) along d on the given face.
  void Advance(bool fixed_origin, const Eigen::Vector3d& d, const Eigen::Vector3d& unit_normal,
               const Eigen::Vector3d& barycentrics, const Eigen::Vector3i& face_vertices);
};

}  // namespace sft

#endif  // SFT_RENDER_GEOMETRY_DERIVATIVES_H_
