// The fitted lights of a reconstruction (`OUT/lights.json`), so that a re-render reproduces the
// fit: {"format": "sft-light-scales/1", "lights": [{"id": ID, "scale": s}, ...]}, one entry per
// dataset light in dataset order (matched by id on reading). A point light's intensity, a
// directional light's irradiance or an environment light's scale is multiplied by s. When the run
// fitted point-light positions
// (`fit_light_positions`), each point light's entry also has "frame" ("world" or "camera", the
// dataset light's) and "position" [x, y, z]: the fitted position in that frame, which replaces
// the dataset's. Likewise with fitted directional-light directions (`fit_light_directions`): each
// directional light's entry has "frame" and "direction" [x, y, z], the unit direction the light
// travels in that frame. With fitted probe rotations (`fit_environment_rotation`) each
// environment light's entry has "frame" and "rotation" [x, y, z]: the rotation vector θ (radians,
// axis·angle, in that frame) that turns the probe as world_from_env ← exp([θ]×)·world_from_env
// (camera-fixed: cam_from_env ← exp([θ]×)·cam_from_env). Readers that do not know these keys
// ignore them (the format name stays).
#ifndef SFT_IO_LIGHT_SCALES_H_
#define SFT_IO_LIGHT_SCALES_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/io/dataset.h"

namespace sft {

// `positions`: empty, or one per dataset light (each point light's in its frame; the entries of
// other lights are not written). `directions` the same for directional lights (normalized on
// writing), `rotations` for environment lights.
Status WriteLightScales(const std::string& path, const Dataset& dataset,
                        const std::vector<double>& scales,
                        const std::vector<Eigen::Vector3d>& positions = {},
                        const std::vector<Eigen::Vector3d>& directions = {},
                        const std::vector<Eigen::Vector3d>& rotations = {});
// Reads scales for `dataset`'s lights (every dataset light must be listed, by id; scales finite
// and > 0). With `positions`: empty when no entry has a position, else one per dataset light,
// the file's where it has one (a point light's only, its frame must be the dataset light's) and
// the dataset's elsewhere. The same with `directions` for directional lights' "direction" and
// `rotations` for environment lights' "rotation" (0 where the file has none). Errors name the
// file and the entry.
Status ReadLightScales(const std::string& path, const Dataset& dataset, std::vector<double>* scales,
                       std::vector<Eigen::Vector3d>* positions = nullptr,
                       std::vector<Eigen::Vector3d>* directions = nullptr,
                       std::vector<Eigen::Vector3d>* rotations = nullptr);
// Multiplies the dataset's light intensities (point), irradiances (directional) and scales
// (environment) by `scales`.
void ApplyLightScales(const std::vector<double>& scales, Dataset* dataset);
// Sets the dataset's point-light positions (in their frames) to `positions` (empty: no change).
void ApplyLightPositions(const std::vector<Eigen::Vector3d>& positions, Dataset* dataset);
// Sets the dataset's directional-light directions (in their frames, normalized) to `directions`
// (empty: no change).
void ApplyLightDirections(const std::vector<Eigen::Vector3d>& directions, Dataset* dataset);
// Turns the dataset's environment lights by `rotations` (rotation vectors in their frames:
// world_from_env ← exp([θ]×)·world_from_env; empty: no change).
void ApplyEnvironmentRotations(const std::vector<Eigen::Vector3d>& rotations, Dataset* dataset);
// Reads lights file `path` (ReadLightScales) and applies its scales, positions, directions and
// rotations to the dataset's lights: renders then reproduce the fit.
Status ApplyLightsFile(const std::string& path, Dataset* dataset);

}  // namespace sft

#endif  // SFT_IO_LIGHT_SCALES_H_
