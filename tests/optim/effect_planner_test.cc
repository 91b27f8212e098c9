// The effect planner (src/optim/effect_planner.h) on scenes whose answers are known:
//   - a convex, diffuse, flash-lit icosphere: no light ever bounces back onto it and no part of it
//     shadows another, so the bounce and the shadows change nothing (change exactly 0) and are
//     dropped; its constant albedo has no texel boundaries; the silhouettes carry the geometry
//     gradient, so primary edges stay;
//   - a white inner corner (two unit squares at 90°, albedo 0.9): light bounces between the
//     faces, so the bounce stays.
#include "src/optim/effect_planner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "src/geometry/material.h"
#include "src/io/dataset.h"
#include "src/optim/config.h"
#include "src/optim/reconstruct.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

const EffectDecision& Find(const EffectPlanReport& report, const std::string& name) {
  for (const EffectDecision& d : report.decisions) {
    if (d.name == name) return d;
  }
  static const EffectDecision none;
  ADD_FAILURE() << "no decision for " << name;
  return none;
}

TEST(EffectPlanTest, SwitchesMapOntoRenderOptionsAndBudgets) {
  RenderOptions render;
  render.bounces = 3;
  DerivativeRequest edges;
  edges.primary_edge_ratio = 0.5;
  const EffectPlan plan = EffectPlan::From(render, edges);
  for (const std::string& name : PlannerSwitches()) {
    EXPECT_TRUE(plan.IsOn(name)) << name;
    const EffectPlan without = plan.Without(name);
    EXPECT_FALSE(without.IsOn(name)) << name;
    for (const std::string& other : PlannerSwitches()) {
      if (other != name) {
        EXPECT_TRUE(without.IsOn(other)) << name << " turned off " << other;
      }
    }
  }
  EXPECT_EQ(plan.Without("bounces").bounces, 1);
  RenderOptions out_render;
  DerivativeRequest out_edges;
  plan.Without("secondary_edges").ApplyTo(&out_render, &out_edges);
  EXPECT_EQ(out_render.bounces, 3);
  EXPECT_EQ(out_edges.primary_edge_ratio, 0.5);
  EXPECT_EQ(out_edges.secondary_edge_samples, 0.0);
  EXPECT_EQ(plan.Summary(), "direct env spec shadows 3seg | edges: primary shadow texel secondary");
}

TEST(EffectPlanTest, ConfigKeys) {
  ReconstructOptions options;
  EXPECT_TRUE(options.planner.enabled);  // the default is "auto".
  ASSERT_TRUE(ApplyReconstructConfig(nlohmann::json::parse(R"({"effects": "direct,shadows"})"),
                                     "cfg.json", &options)
                  .ok());
  EXPECT_FALSE(options.planner.enabled);
  EXPECT_FALSE(options.cache.render.effects.bounces);
  ASSERT_TRUE(
      ApplyReconstructConfig(nlohmann::json::parse(R"({"effects": "auto", "pin": {"shadows": true,
                      "secondary_edges": false}, "planner_views": 2})"),
                             "cfg.json", &options)
          .ok());
  EXPECT_TRUE(options.planner.enabled);
  EXPECT_TRUE(options.cache.render.effects.bounces);  // auto: every effect is a candidate.
  EXPECT_EQ(options.planner.pins.size(), 2u);
  EXPECT_EQ(options.planner.views, 2);
  const nlohmann::json round = ReconstructConfigJson(options);
  EXPECT_EQ(round["effects"], "auto");
  EXPECT_EQ(round["pin"]["secondary_edges"], false);
  const Status bad = ApplyReconstructConfig(nlohmann::json::parse(R"({"pin": {"bounce": true}})"),
                                            "cfg.json", &options);
  EXPECT_EQ(bad.message(),
            "cfg.json: pin: unknown effect 'bounce' (known: environment, specular, shadows, "
            "bounces, primary_edges, shadow_edges, texel_edges, secondary_edges)");
  EXPECT_EQ(ApplyReconstructConfig(nlohmann::json::parse(R"({"effects": "direct,glow"})"),
                                   "cfg.json", &options)
                .message(),
            "cfg.json: effects: unknown effect 'glow' (known: direct, shadows, bounces, "
            "specular, environment, all, none)");
  EXPECT_THAT(ApplyReconstructConfig(nlohmann::json::parse(R"({"planner_noise_factor": -1})"),
                                     "cfg.json", &options)
                  .message(),
              HasSubstr("planner_noise_factor: expected a number in [0.0, 100.0]"));
}

class EffectPlannerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    // Convex: flash-lit icosphere, diffuse, two segments in the images.
    ASSERT_EQ(testing::SynthIcosphere(dir_->Join("sphere"),
                                      "--cameras 4 --zooms 1 --res 32 --spp 16 --bounces 2 "
                                      "--material '{\"albedo\": [0.6, 0.6, 0.6], \"roughness\": "
                                      "0.5, \"specular\": 0}'"),
              "");
    // Concave: an inner corner of two white squares, lit by a light beside each camera.
    const std::string corner = dir_->Join("corner.obj");
    testing::WriteTestFile(corner,
                           "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n"
                           "f 1 2 3\nf 1 3 4\nf 1 6 2\nf 1 5 6\n");
    std::string output;
    ASSERT_EQ(testing::RunCommand(testing::SftBinary() + " synth --quiet --mesh " + corner +
                                      " --out " + dir_->Join("corner") +
                                      " --cameras 6 --zooms 1 --res 32 --spp 16 --bounces 2 "
                                      "--material '{\"albedo\": [0.9, 0.9, 0.9], \"roughness\": "
                                      "0.5, \"specular\": 0}'",
                                  &output),
              0)
        << output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  // Plans at the true mesh and material of dataset `name` with `config` keys; *renders gets the
  // number of renders the planner made.
  EffectPlanReport Plan(const std::string& name, const std::string& config,
                        EffectPlan* cache_plan = nullptr, int64_t* renders = nullptr) {
    return PlanAt(dir_->Join(name), dir_->Join(name + "/gt/material.json"), config, cache_plan,
                  renders);
  }
  // Plans at the true mesh of the dataset in `dir` with material `material` (file or JSON).
  EffectPlanReport PlanAt(const std::string& dir, const std::string& material_spec,
                          const std::string& config, EffectPlan* cache_plan = nullptr,
                          int64_t* renders = nullptr) {
    Dataset dataset;
    EXPECT_TRUE(ReadDataset(dir, &dataset).ok());
    TriMesh mesh;
    EXPECT_TRUE(ReadMesh(dir + "/gt/mesh.ply", &mesh).ok());
    Material material;
    EXPECT_TRUE(LoadMaterial(material_spec, mesh, &material).ok());
    ReconstructOptions options;
    options.cache.render.threads = 2;
    EXPECT_TRUE(ApplyReconstructConfig(nlohmann::json::parse(config), "test", &options).ok());
    std::unique_ptr<Reconstruction> reconstruction;
    EXPECT_TRUE(Reconstruction::Create(dataset, mesh, material, {}, options, &reconstruction).ok());
    EffectPlanReport report;
    const int64_t renders_before = reconstruction->cache().renders();
    const Status status = reconstruction->PlanEffects(0, &report);
    EXPECT_TRUE(status.ok()) << status.message();
    if (cache_plan != nullptr) *cache_plan = reconstruction->cache().plan();
    if (renders != nullptr) *renders = reconstruction->cache().renders() - renders_before;
    return report;
  }

  static testing::TempDir* dir_;
};

testing::TempDir* EffectPlannerTest::dir_ = nullptr;

TEST_F(EffectPlannerTest, ConvexDiffuseFlashLitObjectNeedsNeitherBouncesNorShadows) {
  EffectPlan cache_plan;
  const EffectPlanReport report = Plan("sphere", R"({"spp": 16})", &cache_plan);
  EXPECT_EQ(report.plan, cache_plan);  // the renders from now on use the plan.
  const EffectDecision& bounces = Find(report, "bounces");
  EXPECT_EQ(bounces.reason, "measured");
  EXPECT_EQ(bounces.bounces, 1);
  EXPECT_EQ(bounces.image.change, 0.0);  // every bounce ray leaves a convex object.
  EXPECT_EQ(bounces.step.change, 0.0);
  EXPECT_GT(bounces.image.noise, 0.0);
  const EffectDecision& shadows = Find(report, "shadows");
  EXPECT_EQ(shadows.reason, "measured");
  EXPECT_FALSE(shadows.on);
  EXPECT_EQ(shadows.image.change, 0.0);  // a convex object does not shadow itself.
  // Shadow edges remain along the terminator (where the light grazes the surface): tiny.
  EXPECT_LT(shadows.step.change, 0.01 * shadows.step.signal);
  EXPECT_EQ(Find(report, "specular").reason, "absent");  // specular weight 0.
  EXPECT_EQ(Find(report, "environment").reason, "absent");
  EXPECT_FALSE(Find(report, "texel_edges").on);              // constant albedo: no texel boundary.
  EXPECT_EQ(Find(report, "shadow_edges").reason, "absent");  // shadows are off.
  EXPECT_EQ(Find(report, "secondary_edges").reason, "absent");  // one segment, no environment.
  const EffectDecision& primary = Find(report, "primary_edges");
  EXPECT_EQ(primary.reason, "measured");
  EXPECT_TRUE(primary.on);
  EXPECT_FALSE(primary.image.measured);  // a derivative term does not change the images.
  EXPECT_GT(primary.step.change, primary.step.noise);
  EXPECT_GT(primary.step.change, 0.2 * primary.step.signal);  // silhouettes carry the gradient.
  EXPECT_EQ(report.plan.Summary(), "direct 1seg | edges: primary");
  EXPECT_GT(report.seconds, 0.0);
  EXPECT_EQ(report.views, 2);
}

// The derivative terms are measured on the reference passes' own parts (GradientParts): the
// planner renders as much when it measures them as when they are pinned on. The decisions are
// those of the test above.
TEST_F(EffectPlannerTest, MeasuringDerivativeTermsCostsNoRenders) {
  int64_t measured_renders = 0, pinned_renders = 0;
  const EffectPlanReport measured = Plan("sphere", R"({"spp": 16})", nullptr, &measured_renders);
  EXPECT_EQ(Find(measured, "primary_edges").reason, "measured");
  EXPECT_EQ(Find(measured, "texel_edges").reason, "measured");
  const EffectPlanReport pinned =
      Plan("sphere", R"({"spp": 16, "pin": {"primary_edges": true, "texel_edges": true}})", nullptr,
           &pinned_renders);
  EXPECT_EQ(Find(pinned, "primary_edges").reason, "pinned");
  EXPECT_GT(measured_renders, 0);
  EXPECT_EQ(measured_renders, pinned_renders);
  // Texel edges of a constant albedo change the gradient by exactly nothing.
  EXPECT_EQ(Find(measured, "texel_edges").step.change, 0.0);
}

// Lit by a studio probe (Cycles dataset), a convex sphere: the environment is all of the image;
// the sphere shadows no part of itself and bounces leave it, so both change nothing
// distinguishable from 0 and are dropped.
TEST_F(EffectPlannerTest, EnvironmentLitConvexSphereNeedsNoShadows) {
  const EffectPlanReport report =
      PlanAt(testing::DataDir() + "/cycles/sphere_env_studio",
             R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5})", R"({"spp": 8})");
  const EffectDecision& environment = Find(report, "environment");
  EXPECT_TRUE(environment.on);
  EXPECT_GT(environment.image.change, 0.5 * environment.image.signal);
  const EffectDecision& shadows = Find(report, "shadows");
  EXPECT_EQ(shadows.reason, "measured");
  EXPECT_FALSE(shadows.on);
  EXPECT_EQ(shadows.image.change, 0.0);
  EXPECT_LE(shadows.step.change, shadows.step.floor);
  EXPECT_EQ(Find(report, "bounces").bounces, 1);
  EXPECT_TRUE(Find(report, "primary_edges").on);
}

TEST_F(EffectPlannerTest, LightBouncingInsideACornerIsKept) {
  const EffectPlanReport report = Plan("corner", R"({"spp": 16})");
  const EffectDecision& bounces = Find(report, "bounces");
  EXPECT_EQ(bounces.reason, "measured");
  EXPECT_EQ(bounces.bounces, 2);
  EXPECT_GT(bounces.image.change, bounces.image.noise);
  EXPECT_GT(bounces.image.change, 0.01 * bounces.image.signal);
}

TEST_F(EffectPlannerTest, PinsAndTheNoiseFactorDecide) {
  // A noise factor of 100 and a share limit of 1 drop every measured switch; pins keep theirs.
  const EffectPlanReport strict =
      Plan("sphere", R"({"spp": 16, "planner_noise_factor": 100, "planner_max_share": 1,
                    "pin": {"bounces": true,
                    "primary_edges": true, "shadows": false}})");
  EXPECT_EQ(Find(strict, "bounces").reason, "pinned");
  EXPECT_EQ(Find(strict, "bounces").bounces, 2);
  EXPECT_TRUE(Find(strict, "primary_edges").on);
  EXPECT_EQ(Find(strict, "shadows").reason, "pinned");
  EXPECT_FALSE(Find(strict, "shadows").on);
  // Two segments and no environment: the secondary edges are measured, and dropped.
  EXPECT_EQ(Find(strict, "secondary_edges").reason, "measured");
  EXPECT_FALSE(Find(strict, "secondary_edges").on);
  // A texture-only fit measures no derivative term.
  const EffectPlanReport texture = Plan("sphere", R"({"spp": 16, "phases": "texture"})");
  EXPECT_EQ(Find(texture, "primary_edges").reason, "no geometry phase");
  // The console names what the first plan switched off, then only changes.
  const std::vector<std::string> lines = PlanChangeLines(strict, nullptr);
  ASSERT_FALSE(lines.empty());
  EXPECT_THAT(lines[0], HasSubstr("effects: shadows off (pinned)"));
  EXPECT_TRUE(PlanChangeLines(strict, &strict).empty());
}

}  // namespace
}  // namespace sft
