// A scene shared by the light-derivative tests: a glossy-lit cube throwing its shadow onto a
// ground quad in view (tests/render/light_position_derivatives_test.cc,
// light_direction_derivatives_test.cc).
#ifndef SFT_TESTS_TESTING_SHADOW_SCENES_H_
#define SFT_TESTS_TESTING_SHADOW_SCENES_H_

#include <memory>

#include "src/geometry/material.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/meshes.h"

namespace sft {
namespace testing {

// The cube (half-size 0.25, centred at (0, 0, 0.5), turned to a generic orientation) above a
// 12 × 12 ground, the camera at (0.5, −2, 2) looking at (0, 0.3, 0.2), res × res pixels. No
// lights.
struct CubeOverGround {
  explicit CubeOverGround(int res);

  // The light tests' glossy material: albedo 0.7/0.6/0.5, roughness 0.4, specular 0.3.
  Material GlossyMaterial() const;
  // Their render options: `spp`, `bounces`, shadows on or off, no environment, seed 5, paths
  // sampled with `sampling` (detached sampling: nearby lights follow the same paths).
  static RenderOptions Options(int spp, int bounces, bool shadows, const Material* sampling);

  Triangles geometry;
  ViewSetup view;
  std::unique_ptr<RenderScene> scene;
};

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_SHADOW_SCENES_H_
