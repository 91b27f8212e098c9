// Fitted directional-light directions (`fit_light_directions`; issue 22): the parameter layout
// beside light positions, lights.json with directions (written, read back, refused
// when malformed), and fits on a small synthetic dataset where the light starts 10° off.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "src/core/file_util.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "src/io/light_scales.h"
#include "src/optim/parameters.h"
#include "src/optim/reconstruct.h"
#include "tests/testing/light_fits.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// The true light: travelling down and across the object (bounding-box diagonal 1, centred at 0).
const Eigen::Vector3d kTrueTravel = Eigen::Vector3d(-0.5, 0.4, -0.77).normalized();

double AngleDegrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

TEST(LightDirectionParametersTest, LayoutBlocksAndValues) {
  SceneParameters params = testing::LayoutTestParameters();
  const int size = params.size();
  EXPECT_TRUE(params.LightDirections().empty());
  params.AddLightDirections({{0, 0, -1}, {0.6, 0, 0.8}});
  // Positions added later go before the directions; the directions keep their values.
  params.AddLightPositions({{0.1, 0.2, 0.3}, {4, 5, 6}});
  const ParameterLayout& layout = params.layout();
  ASSERT_TRUE(layout.light_directions);
  EXPECT_EQ(params.size(), size + 12);
  EXPECT_EQ(layout.LightDirectionOffset(), layout.LightPositionOffset() + 6);
  EXPECT_EQ(layout.KindOf(layout.LightDirectionOffset() + 3), ParameterKind::kLightDirection);
  EXPECT_EQ(layout.KindOf(layout.LightDirectionOffset() - 1), ParameterKind::kLightPosition);
  EXPECT_EQ(layout.Describe(layout.LightDirectionOffset() + 5), "light_direction[1].z");
  EXPECT_EQ(params.LightDirections()[1], Eigen::Vector3d(0.6, 0, 0.8));
  EXPECT_EQ(params.LightPositions()[1], Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(params.Gains(1).z(), 1.5) << "the gains keep their values";
  const BlockSpan block = params.BlockOf(layout.LightDirectionOffset() + 4);
  EXPECT_EQ(block.offset, layout.LightDirectionOffset() + 3);
  EXPECT_EQ(block.size, 3);
  EXPECT_EQ(block.kind, ParameterKind::kLightDirection);
  EXPECT_TRUE(std::isinf(params.Lower(block.offset, ParameterBounds())));
  EXPECT_TRUE(std::isinf(params.Upper(block.offset, ParameterBounds())));
  int direction_blocks = 0;
  for (const BlockSpan& b : params.Blocks()) {
    direction_blocks += b.kind == ParameterKind::kLightDirection;
  }
  EXPECT_EQ(direction_blocks, 2);
  ParameterKind kind;
  ASSERT_TRUE(ParameterKindFromName("light_direction", &kind));
  EXPECT_EQ(kind, ParameterKind::kLightDirection);
  EXPECT_STREQ(ParameterKindName(kind), "light_direction");
}

// An icosphere dataset (6 views at 32², flat shading, constant albedo 0.6/0.5/0.4, roughness 0.4,
// specular 0.2) lit by one world-frame directional light travelling along kTrueTravel.
class LightDirectionFitTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    ASSERT_EQ(testing::SynthLightFitIcosphere(dir_->Join("flash")), "");
    ASSERT_EQ(testing::RelightDataset(dir_->Join("flash"), dir_->Join("sun"),
                                      [](Dataset* dataset) {
                                        LightSpec& light = dataset->lights.at(0);
                                        light.type = LightType::kDirectional;
                                        light.frame = LightFrame::kWorld;
                                        light.direction = kTrueTravel;
                                        light.irradiance = Eigen::Vector3d(3.0, 3.0, 3.0);
                                      }),
              "");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  static testing::TempDir* dir_;
};

testing::TempDir* LightDirectionFitTest::dir_ = nullptr;

// Fits the direction from 10° off (texture phases: LM, 3 outer iterations × 5 steps, 8 spp, from
// the true material; with `material` the albedo and roughness too, else held), returns the final
// angle to the truth in degrees, and checks that lights.json round-trips the fitted direction.
double FitDirection(const std::string& dataset_dir, bool material_too) {
  testing::LightFit fit;
  EXPECT_EQ(testing::ReadLightFit(dataset_dir, &fit), "");
  Dataset& dataset = fit.dataset;
  EXPECT_EQ(dataset.lights.at(0).type, LightType::kDirectional);
  fit.options.fit_light_directions = true;
  fit.options.fit_albedo = fit.options.fit_roughness = material_too;
  const Eigen::Vector3d axis = kTrueTravel.unitOrthogonal();
  const Eigen::Vector3d start = Eigen::AngleAxisd(10.0 * M_PI / 180.0, axis) * kTrueTravel;
  EXPECT_NEAR(AngleDegrees(start, kTrueTravel), 10.0, 1e-9);
  std::unique_ptr<Reconstruction> r;
  const std::string error = testing::RunLightFit(fit, {}, {start}, &r);
  EXPECT_EQ(error, "");
  if (!error.empty()) return 180.0;
  const std::vector<Eigen::Vector3d> fitted = r->LightDirections();
  EXPECT_EQ(fitted.size(), 1u);
  if (fitted.size() != 1) return 180.0;
  const double after = AngleDegrees(fitted[0], kTrueTravel);
  std::printf("%s: 10° from the truth at the start, %.3f° after (|v| = %.4f)\n",
              material_too ? "with the material" : "direction alone", after, fitted[0].norm());

  const std::string lights = JoinPath(dataset_dir, "lights.json");
  EXPECT_TRUE(WriteLightScales(lights, dataset, r->LightScales(), {}, fitted).ok());
  std::vector<double> scales;
  std::vector<Eigen::Vector3d> positions, read;
  EXPECT_TRUE(ReadLightScales(lights, dataset, &scales, &positions, &read).ok());
  EXPECT_TRUE(positions.empty());
  EXPECT_EQ(read.size(), 1u);
  if (read.size() == 1) {
    EXPECT_LT((read[0] - fitted[0].normalized()).norm(), 1e-12);
  }
  EXPECT_TRUE(ApplyLightsFile(lights, &dataset).ok());
  EXPECT_LT((dataset.lights[0].direction - fitted[0].normalized()).norm(), 1e-12);
  return after;
}

// The direction alone must end within 2° (measured 0.09°; the outer iterations' fresh samples
// move it by up to ~1.4° at 8 spp on 32² images: docs/design-notes.md, "Directional lights").
TEST_F(LightDirectionFitTest, DirectionAloneEndsWithinTwoDegrees) {
  EXPECT_LT(FitDirection(dir_->Join("sun"), /*material_too=*/false), 2.0);
}

// Fitted together with the albedo and roughness texels the direction moves towards the truth but
// stops short (measured 5.4°): each face's albedo absorbs the change of its cosine, and only the
// terminator, the highlight and the albedo's smoothness prior tell the two apart. Checked: at
// least 30% closer.
TEST_F(LightDirectionFitTest, DirectionWithTheMaterialMovesTowardsTheTruth) {
  EXPECT_LT(FitDirection(dir_->Join("sun"), /*material_too=*/true), 7.0);
}

// Malformed directions in lights.json are refused with the file and the entry named.
TEST_F(LightDirectionFitTest, LightsFileRefusesBadDirections) {
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir_->Join("sun"), &dataset).ok());
  const std::string path = dir_->Join("bad_lights.json");
  const auto read_error = [&](const std::string& members) {
    return testing::LightsFileError(path, dataset, members);
  };
  EXPECT_THAT(read_error(R"("direction": [1, 2])"),
              ::testing::HasSubstr("bad_lights.json: lights[0].direction: expected 3 numbers"));
  EXPECT_THAT(read_error(R"("direction": [0, 0, 0])"),
              ::testing::HasSubstr("lights[0].direction: must not be zero"));
  EXPECT_THAT(read_error(R"("frame": "camera", "direction": [0, 0, 1])"),
              ::testing::HasSubstr("lights[0].frame: expected \"world\""));
  EXPECT_THAT(read_error(R"("position": [0, 0, 1])"),
              ::testing::HasSubstr("lights[0].position: light \"" + dataset.lights[0].id +
                                   "\" is not a point light"));
}

}  // namespace
}  // namespace sft
