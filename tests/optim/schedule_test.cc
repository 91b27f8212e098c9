// The schedule: stage lists from the config (keys, precedence, errors, built-in lists), the image
// scale of a stage (targets and cameras downscaled consistently), and runs of several stages with
// texel-resolution changes, checkpoints and resume.
#include "src/optim/schedule.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "src/geometry/material.h"
#include "src/io/dataset.h"
#include "src/optim/adam_checkpoint.h"
#include "src/optim/run_outputs.h"
#include "src/optim/schedule_config.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using json = nlohmann::json;
using ::testing::HasSubstr;

// "environment_frame" is a run-level key: "world" (default) or "camera"; anything else is one
// error naming the file and the key.
TEST(ScheduleConfigTest, EnvironmentFrameIsWorldOrCamera) {
  ScheduleConfig config;
  EXPECT_EQ(config.environment.frame, LightFrame::kWorld);
  EXPECT_FALSE(config.environment_frame_given);
  ASSERT_TRUE(MergeScheduleConfig({{"environment_frame", "camera"}}, "cfg", &config).ok());
  EXPECT_EQ(config.environment.frame, LightFrame::kCamera);
  EXPECT_TRUE(config.environment_frame_given);
  EXPECT_TRUE(config.flat.empty());  // not a stage key.
  for (const json& bad : {json("object"), json(1)}) {
    ScheduleConfig other;
    const Status status = MergeScheduleConfig({{"environment_frame", bad}}, "cfg.json", &other);
    ASSERT_FALSE(status.ok()) << bad;
    EXPECT_EQ(status.message(), "cfg.json: environment_frame: expected \"world\" or \"camera\"");
  }
}

TEST(ScheduleConfigTest, FlatKeysOverrideEveryStage) {
  ScheduleConfig config;
  ASSERT_TRUE(MergeScheduleConfig(json::parse(R"({
      "spp": 24,
      "stages": [{"name": "a", "image_scale": 0.5, "spp": 8, "texel_resolution": 2},
                 {"name": "b", "phases": "texture", "outer_iterations": 3}]})"),
                                  "cfg", &config)
                  .ok());
  std::vector<StageOptions> stages;
  ASSERT_TRUE(ResolveStages(config, /*carved_start=*/false, &stages).ok());
  ASSERT_EQ(stages.size(), 2u);
  EXPECT_EQ(stages[0].name, "a");
  EXPECT_EQ(stages[0].fit.cache.image_scale_log2, 1);
  EXPECT_EQ(stages[0].fit.cache.render.spp, 24);  // the flat key wins over the stage's 8.
  EXPECT_EQ(stages[0].texel_resolution, 2);
  EXPECT_EQ(stages[1].fit.phases, PhaseSchedule::kTexture);
  EXPECT_EQ(stages[1].fit.outer_iterations, 3);
  EXPECT_EQ(stages[1].fit.cache.render.spp, 24);
  EXPECT_EQ(stages[1].fit.cache.image_scale_log2, 0);  // the default, not stage a's.
  // StageJson round-trips.
  std::vector<StageOptions> again;
  ASSERT_TRUE(
      StagesFromJson(json::array({StageJson(stages[0]), StageJson(stages[1])}), "state", &again)
          .ok());
  EXPECT_EQ(StageJson(again[0]), StageJson(stages[0]));
  EXPECT_EQ(StageJson(again[1]), StageJson(stages[1]));
  const std::string table = FormatSchedule(stages);
  EXPECT_THAT(table, HasSubstr("1/2"));
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 3);
}

// A stage name longer than the default column keeps the table's columns aligned: the phases
// column starts at the same offset on the header and on every stage line.
TEST(ScheduleConfigTest, LongStageNamesKeepColumnsAligned) {
  std::vector<StageOptions> stages(2);
  stages[0].name = "a";
  stages[1].name = "material_full_scale";
  const std::string table = FormatSchedule(stages);
  std::vector<std::string> lines;
  for (size_t start = 0, end; (end = table.find('\n', start)) != std::string::npos;
       start = end + 1) {
    lines.push_back(table.substr(start, end - start));
  }
  ASSERT_EQ(lines.size(), 3u);
  const size_t column = lines[0].find("phases");
  ASSERT_NE(column, std::string::npos);
  for (size_t k = 1; k < lines.size(); ++k) {
    EXPECT_EQ(lines[k].find(PhaseScheduleName(stages[k - 1].fit.phases)), column) << lines[k];
  }
}

// The table names the views each stage fits: all, a short list, the few left out of a long one,
// or the ends of a long list; the views column stays aligned after a long "before".
TEST(ScheduleConfigTest, TableShowsEachStagesViews) {
  EXPECT_EQ(DescribeStageViews({}, 8), "all 8");
  EXPECT_EQ(DescribeStageViews({}, 0), "all");
  EXPECT_EQ(DescribeStageViews({1, 3, 5, 7}, 8), "4 of 8: 1,3,5,7");
  std::vector<int> most;  // 40 views, every 8th held out.
  for (int v = 0; v < 40; ++v) {
    if (v % 8 != 0) most.push_back(v);
  }
  EXPECT_EQ(DescribeStageViews(most, 40), "35 of 40: all but 0,8,16,24,32");
  std::vector<int> even;
  for (int v = 0; v < 80; v += 2) even.push_back(v);
  EXPECT_EQ(DescribeStageViews(even, 80), "40 of 80: 0,2,4,...,74,76,78");

  std::vector<StageOptions> stages(2);
  stages[0].name = "all";
  stages[0].topology.remesh = "isotropic";
  stages[0].topology.resample = true;
  stages[1].name = "some";
  stages[1].fit.views = {1, 3};
  const std::string table = FormatSchedule(stages, 4);
  std::vector<std::string> lines;
  for (size_t start = 0, end; (end = table.find('\n', start)) != std::string::npos;
       start = end + 1) {
    lines.push_back(table.substr(start, end - start));
  }
  ASSERT_EQ(lines.size(), 3u);
  const size_t column = lines[0].find("views");
  ASSERT_NE(column, std::string::npos);
  EXPECT_EQ(lines[1].find("all 4"), column) << table;
  EXPECT_EQ(lines[2].find("2 of 4: 1,3"), column) << table;
}

void ExpectGlossyRefineList(const std::string& path) {
  ScheduleConfig config;
  ASSERT_TRUE(ReadScheduleConfig(path, &config).ok());
  std::vector<StageOptions> stages;
  ASSERT_TRUE(ResolveStages(config, /*carved_start=*/false, &stages).ok());
  ASSERT_GE(stages.size(), 5u);
  double last_lr = 1e9;
  for (const StageOptions& stage : stages) {
    SCOPED_TRACE(stage.name);
    if (stage.fit.phases == PhaseSchedule::kTexture) {
      const bool last = &stage == &stages.back();
      EXPECT_EQ(stage.fit.solver.kind, last ? SolverKind::kAdam : SolverKind::kLevenbergMarquardt);
      EXPECT_EQ(stage.fit.cache.independent_gradient, last);
      EXPECT_TRUE(stage.fit.fit_specular);
      continue;
    }
    EXPECT_EQ(stage.fit.phases, PhaseSchedule::kGeometry);
    EXPECT_EQ(stage.fit.solver.kind, SolverKind::kAdam);
    EXPECT_EQ(stage.fit.solver.adam.large_steps_lambda, 25.0);
    EXPECT_TRUE(stage.fit.solver.adam.resample);
    EXPECT_FALSE(stage.fit.cache.independent_gradient);
    ASSERT_EQ(stage.fit.planner.pins.count("specular"), 1u);
    EXPECT_FALSE(stage.fit.planner.pins.at("specular"));
    EXPECT_LT(stage.fit.solver.adam.learning_rate_vertices, last_lr);
    last_lr = stage.fit.solver.adam.learning_rate_vertices;
  }
  EXPECT_EQ(stages.back().fit.phases, PhaseSchedule::kTexture);
}

// The shipped glossy-refine schedules (data/example/glossy_refine.json and the faster list
// large_steps_fast.json, docs/reconstruct.md) parse and alternate LM texture stages with Adam
// large-steps geometry stages that do not simulate the specular lobe, with the step size falling
// from stage to stage, and end with an Adam texture stage on independent gradient paths.
TEST(ScheduleConfigTest, ShippedGlossyRefineSchedulesParse) {
  for (const char* file : {"glossy_refine.json", "large_steps_fast.json"}) {
    SCOPED_TRACE(file);
    ExpectGlossyRefineList(testing::DataDir() + "/example/" + file);
  }
}

// The shipped list for real captures without a probe (data/example/real_ring.json,
// docs/reconstruct.md "Real captures without a probe"): a stereo start of 30,000 faces, every 8th
// view held out, a growing scale that alternates texture and geometry, and two final texture
// stages, the last at full scale.
TEST(ScheduleConfigTest, ShippedRealRingScheduleParses) {
  ScheduleConfig config;
  const Status status = ReadScheduleConfig(testing::DataDir() + "/example/real_ring.json", &config);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(config.carve.stereo);
  EXPECT_EQ(config.carve.faces, 30000);
  EXPECT_EQ(config.carve.stereo_options.consistency_pixels, 0.5);
  EXPECT_EQ(config.holdout, 8);
  std::vector<StageOptions> stages;
  ASSERT_TRUE(ResolveStages(config, /*carved_start=*/true, &stages).ok());
  ASSERT_EQ(stages.size(), 6u);
  int last_scale_log2 = 10;
  for (const StageOptions& stage : stages) {
    SCOPED_TRACE(stage.name);
    EXPECT_LE(stage.fit.cache.image_scale_log2, last_scale_log2);  // coarse to fine.
    last_scale_log2 = stage.fit.cache.image_scale_log2;
    EXPECT_FALSE(stage.fit.fit_specular);
    // Unweighted, as the held-out PSNR it is measured by (docs/design-notes.md, "The dino's last
    // texture stage").
    EXPECT_EQ(stage.fit.cache.image_loss, ImageLoss::kL2);
  }
  EXPECT_EQ(stages.front().fit.cache.image_scale_log2, 3);
  EXPECT_EQ(stages[1].fit.phases, PhaseSchedule::kGeometry);
  EXPECT_EQ(stages.back().fit.phases, PhaseSchedule::kTexture);
  // The last stage fits texels at full scale with Adam: LM's Jacobian would not fit there.
  EXPECT_EQ(stages.back().fit.cache.image_scale_log2, 0);
  EXPECT_EQ(stages.back().fit.solver.kind, SolverKind::kAdam);
}

// A step's progress work: pixels × spp, and for an Adam minibatch its share of the fitted views.
TEST(ScheduleConfigTest, StepWorkCountsTheMinibatchShare) {
  StageOptions lm;
  StageOptions adam = lm;
  adam.fit.solver.kind = SolverKind::kAdam;
  adam.fit.solver.adam.views_per_step = 8;
  EXPECT_EQ(Schedule::StepWork(lm, 64), 1000);
  EXPECT_EQ(Schedule::StepWork(adam, 64), 125);
  EXPECT_EQ(Schedule::StepWork(adam, 0), 1000);  // the view count unknown: no share.
  EXPECT_EQ(Schedule::StepWork(adam, 4), 1000);  // a batch of all views.
  adam.fit.cache.image_scale_log2 = 1;
  EXPECT_EQ(Schedule::StepWork(adam, 64), 31);  // a quarter of the pixels: 31.25, rounded.
}

// The progress work split by kind of step: an alternating LM stage gives each phase its steps, an
// Adam texture stage its minibatch share, and the kinds add up to the total.
TEST(ScheduleConfigTest, WorkIsSplitByKindOfStep) {
  ScheduleConfig config;
  ASSERT_TRUE(MergeScheduleConfig(json::parse(R"({"stages": [
      {"name": "both", "phases": "alternate", "outer_iterations": 2, "steps": 3},
      {"name": "adam", "phases": "texture", "solver": "adam", "steps": 10,
       "adam_views_per_step": 8, "outer_iterations": 1},
      {"name": "shape", "phases": "geometry", "solver": "adam", "steps": 4,
       "adam_views_per_step": 8, "outer_iterations": 1, "image_scale": 0.5}]})"),
                                  "test", &config)
                  .ok());
  std::vector<StageOptions> stages;
  ASSERT_TRUE(ResolveStages(config, /*carved_start=*/false, &stages).ok());
  const std::vector<int64_t> work = Schedule::TotalWorkByKind(stages, 64);
  ASSERT_EQ(work.size(), static_cast<size_t>(Schedule::kNumWorkKinds));
  const int lm_texture = Schedule::WorkKindOf(stages[0], "texture");
  const int lm_geometry = Schedule::WorkKindOf(stages[0], "geometry");
  const int adam_texture = Schedule::WorkKindOf(stages[1], "texture");
  const int adam_geometry = Schedule::WorkKindOf(stages[2], "geometry");
  EXPECT_EQ(std::set<int>({lm_texture, lm_geometry, adam_texture, adam_geometry}).size(), 4u);
  // A full-scale step at the default 16 spp is 1000 units; an Adam step of 8 of 64 views 125, at
  // half scale a quarter of that (31).
  const int spp = stages[0].fit.cache.render.spp;
  const int64_t full = Schedule::StepWork(stages[0], 64);
  EXPECT_EQ(full, std::llround(1000.0 * spp / 16.0));
  EXPECT_EQ(work[lm_texture], 2 * 3 * full);
  EXPECT_EQ(work[lm_geometry], 2 * 3 * full);
  EXPECT_EQ(work[adam_texture], 10 * Schedule::StepWork(stages[1], 64));
  EXPECT_EQ(work[adam_geometry], 4 * Schedule::StepWork(stages[2], 64));
  EXPECT_LT(Schedule::StepWork(stages[2], 64), Schedule::StepWork(stages[1], 64));
  EXPECT_EQ(Schedule::TotalWork(stages, 64),
            work[lm_texture] + work[lm_geometry] + work[adam_texture] + work[adam_geometry]);
}

TEST(ScheduleConfigTest, BuiltInListsFollowTheStart) {
  ScheduleConfig config;
  std::vector<StageOptions> stages;
  // A given mesh: the large-steps list. One LM material stage, then Adam material stages on
  // independent gradient paths (the first restarts the lobe) alternating with Adam geometry stages
  // on large steps whose step size falls; the geometry stages render the lobe into the residual
  // at 64 spp and keep it out of the step.
  ASSERT_TRUE(ResolveStages(config, /*carved_start=*/false, &stages).ok());
  ASSERT_GE(stages.size(), 6u);
  EXPECT_EQ(stages[0].fit.phases, PhaseSchedule::kTexture);
  EXPECT_EQ(stages[0].fit.solver.kind, SolverKind::kLevenbergMarquardt);
  EXPECT_TRUE(stages[0].fit.fit_specular);
  EXPECT_EQ(stages[0].fit.planner.pins.count("specular"), 0u);  // material stages fit the lobe.
  EXPECT_EQ(stages[0].restart_roughness, 0.0);
  EXPECT_EQ(stages[1].fit.phases, PhaseSchedule::kTexture);
  EXPECT_EQ(stages[1].fit.solver.kind, SolverKind::kAdam);
  EXPECT_TRUE(stages[1].fit.cache.independent_gradient);
  EXPECT_EQ(stages[1].restart_roughness, 0.5);  // the LM stage leaves it at its floor.
  EXPECT_EQ(stages[1].restart_specular, 0.2);
  double last_lr = 1e9;
  int geometry_stages = 0;
  for (size_t k = 2; k < stages.size(); ++k) {
    const StageOptions& stage = stages[k];
    SCOPED_TRACE(stage.name);
    EXPECT_EQ(stage.fit.solver.kind, SolverKind::kAdam);
    if (stage.fit.phases == PhaseSchedule::kTexture) {
      EXPECT_TRUE(stage.fit.cache.independent_gradient);
      EXPECT_EQ(stage.fit.solver.adam.views_per_step, 16);
      continue;
    }
    ++geometry_stages;
    EXPECT_EQ(stage.fit.phases, PhaseSchedule::kGeometry);
    EXPECT_EQ(stage.fit.solver.adam.large_steps_lambda, 25.0);
    EXPECT_TRUE(stage.fit.solver.adam.resample);
    EXPECT_FALSE(stage.fit.cache.independent_gradient);
    ASSERT_EQ(stage.fit.planner.pins.count("specular"), 1u);
    EXPECT_TRUE(stage.fit.planner.pins.at("specular"));  // in the residual...
    EXPECT_FALSE(stage.fit.cache.gradient_specular);     // ...out of the step.
    EXPECT_EQ(stage.fit.cache.render.spp, 64);
    EXPECT_LT(stage.fit.solver.adam.learning_rate_vertices, last_lr);
    last_lr = stage.fit.solver.adam.learning_rate_vertices;
  }
  EXPECT_EQ(geometry_stages, 4);
  EXPECT_EQ(stages.back().fit.phases, PhaseSchedule::kTexture);
  EXPECT_EQ(stages.back().restart_roughness, 0.5);
  EXPECT_EQ(stages.back().restart_specular, 0.2);
  // Flat keys that describe one stage's loop pick the one-stage refine list.
  for (const char* key : {"phases", "solver", "outer_iterations", "steps"}) {
    SCOPED_TRACE(key);
    ScheduleConfig one;
    const json value = std::string(key) == "phases"   ? json("geometry")
                       : std::string(key) == "solver" ? json("lm")
                                                      : json(2);
    ASSERT_TRUE(MergeScheduleConfig({{key, value}}, "cfg", &one).ok());
    ASSERT_TRUE(ResolveStages(one, /*carved_start=*/false, &stages).ok());
    ASSERT_EQ(stages.size(), 1u);
    EXPECT_EQ(stages[0].name, "refine");
  }
  // Other flat keys keep the list and apply to every stage.
  ScheduleConfig spp;
  ASSERT_TRUE(MergeScheduleConfig({{"spp", 7}}, "cfg", &spp).ok());
  ASSERT_TRUE(ResolveStages(spp, /*carved_start=*/false, &stages).ok());
  ASSERT_GE(stages.size(), 5u);
  for (const StageOptions& stage : stages) EXPECT_EQ(stage.fit.cache.render.spp, 7);
  ScheduleConfig named;
  ASSERT_TRUE(MergeScheduleConfig({{"schedule", "refine"}}, "cfg", &named).ok());
  ASSERT_TRUE(ResolveStages(named, /*carved_start=*/false, &stages).ok());
  EXPECT_EQ(stages.size(), 1u);
  ASSERT_TRUE(ResolveStages(config, /*carved_start=*/true, &stages).ok());
  ASSERT_GE(stages.size(), 3u);
  EXPECT_EQ(stages.front().fit.cache.image_scale_log2, 2);  // coarse to fine.
  EXPECT_EQ(stages.back().fit.cache.image_scale_log2, 0);
  EXPECT_EQ(stages.back().fit.phases, PhaseSchedule::kTexture);
  // The large_steps stage keys: Adam on the large-steps parameterisation for geometry, and the
  // closing material stage with independent adjoint paths.
  for (const StageOptions& stage : stages) {
    if (stage.fit.phases == PhaseSchedule::kGeometry) {
      EXPECT_EQ(stage.fit.solver.kind, SolverKind::kAdam) << stage.name;
      EXPECT_EQ(stage.fit.solver.adam.large_steps_lambda, 25.0) << stage.name;
      EXPECT_FALSE(stage.fit.planner.pins.at("specular")) << stage.name;  // pinned off.
    }
  }
  EXPECT_TRUE(stages.back().fit.cache.independent_gradient);
  // "schedule": "hull" picks the hull list from any start.
  ASSERT_TRUE(MergeScheduleConfig({{"schedule", "hull"}}, "cfg", &config).ok());
  ASSERT_TRUE(ResolveStages(config, /*carved_start=*/false, &stages).ok());
  EXPECT_GE(stages.size(), 3u);
}

TEST(ScheduleConfigTest, ErrorsNameTheStageAndKey) {
  const auto error = [](const std::string& text) {
    ScheduleConfig config;
    const Status status = MergeScheduleConfig(json::parse(text), "cfg.json", &config);
    return status.ok() ? std::string("ok") : status.message();
  };
  EXPECT_EQ(error(R"({"stages": [{"spp": 4}, {"remesh": "magic"}]})"),
            "cfg.json: stages[1]: remesh: expected none, adaptive or isotropic");
  EXPECT_EQ(error(R"({"stages": [{"image_scale": 0.3}]})"),
            "cfg.json: stages[0]: image_scale: expected 1, 0.5, 0.25, 0.125, 0.0625, 0.03125 or "
            "0.015625");
  EXPECT_THAT(error(R"({"stages": [{"stepz": 1}]})"), HasSubstr("stages[0]: stepz: unknown key"));
  EXPECT_THAT(error(R"({"stages": []})"), HasSubstr("stages: expected a non-empty array"));
  EXPECT_THAT(error(R"({"schedule": "fast"})"), HasSubstr("schedule: expected auto"));
  EXPECT_THAT(error(R"({"name": "x"})"), HasSubstr("name: a stage key"));
  EXPECT_THAT(error(R"({"effect_plan": "auto"})"), HasSubstr("effect_plan: unknown key"));
  EXPECT_THAT(error(R"({"pin": {"shadowz": true}})"), HasSubstr("pin: unknown effect 'shadowz'"));
  EXPECT_THAT(error(R"({"pin": {"shadows": 1}})"),
              HasSubstr("pin: shadows: expected true or false"));
  EXPECT_THAT(error(R"({"texel_resolution": 65})"), HasSubstr("texel_resolution"));
  EXPECT_THAT(error(R"({"stages": [{"restart_roughness": 1.5}]})"),
              HasSubstr("stages[0]: restart_roughness: expected a number in [0.0, 1.0]"));
}

// A textured icosphere at 32², 4 views, flash-lit, one segment.
class ScheduleRunTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    ASSERT_EQ(testing::SynthIcosphere(
                  dir_->Join("ds"),
                  "--cameras 4 --zooms 1 --res 32 --spp 64 --bounces 1 --material "
                  "'{\"procedural\": \"noise\", \"colors\": [[0.8, 0.3, 0.2], [0.2, 0.5, 0.7]], "
                  "\"roughness\": 0.5, \"specular\": 0, \"resolution\": 2}'"),
              "");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    ASSERT_TRUE(ReadDataset(dir_->Join("ds"), &dataset_).ok());
    ASSERT_TRUE(ReadMesh(dir_->Join("ds/gt/mesh.ply"), &start_.mesh).ok());
    ASSERT_TRUE(LoadMaterial(R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5})", start_.mesh,
                             &start_.material)
                    .ok());
  }
  std::vector<StageOptions> Stages(const std::string& text) {
    ScheduleConfig config;
    EXPECT_TRUE(MergeScheduleConfig(json::parse(text), "test", &config).ok());
    std::vector<StageOptions> stages;
    EXPECT_TRUE(ResolveStages(config, false, &stages).ok());
    return stages;
  }

  static testing::TempDir* dir_;
  Dataset dataset_;
  ScheduleStart start_;
};

testing::TempDir* ScheduleRunTest::dir_ = nullptr;

// At the true mesh and material, a render at half scale matches the half-scale target as well
// as a full-scale render matches the full-scale target: the camera and the target are scaled
// consistently (a half-pixel shift of the principal point would cost several dB at the edges).
TEST_F(ScheduleRunTest, HalfScaleTargetsMatchHalfScaleRenders) {
  Material truth;
  ASSERT_TRUE(LoadMaterial(dir_->Join("ds/gt/material.json"), start_.mesh, &truth).ok());
  double psnr[2];
  for (int k = 0; k < 2; ++k) {
    ReconstructOptions options;
    options.cache.render.spp = 64;
    options.cache.render.bounces = 1;
    options.cache.image_scale_log2 = k;
    std::unique_ptr<Reconstruction> r;
    ASSERT_TRUE(Reconstruction::Create(dataset_, start_.mesh, truth, {}, options, &r).ok());
    const std::vector<Image> renders = r->RenderViews(7);
    EXPECT_EQ(renders[0].width, 32 >> k);
    EXPECT_EQ(r->cache().Target(0).width, 32 >> k);
    double mse = 0.0;
    for (double m : r->cache().ViewMse()) mse += m / r->cache().num_views();
    psnr[k] = PsnrFromMse(mse);
  }
  EXPECT_GT(psnr[0], 28.0);
  // Half scale averages 4 pixels: less noise, so at least as good.
  EXPECT_GT(psnr[1], psnr[0] - 0.5) << psnr[0] << " " << psnr[1];
}

// "auto" picks the texel resolution whose spacing (mean edge / r) is closest to the pixel
// footprint: computed independently here from the mesh and the cameras' focal lengths; it
// halves (to the floor of 1) when the images are halved; "auto" parses and prints.
TEST_F(ScheduleRunTest, AutoTexelResolutionFollowsThePixelFootprint) {
  std::vector<int> views(dataset_.views.size());
  for (size_t v = 0; v < views.size(); ++v) views[v] = static_cast<int>(v);
  double edge_sum = 0.0;
  for (const auto& e : start_.mesh.edges()) edge_sum += start_.mesh.calc_edge_length(e);
  const double mean_edge = edge_sum / start_.mesh.n_edges();
  const double footprint = PixelFootprint(start_.mesh, dataset_, views, 0);
  ASSERT_GT(footprint, 0.0);
  const int full = ResolveTexelResolution(kTexelResolutionAuto, 1, start_.mesh, dataset_, views, 0);
  const int expected =
      std::clamp(static_cast<int>(std::lround(mean_edge / footprint)), 1, kMaxAutoTexelResolution);
  EXPECT_EQ(full, expected);
  EXPECT_GE(full, 1);
  const int half = ResolveTexelResolution(kTexelResolutionAuto, 1, start_.mesh, dataset_, views, 1);
  EXPECT_EQ(half, std::clamp(static_cast<int>(std::lround(mean_edge / (2 * footprint))), 1,
                             kMaxAutoTexelResolution));
  EXPECT_LE(half, full);
  EXPECT_EQ(ResolveTexelResolution(0, 5, start_.mesh, dataset_, views, 0), 5);  // keep.
  EXPECT_EQ(ResolveTexelResolution(3, 5, start_.mesh, dataset_, views, 0), 3);
  const std::vector<StageOptions> stages = Stages(R"({"texel_resolution": "auto"})");
  EXPECT_EQ(stages[0].texel_resolution, kTexelResolutionAuto);
  EXPECT_THAT(FormatSchedule(stages), HasSubstr("auto"));
  EXPECT_EQ(StageJson(stages[0])["texel_resolution"], "auto");
}

// Two stages: texture at half scale, then texture at full scale with twice the texel
// resolution. The run records both, changes the texel resolution, lowers the cost, writes the
// stage images; a resumed finished run does nothing; the state is format 2.
TEST_F(ScheduleRunTest, StagesRunInOrderWithCheckpoints) {
  testing::TempDir out;
  const auto stages = Stages(R"({"spp": 8, "bounces": 1, "steps": 3, "phases": "texture",
      "stages": [{"name": "coarse", "image_scale": 0.5, "outer_iterations": 2},
                 {"name": "fine", "texel_resolution": 2, "outer_iterations": 1}]})");
  std::unique_ptr<Schedule> schedule;
  ASSERT_TRUE(
      Schedule::Start(dataset_, out.Join("r"), stages, start_, {{"dataset", "ds"}}, &schedule)
          .ok());
  std::vector<std::string> events;
  ScheduleCallbacks callbacks;
  callbacks.on_event = [&](const std::string& line) { events.push_back(line); };
  const int64_t work = schedule->RemainingWork();
  const std::vector<int64_t> work_by_kind = schedule->RemainingWorkByKind();
  int64_t done = 0;
  std::vector<int64_t> done_by_kind(Schedule::kNumWorkKinds, 0);
  callbacks.on_iteration = [&](const IterationRecord& r) {
    done += schedule->CurrentStepWork();
    done_by_kind[Schedule::WorkKindOf(schedule->CurrentStage(), r.phase)] +=
        schedule->CurrentStepWork();
    return true;
  };
  ASSERT_TRUE(schedule->Run(callbacks).ok());
  EXPECT_TRUE(schedule->finished());
  // The weights add up to at most the ETA's total (a solve may stop early when it converges),
  // kind by kind as the progress line prices them; nothing is left once the run is finished.
  EXPECT_LE(done, work);
  EXPECT_GT(done, work / 2);
  for (int k = 0; k < Schedule::kNumWorkKinds; ++k) {
    EXPECT_LE(done_by_kind[k], work_by_kind[k]) << "kind " << k;
    EXPECT_EQ(done_by_kind[k] == 0, work_by_kind[k] == 0) << "kind " << k;
  }
  EXPECT_EQ(schedule->RemainingWork(), 0);
  // One line per stage start, one per texel-resolution change (the second stage doubles it),
  // and the effect planner's (the default "effects": "auto"): the convex icosphere does not
  // shadow itself, so the first plan drops shadows and later plans change nothing.
  std::vector<std::string> planner_lines, other_lines;
  for (const std::string& line : events) {
    (line.find("effects: ") != std::string::npos ? planner_lines : other_lines).push_back(line);
  }
  ASSERT_EQ(other_lines.size(), 3u);
  EXPECT_THAT(other_lines[0], HasSubstr("stage 1/2 coarse"));
  EXPECT_THAT(other_lines[1], HasSubstr("stage 2/2 fine"));
  EXPECT_THAT(other_lines[2], HasSubstr("texels: mesh-colours resolution"));
  ASSERT_EQ(planner_lines.size(), 1u);
  EXPECT_THAT(planner_lines[0],
              HasSubstr("coarse: effects: shadows off (image change 0: noise threshold "));
  const auto& records = schedule->records();
  ASSERT_FALSE(records.empty());
  EXPECT_EQ(records.front().stage, "coarse");
  EXPECT_EQ(records.back().stage, "fine");
  EXPECT_EQ(records.back().outer, 2);
  EXPECT_LT(records.back().cost, records.front().cost * 2.0);  // costs differ by scale; finite.
  EXPECT_EQ(schedule->reconstruction()->CurrentMaterial().albedo.resolution(), 2);

  RunState state;
  ASSERT_TRUE(ReadRunState(out.Join("r"), &state).ok());
  EXPECT_EQ(state.progress.stage, 2);
  EXPECT_EQ(state.progress.outer_done, 3);
  EXPECT_TRUE(state.finished);
  EXPECT_TRUE(std::filesystem::exists(out.Join("r/stages/00_coarse_normals.png")));
  EXPECT_TRUE(std::filesystem::exists(out.Join("r/stages/01_fine_normals.png")));
  const json metrics = json::parse(testing::ReadTestFile(out.Join("r/metrics.json")));
  EXPECT_EQ(metrics["outer"].size(), 3u);
  EXPECT_EQ(metrics["outer"][0]["stage"], "coarse");
  EXPECT_EQ(metrics["outer"][0]["self_intersecting_faces"], 0);
  for (const json& outer : metrics["outer"]) {
    EXPECT_EQ(outer["effects"]["plan"], "direct 1seg | edges: primary texel");
    EXPECT_EQ(outer["effects"]["decisions"].size(), 8u);
    EXPECT_GT(outer["effects"]["seconds"].get<double>(), 0.0);
  }
  EXPECT_EQ(metrics["stages"].size(), 2u);

  // Texel resolution in the checkpoint: the material file carries resolution 2.
  TriMesh mesh;
  Material material;
  std::vector<double> scales;
  ASSERT_TRUE(ReadRunSnapshot(out.Join("r"), dataset_, &mesh, &material, &scales).ok());
  EXPECT_EQ(material.albedo.resolution(), 2);

  // Resuming a finished run runs nothing and keeps the records.
  std::unique_ptr<Schedule> resumed;
  ASSERT_TRUE(Schedule::Resume(dataset_, out.Join("r"), stages, state.run_info, state.progress,
                               state.view_gains, &resumed)
                  .ok());
  int iterations = 0;
  callbacks.on_iteration = [&](const IterationRecord&) { return ++iterations > 0; };
  ASSERT_TRUE(resumed->Run(callbacks).ok());
  EXPECT_EQ(iterations, 0);
  EXPECT_EQ(resumed->records().size(), records.size());
}

// A stop in the middle of stage 1 writes a checkpoint; resuming finishes exactly the remaining
// outer iterations, with the same total as an uninterrupted run.
TEST_F(ScheduleRunTest, StopAndResumeMidStage) {
  testing::TempDir out;
  const auto stages = Stages(R"({"spp": 4, "bounces": 1, "steps": 2, "phases": "texture",
      "stages": [{"name": "a", "image_scale": 0.5, "outer_iterations": 1},
                 {"name": "b", "outer_iterations": 3}]})");
  std::unique_ptr<Schedule> schedule;
  ASSERT_TRUE(
      Schedule::Start(dataset_, out.Join("r"), stages, start_, {{"dataset", "ds"}}, &schedule)
          .ok());
  ScheduleCallbacks callbacks;
  int calls = 0;
  // Stop at stage b's first iteration after its first outer iteration finished.
  callbacks.on_iteration = [&](const IterationRecord& r) {
    ++calls;
    return !(r.stage == "b" && r.outer == 2);
  };
  ASSERT_TRUE(schedule->Run(callbacks).ok());
  EXPECT_TRUE(schedule->stopped());
  RunState state;
  ASSERT_TRUE(ReadRunState(out.Join("r"), &state).ok());
  EXPECT_EQ(state.progress.stage, 1);
  EXPECT_EQ(state.progress.stage_outer_done, 1);
  EXPECT_TRUE(state.progress.stage_prepared);
  EXPECT_FALSE(state.finished);

  std::unique_ptr<Schedule> resumed;
  ASSERT_TRUE(Schedule::Resume(dataset_, out.Join("r"), stages, state.run_info, state.progress,
                               state.view_gains, &resumed)
                  .ok());
  std::vector<int> outers;
  callbacks.on_iteration = [&](const IterationRecord& r) {
    outers.push_back(r.outer);
    return true;
  };
  ASSERT_TRUE(resumed->Run(callbacks).ok());
  EXPECT_TRUE(resumed->finished());
  ASSERT_FALSE(outers.empty());
  EXPECT_EQ(outers.front(), 2);  // the interrupted outer iteration runs again.
  EXPECT_EQ(outers.back(), 3);
  EXPECT_EQ(resumed->progress().outer_done, 4);
}

// The texels of a run's current material (albedo, then roughness).
std::vector<double> Texels(Schedule* schedule) {
  const Material material = schedule->reconstruction()->CurrentMaterial();
  std::vector<double> texels = material.albedo.values();
  texels.insert(texels.end(), material.roughness.values().begin(),
                material.roughness.values().end());
  return texels;
}

double MaxDifference(const std::vector<double>& a, const std::vector<double>& b) {
  EXPECT_EQ(a.size(), b.size());
  double d = 0.0;
  for (size_t k = 0; k < a.size() && k < b.size(); ++k) d = std::max(d, std::abs(a[k] - b[k]));
  return d;
}

// An Adam texture stage (new samples every step, 2 renders threads) of 2 outer iterations. The
// uninterrupted run is bit-reproducible. A copy of its folder taken right after the first outer
// iteration's checkpoint (a run killed then) resumes to the same texels up to what the
// checkpoint's float32 material file rounds away (< 1e-6); without adam_state.bin (moments, step
// count and hence per-step seeds restart) the resumed run ends more than 100 times further away.
TEST_F(ScheduleRunTest, AdamMomentsSurviveResume) {
  const auto stages = Stages(R"({"spp": 4, "bounces": 1, "effects": "direct", "threads": 2,
      "phases": "texture", "solver": "adam", "adam_resample": true, "steps": 3,
      "stages": [{"name": "adam", "outer_iterations": 2}]})");
  testing::TempDir out;
  // Runs the stage in `run`; with `copy`, copies the folder when the second outer iteration
  // reports its first step (the checkpoint after the first is complete then).
  const auto run_whole = [&](const std::string& run, const std::string& copy) {
    std::unique_ptr<Schedule> schedule;
    EXPECT_TRUE(
        Schedule::Start(dataset_, run, stages, start_, {{"dataset", "ds"}}, &schedule).ok());
    ScheduleCallbacks callbacks;
    callbacks.on_iteration = [&](const IterationRecord& r) {
      if (!copy.empty() && r.outer == 1 && r.iteration == 1) {
        std::filesystem::copy(run, copy, std::filesystem::copy_options::recursive);
      }
      return true;
    };
    EXPECT_TRUE(schedule->Run(callbacks).ok());
    EXPECT_TRUE(schedule->finished());
    return Texels(schedule.get());
  };
  const std::vector<double> whole = run_whole(out.Join("whole"), out.Join("killed"));
  EXPECT_EQ(MaxDifference(run_whole(out.Join("again"), ""), whole), 0.0);
  ASSERT_TRUE(std::filesystem::exists(out.Join("killed/adam_state.bin")));
  std::filesystem::copy(out.Join("killed"), out.Join("killed_old"),
                        std::filesystem::copy_options::recursive);
  std::filesystem::remove(out.Join("killed_old/adam_state.bin"));

  const auto resume = [&](const std::string& run, std::vector<std::string>* events) {
    RunState state;
    EXPECT_TRUE(ReadRunState(run, &state).ok());
    EXPECT_EQ(state.progress.outer_done, 1);
    std::unique_ptr<Schedule> resumed;
    EXPECT_TRUE(Schedule::Resume(dataset_, run, stages, state.run_info, state.progress,
                                 state.view_gains, &resumed)
                    .ok());
    ScheduleCallbacks callbacks;
    callbacks.on_event = [&](const std::string& line) { events->push_back(line); };
    EXPECT_TRUE(resumed->Run(callbacks).ok());
    EXPECT_TRUE(resumed->finished());
    EXPECT_EQ(resumed->progress().outer_done, 2);
    return Texels(resumed.get());
  };
  std::vector<std::string> events, old_events;
  const double restored = MaxDifference(resume(out.Join("killed"), &events), whole);
  const double fresh = MaxDifference(resume(out.Join("killed_old"), &old_events), whole);
  EXPECT_THAT(events, ::testing::Contains("resume: Adam's moments restored (step 3)"));
  EXPECT_TRUE(old_events.empty());  // an older run folder resumes silently, as before.
  EXPECT_LT(restored, 1e-6);
  EXPECT_GT(fresh, 100.0 * std::max(restored, 1e-7)) << restored << " " << fresh;
  std::cout << "texels after resume, max |difference| to the uninterrupted run: with moments "
            << restored << ", without " << fresh << "\n";
}

// A truncated adam_state.bin stops the resume with one line naming the file; one whose moments do
// not fit the parameters is set aside with one console line.
TEST_F(ScheduleRunTest, BrokenAdamStateIsReported) {
  testing::TempDir out;
  const auto stages = Stages(R"({"spp": 2, "bounces": 1, "effects": "direct", "phases": "texture",
      "solver": "adam", "steps": 1, "stages": [{"name": "adam", "outer_iterations": 1}]})");
  std::unique_ptr<Schedule> schedule;
  ASSERT_TRUE(
      Schedule::Start(dataset_, out.Join("r"), stages, start_, {{"dataset", "ds"}}, &schedule)
          .ok());
  ASSERT_TRUE(schedule->Run(ScheduleCallbacks()).ok());
  const std::string file = out.Join("r/adam_state.bin");
  const uintmax_t size = std::filesystem::file_size(file);
  RunState state;
  ASSERT_TRUE(ReadRunState(out.Join("r"), &state).ok());
  // --outer 2 on resume: the finished stage continues, with its moments.
  auto more = stages;
  more[0].fit.outer_iterations = 2;
  std::unique_ptr<Schedule> resumed;
  AdamCheckpoint saved;
  bool found = false;
  ASSERT_TRUE(ReadAdamCheckpoint(out.Join("r"), &saved, &found).ok());
  ASSERT_TRUE(found);

  std::filesystem::resize_file(file, size - 8);
  Status status = Schedule::Resume(dataset_, out.Join("r"), more, state.run_info, state.progress,
                                   state.view_gains, &resumed);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(file + ": truncated or corrupt"));
  EXPECT_THAT(status.message(), HasSubstr("need " + std::to_string(size) + ")"));
  EXPECT_EQ(status.message().find('\n'), std::string::npos);
  std::filesystem::resize_file(file, 20);
  status = Schedule::Resume(dataset_, out.Join("r"), more, state.run_info, state.progress,
                            state.view_gains, &resumed);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(file + ": not an sft Adam state"));

  saved.state.m.pop_back();
  saved.state.v.pop_back();
  ASSERT_TRUE(WriteAdamCheckpoint(out.Join("r"), saved).ok());
  ASSERT_TRUE(Schedule::Resume(dataset_, out.Join("r"), more, state.run_info, state.progress,
                               state.view_gains, &resumed)
                  .ok());
  std::vector<std::string> events;
  ScheduleCallbacks callbacks;
  callbacks.on_event = [&](const std::string& line) { events.push_back(line); };
  ASSERT_TRUE(resumed->Run(callbacks).ok());
  ASSERT_FALSE(events.empty());
  EXPECT_THAT(events.front(), HasSubstr("moments do not match the parameters: Adam starts fresh"));
  EXPECT_THAT(events.front(), HasSubstr(file));
}

// A geometry outer iteration that leaves self-intersecting faces is followed by untangling (the
// default): the outer record counts none, and its `untangle` entry says how many there were.
// With `untangle` off they stay.
TEST_F(ScheduleRunTest, GeometryOuterUntanglesSelfIntersections) {
  // One vertex pushed through the centre and out beyond the far side.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (TriMesh::VertexHandle v : start_.mesh.vertices()) {
    const TriMesh::Point p = start_.mesh.point(v);
    centre += Eigen::Vector3d(p[0], p[1], p[2]) / start_.mesh.n_vertices();
  }
  const TriMesh::VertexHandle pushed = start_.mesh.vertex_handle(0);
  const TriMesh::Point p = start_.mesh.point(pushed);
  const Eigen::Vector3d moved = centre - 1.3 * (Eigen::Vector3d(p[0], p[1], p[2]) - centre);
  start_.mesh.set_point(pushed, TriMesh::Point(moved.x(), moved.y(), moved.z()));
  for (const bool untangle : {true, false}) {
    testing::TempDir out;
    const auto stages = Stages(std::string(R"({"spp": 4, "bounces": 1, "steps": 1,
        "phases": "geometry", "resample_fold_fraction": 0, "untangle": )") +
                               (untangle ? "true" : "false") + R"(,
        "stages": [{"name": "shape", "outer_iterations": 1}]})");
    std::unique_ptr<Schedule> schedule;
    ASSERT_TRUE(
        Schedule::Start(dataset_, out.Join("r"), stages, start_, {{"dataset", "ds"}}, &schedule)
            .ok());
    std::vector<std::string> events;
    ScheduleCallbacks callbacks;
    callbacks.on_event = [&](const std::string& line) { events.push_back(line); };
    ASSERT_TRUE(schedule->Run(callbacks).ok());
    const json& outer = schedule->outer_records().back();
    if (untangle) {
      ASSERT_TRUE(outer.contains("untangle"));
      EXPECT_GE(outer["untangle"]["faces_before"].get<int>(), 10);
      EXPECT_EQ(outer["untangle"]["faces_after"], 0);
      EXPECT_EQ(outer["self_intersecting_faces"], 0);
      bool logged = false;
      for (const std::string& line : events) logged |= line.find("shape: untangle: ") == 0;
      EXPECT_TRUE(logged);
    } else {
      EXPECT_FALSE(outer.contains("untangle"));
      EXPECT_GE(outer["self_intersecting_faces"].get<int>(), 10);
    }
  }
}

TEST(RunStateTest, OlderFormatIsRefusedWithOneLine) {
  testing::TempDir dir;
  testing::WriteTestFile(dir.Join("state.json"),
                         R"({"format": "sft-reconstruct-state/1", "dataset": "d", "config": {},
                             "outer_done": 1})");
  RunState state;
  const Status status = ReadRunState(dir.path(), &state);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("sft-reconstruct-state/1"));
  EXPECT_THAT(status.message(), HasSubstr("older sft"));
  EXPECT_EQ(status.message().find('\n'), std::string::npos);
}

}  // namespace
}  // namespace sft
