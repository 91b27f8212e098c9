// Camera pose refinement (docs/reconstruct.md, "Camera poses"): a correction δ = (ω, τ) per fitted
// view, ω a rotation vector (radians) and τ a translation (scene units), both in the camera frame
// and applied on the left of the dataset's pose:
//   cam_from_world' = exp(δ)·cam_from_world,  i.e.  p_cam' = exp([ω]×)·p_cam + τ.
// δ = 0 is the dataset's pose. The renderer knows nothing of δ: a view renders at its corrected
// pose (ApplyPoseCorrection), and the rows of δ come from the chain rule. Moving the camera is
// moving the scene rigidly the other way relative to it, so with the camera held at its corrected
// pose (R', t') a change dδ moves every world-fixed point x (vertices, world-frame point lights) by
//   dx = R'ᵀ(−[q]×·J_l(ω)·dω + dτ),  q = exp([ω]×)·p_cam = R'x + t' − τ,
// (J_l the left Jacobian of SO(3): exp([ω + dω]×) = exp([J_l(ω)dω]×)·exp([ω]×) to first order),
// turns world-frame directional lights' direction parameters v by dv = −[v]×·R'ᵀJ_l(ω)·dω, and
// turns a world-fixed probe by the world rotation b = R'ᵀJ_l(ω)·dω, i.e. its rotation parameter θ
// by dθ = J⁻¹·b (J = ViewSetup::environment_rotation_jacobian). Camera-frame lights (a flash) ride
// with the camera and do not move relative to it. So ∂I/∂δ = Σ ∂I/∂x·∂x/∂δ over those parameters:
// the renderer's rows (or adjoint gradient) of vertices, light positions, light directions and
// environment rotations — edge terms included — contracted with the matrices above (PoseChain).
// A fitted world-fixed environment (unknown lighting) takes a probe's route: its rotation
// parameter, held at 0, carries the chain. A camera-fixed probe or fitted map would have to be
// turned with every pose change; they are not supported.
#ifndef SFT_OPTIM_POSE_CORRECTIONS_H_
#define SFT_OPTIM_POSE_CORRECTIONS_H_

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "cost_functions/pyramid_pixel.h"
#include "src/core/status.h"
#include "src/render/camera.h"
#include "src/render/derivatives.h"
#include "src/render/render.h"

namespace sft {

// (ω, τ): rotation vector (radians), then translation (scene units), both in the camera frame.
using PoseDelta = Eigen::Matrix<double, 6, 1>;

// The gauge of the poses: moving the whole scene and every camera rigidly changes no image, so the
// pose of fitted view 0 — the lowest dataset index fitted — is never corrected; every other
// correction is relative to it (docs/reconstruct.md, "Camera poses").
constexpr int kPoseGaugeView = 0;

// exp(δ)·cam_from_world (above).
Rigid3d CorrectedCamFromWorld(const Rigid3d& cam_from_world, const PoseDelta& delta);

// Moves `view` (set up at the dataset's pose) to its corrected pose: its camera, and the
// camera-frame point and directional lights with it. The view must have no camera-fixed
// environment (those are rejected before a fit starts).
void ApplyPoseCorrection(const PoseDelta& delta, ViewSetup* view);

// The parameters the chain needs from the renderer, added to `selection`.
void AddPoseChainSelection(ParameterSelection* selection);

// ∂(scene parameter)/∂δ of one view at its corrected pose (the header's chain), for every renderer
// parameter that moves with the scene relative to the camera.
class PoseChain {
 public:
  PoseChain() = default;  // moves nothing.
  // `view` is the view as rendered (ApplyPoseCorrection done, and its probe's rotation Jacobian
  // set); `delta` its correction; `positions` the vertices; `light_directions` the direction
  // parameters v per dataset light (empty when they are not parameters).
  PoseChain(const ParameterLayout& layout, const ViewSetup& view, const PoseDelta& delta,
            const std::vector<Eigen::Vector3d>& positions,
            const std::vector<Eigen::Vector3d>& light_directions);

  // ∂(parameter `param`)/∂δ as a row (1 × 6); null when the parameter does not move with δ.
  const Eigen::Matrix<double, 1, 6>* Derivative(int param) const;

  // Σ_param gradient[param]·∂param/∂δ over a layout-size gradient.
  PoseDelta Contract(const std::vector<double>& gradient) const;

 private:
  // ∂x/∂δ (3 × 6) of a world-fixed point x, and of a world-fixed direction parameter v.
  Eigen::Matrix<double, 3, 6> PointJacobian(const Eigen::Vector3d& x) const;

  int light_offset_ = 0;            // the layout's LightPositionOffset(): start of light_rows_.
  Eigen::Matrix3d world_from_cam_;  // R'ᵀ.
  Eigen::Matrix3d left_;            // J_l(ω).
  Eigen::Vector3d translation_;     // t' − τ.
  Eigen::Matrix3d rotation_;        // R'.
  std::vector<Eigen::Matrix<double, 1, 6>> vertex_rows_;  // 3 per vertex.
  std::vector<Eigen::Matrix<double, 1, 6>> light_rows_;   // from light_offset_ to the layout's end.
  std::vector<bool> light_moves_;                         // whether light_rows_[k] is set.
};

// `rows` (one view's, all renderer parameters) with six entries ∂I/∂δ per pixel appended at
// pose_offset .. pose_offset + 5 (zero entries left out), and the entries whose parameter `keep`
// rejects dropped. The appended indices must exceed every kept one (the poses are the last
// parameters), so each pixel's entries stay sorted.
LevelRows PoseRows(const LevelRows& rows, const PoseChain& chain, int pose_offset,
                   const std::function<bool(int)>& keep);

// poses.json (format sft-poses/1): {"format": "sft-poses/1", "gauge_view": G, "views": [{"view":
// i, "image": name, "rotation": [ωx, ωy, ωz], "translation": [τx, τy, τz], "cam_from_world":
// {"rotation": [w, x, y, z], "translation": [tx, ty, tz]}}, ...]}, one entry per dataset view with
// a correction (corrections: one per dataset view, zero = none; `images` their names, may be
// empty). cam_from_world is the corrected pose, for reading by other tools; reading uses δ.
std::string PosesJson(const std::vector<PoseDelta>& corrections,
                      const std::vector<Rigid3d>& cam_from_world,
                      const std::vector<std::string>& images, int gauge_view);
// Parses poses.json text into one correction per dataset view (views not listed: zero). Errors
// name the field; `num_views` is the dataset's view count.
Status ParsePosesJson(const std::string& text, int num_views, std::vector<PoseDelta>* corrections);

}  // namespace sft

#endif  // SFT_OPTIM_POSE_CORRECTIONS_H_
