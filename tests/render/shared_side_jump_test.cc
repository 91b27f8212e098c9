// The one-path estimate of a texel boundary's radiance jump (TraceSharedSideJump,
// src/render/internal/integrator.h) against the two-path estimate it replaces: two full paths,
// one per side, with the same random numbers. Both are unbiased for the same jump when the two
// sides are a side offset apart, so their means over many samplers must agree within their
// standard errors.
//
// Scene: a floor with a glossy checkerboard (albedo and roughness differ between texels) under a
// white ceiling, a point light and an environment with a bright patch, three path segments, so
// that the light samples, the MIS between BSDF and environment sampling, the bounce and the rest
// of the path all enter the jump. Tolerance: 4 combined standard errors per channel (a false
// failure about once in 10⁴ runs); the jump itself is required to exceed 10 standard errors, so
// that the comparison has something to compare.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "src/core/rng.h"
#include "src/geometry/material.h"
#include "src/render/environment.h"
#include "src/render/internal/context.h"
#include "src/render/internal/integrator.h"
#include "src/render/render.h"
#include "tests/testing/views.h"

namespace sft {
namespace render_internal {
namespace {

constexpr int kResolution = 4;

struct JumpScene {
  std::vector<Eigen::Vector3d> positions = {{-3, -3, 0},   {3, -3, 0},   {3, 3, 0},   {-3, 3, 0},
                                            {-3, -3, 1.2}, {3, -3, 1.2}, {3, 3, 1.2}, {-3, 3, 1.2}};
  std::vector<Eigen::Vector3i> faces = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}};
  RenderScene scene{positions, faces};
  Material material;
  EnvironmentMap environment;
  ViewSetup view;
  RenderOptions options;

  JumpScene() : environment(PatchImage(), Eigen::Matrix3d::Identity(), 1.0) {
    material = ConstantMaterial(4, Eigen::Vector3d::Constant(0.7), 0.5, 0.3, kResolution);
    for (int f = 0; f < 2; ++f) {  // the floor's checkerboard
      for (int i = 0; i <= kResolution; ++i) {
        for (int j = 0; i + j <= kResolution; ++j) {
          const int texel = f * MeshColors::TexelsPerFace(kResolution) +
                            MeshColors::LocalIndex(kResolution, i, j);
          const bool light = (i + j) % 2 == 0;
          double* albedo = material.albedo.texel(texel);
          albedo[0] = light ? 0.8 : 0.1;
          albedo[1] = light ? 0.6 : 0.3;
          albedo[2] = light ? 0.3 : 0.5;
          *material.roughness.texel(texel) = light ? 0.25 : 0.7;
        }
      }
    }
    view = testing::LookAtView(Eigen::Vector3d(0.4, -0.7, 0.9), Eigen::Vector3d(0.1, 0.2, 0), 64,
                               60.0);
    PointLight light;
    light.position = Eigen::Vector3d(-0.4, 0.3, 0.8);
    light.intensity = Eigen::Vector3d::Constant(0.5);
    view.point_lights.push_back(light);
    view.environment = &environment;
    options.bounces = 3;
  }

  // A dim environment with a bright patch (seen through the gap between floor and ceiling).
  static Image PatchImage() {
    Image image(32, 16, 3, 0.3f);
    for (int y = 6; y < 9; ++y) {
      for (int x = 4; x < 12; ++x) image.at(x, y, 0) = image.at(x, y, 1) = 6.f;
    }
    return image;
  }

  Context MakeContext() const {
    return Context{scene,        material,     material,        view, options,
                   &environment, &environment, options.bounces, 1.0,  nullptr,
                   nullptr,      nullptr,      nullptr};
  }

  Eigen::Vector3d Eye() const { return view.cam_from_world.Inverse().translation; }
};

// Two camera rays a side offset apart whose hits are on the same floor face in different texels.
bool FindBoundary(const JumpScene& s, Eigen::Vector3d dirs[2], RayHit hits[2]) {
  const Eigen::Vector3d eye = s.Eye();
  const Eigen::Vector3d from(-0.6, -0.3, 0), to(0.7, 0.5, 0);
  int previous_texel = -1;
  for (int k = 0; k <= 20000; ++k) {
    const Eigen::Vector3d target = from + (to - from) * (k / 20000.0);
    dirs[1] = (target - eye).normalized();
    hits[1] = s.scene.Intersect(eye, dirs[1], 0.0, kInfinity);
    if (!hits[1].hit || hits[1].face >= 2) return false;
    const int texel = s.material.albedo.TexelIndex(hits[1].face, hits[1].u, hits[1].v);
    if (previous_texel >= 0 && texel != previous_texel && hits[0].face == hits[1].face) {
      return true;
    }
    previous_texel = texel;
    dirs[0] = dirs[1];
    hits[0] = hits[1];
  }
  return false;
}

TEST(SharedSideJumpTest, AgreesWithTwoPathsInTheMean) {
  const JumpScene s;
  const Context ctx = s.MakeContext();
  Eigen::Vector3d dirs[2];
  RayHit hits[2];
  ASSERT_TRUE(FindBoundary(s, dirs, hits));
  constexpr int kSamples = 20000;
  Eigen::Vector3d sum[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  Eigen::Vector3d sum2[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  RenderStats stats;
  for (int i = 0; i < kSamples; ++i) {
    const Sampler sampler(7, 0, static_cast<uint64_t>(i), 0);
    Eigen::Vector3d shared;
    ASSERT_TRUE(TraceSharedSideJump(ctx, sampler, dirs, hits, &stats, &shared));
    Eigen::Vector3d two = Eigen::Vector3d::Zero();
    for (int k = 0; k < 2; ++k) {
      Sampler copy = sampler;
      two += (k == 0 ? 1.0 : -1.0) * TraceRadiance(ctx, &copy, dirs[k], hits[k], &stats, nullptr);
    }
    ASSERT_TRUE(shared.allFinite());
    sum[0] += shared;
    sum2[0] += shared.cwiseAbs2();
    sum[1] += two;
    sum2[1] += two.cwiseAbs2();
  }
  for (int c = 0; c < 3; ++c) {
    double mean[2], variance_of_mean[2];
    for (int e = 0; e < 2; ++e) {
      mean[e] = sum[e][c] / kSamples;
      variance_of_mean[e] = (sum2[e][c] / kSamples - mean[e] * mean[e]) / (kSamples - 1);
    }
    const double error = std::sqrt(variance_of_mean[0] + variance_of_mean[1]);
    EXPECT_GT(std::abs(mean[1]), 10.0 * error) << "channel " << c;
    EXPECT_NEAR(mean[0], mean[1], 4.0 * error) << "channel " << c;
  }
}

TEST(SharedSideJumpTest, DeclinesSidesItCannotShare) {
  const JumpScene s;
  const Context ctx = s.MakeContext();
  const Eigen::Vector3d eye = s.Eye();
  const Sampler sampler(7, 0, 0, 0);
  RenderStats stats;
  Eigen::Vector3d jump = Eigen::Vector3d::Constant(-1.0);
  Eigen::Vector3d dirs[2] = {(Eigen::Vector3d(0.1, 0.2, 0) - eye).normalized(),
                             (Eigen::Vector3d(0.1, 0.2, 1.2) - eye).normalized()};
  RayHit hits[2];
  for (int k = 0; k < 2; ++k) hits[k] = s.scene.Intersect(eye, dirs[k], 0.0, kInfinity);
  ASSERT_TRUE(hits[0].hit && hits[1].hit);
  // Floor and ceiling: opposite normals.
  EXPECT_FALSE(TraceSharedSideJump(ctx, sampler, dirs, hits, &stats, &jump));
  // A side that misses.
  hits[1].hit = false;
  EXPECT_FALSE(TraceSharedSideJump(ctx, sampler, dirs, hits, &stats, &jump));
  EXPECT_EQ(jump, Eigen::Vector3d::Constant(-1.0));  // nothing written.
}

}  // namespace
}  // namespace render_internal
}  // namespace sft
