// The small light fits shared by tests/optim/light_position_test.cc and light_direction_test.cc:
// a 6-view icosphere at 32² from `sft synth`, its true mesh and material, and the texture-phase
// options the fits run with.
#ifndef SFT_TESTS_TESTING_LIGHT_FITS_H_
#define SFT_TESTS_TESTING_LIGHT_FITS_H_

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/optim/parameters.h"
#include "src/optim/reconstruct.h"

namespace sft {
namespace testing {

// `sft synth` of the icosphere (6 views at 32², 64 spp, one segment, flat shading, albedo
// 0.6/0.5/0.4, roughness 0.4, specular 0.2) into `dir`, with `args` appended (e.g. the flash's
// offset); "" on success, else the output.
std::string SynthLightFitIcosphere(const std::string& dir, const std::string& args = "");

struct LightFit {
  Dataset dataset;
  TriMesh mesh;       // gt/mesh.ply
  Material material;  // gt/material.json: the fit starts at the true material.
  // Texture phases: LM, 3 outer iterations × 5 steps, 8 spp, one segment, flat shading, 3 pyramid
  // levels, albedo_smoothness 0.1 (the albedo is constant: texels seen by one view alone cannot
  // absorb the light's shading). The caller sets what is fitted.
  ReconstructOptions options;
};

// Reads the dataset at `dir` and its ground truth into *fit and sets the options; "" on success,
// else the error.
std::string ReadLightFit(const std::string& dir, LightFit* fit);

// Creates the reconstruction with the light positions / directions starting at `positions` /
// `directions` (empty: the dataset's) and runs its outer iterations; "" on success, else the
// error.
std::string RunLightFit(const LightFit& fit, const std::vector<Eigen::Vector3d>& positions,
                        const std::vector<Eigen::Vector3d>& directions,
                        std::unique_ptr<Reconstruction>* out);

// Writes a lights file (`sft-light-scales/1`) to `path` whose one entry is the dataset's first
// light with scale 1 and the JSON members `members` (e.g. `"position": [1, 2]`; empty: none),
// and returns the error of reading it for `dataset` with positions and directions ("" when it
// reads).
std::string LightsFileError(const std::string& path, const Dataset& dataset,
                            const std::string& members);

// The parameters the layout tests add light blocks to: three vertices, a constant material
// (resolution 1), two lights' scales and two views' gains, view 1's blue gain set to 1.5.
SceneParameters LayoutTestParameters();

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_LIGHT_FITS_H_
