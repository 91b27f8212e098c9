// The schedule's uv stage (src/optim/uv_stage.h, StageOptions::material_model "uv"): switching a
// mesh-colors material to baked UV textures keeps the renders, a uv stage fits the texels (cost
// decreases, gutters stay out of the fit), its checkpoint holds the textures and resumes, and a
// mesh-colors stage after it samples the textures back.
#include "src/optim/uv_stage.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "src/geometry/uv_texel_charts.h"
#include "src/io/scene_setup.h"
#include "src/optim/run_outputs.h"
#include "src/optim/schedule.h"
#include "src/optim/schedule_config.h"
#include "src/render/render.h"
#include "src/render/scene.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using json = nlohmann::json;
using ::testing::HasSubstr;

// A textured icosphere at 32², 4 views, flash-lit; the start is the true mesh with the true
// (mesh-colors) material, so the uv stage starts from a bake of a good fit.
class UvStageTest : public ::testing::Test {
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
    ASSERT_TRUE(
        LoadMaterial(dir_->Join("ds/gt/material.json"), start_.mesh, &start_.material).ok());
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

testing::TempDir* UvStageTest::dir_ = nullptr;

// Baking the true mesh colors into a 512² atlas changes the renders by little: the atlas's
// corner UVs, the bake and the renderer's UV lookup agree on where each texel is. "Little" is
// against the change a flat grey albedo makes: under a tenth of it (the rest is the bilinear
// blend across the mesh-colour texels' borders, about one atlas texel wide).
TEST_F(UvStageTest, SwitchToUvTexturesKeepsTheRenders) {
  Material uv = start_.material;
  json record;
  ASSERT_TRUE(SwitchToUvTextures(start_.mesh, dataset_, 512, &uv, &record).ok());
  ASSERT_TRUE(uv.has_uv_textures());
  EXPECT_EQ(uv.uv.albedo.width(), 512);
  EXPECT_EQ(record["texture_size_from"], "texture_size");
  EXPECT_GT(record["charts"].get<int>(), 1);
  EXPECT_GT(record["fitted_texels"].get<int>(), 0);
  EXPECT_EQ(uv.specular, start_.material.specular);
  const Material grey = ConstantMaterial(static_cast<int>(start_.mesh.n_faces()),
                                         Eigen::Vector3d::Constant(0.5), 0.5, 0.0);

  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(start_.mesh, &positions, &faces);
  const RenderScene scene(positions, faces);
  DatasetViews views;
  ASSERT_TRUE(MakeDatasetViews(dataset_, &views).ok());
  RenderOptions options;
  options.spp = 16;
  options.bounces = 1;
  double uv_change = 0.0, grey_change = 0.0;
  for (const ViewSetup& view : views.views) {
    Image a, b, c;
    RenderView(scene, start_.material, view, options, &a);
    RenderView(scene, uv, view, options, &b);
    RenderView(scene, grey, view, options, &c);
    for (size_t i = 0; i < a.data.size(); ++i) {
      uv_change += std::abs(a.data[i] - b.data[i]);
      grey_change += std::abs(a.data[i] - c.data[i]);
    }
  }
  // Same seeds in all three: the differences are the materials'.
  EXPECT_GT(grey_change, 0.0);
  EXPECT_LT(uv_change, 0.1 * grey_change) << uv_change << " vs grey " << grey_change;

  // Back to mesh colors: resolution as asked, values in range.
  SwitchToMeshColors(3, &uv);
  EXPECT_FALSE(uv.has_uv_textures());
  EXPECT_EQ(uv.albedo.resolution(), 3);
  EXPECT_EQ(uv.roughness.channels(), 1);
  EXPECT_NEAR(uv.roughness.values()[0], 0.5, 0.02);
}

// A mesh-colors stage, then a uv stage (LM, texture phase, smoothness on): the uv stage's cost
// decreases, the final material is UV textures whose gutter texels are the dilation of the
// fitted ones, the checkpoint holds material.json + PNGs + mesh.obj's UVs, and a run stopped
// inside the uv stage resumes to the end.
TEST_F(UvStageTest, UvStageFitsTheTexelsAndResumes) {
  testing::TempDir out;
  const auto stages = Stages(R"({"spp": 8, "bounces": 1, "steps": 3, "phases": "texture",
      "albedo_smoothness": 0.001,
      "stages": [{"name": "mc", "outer_iterations": 1},
                 {"name": "uv", "material_model": "uv", "texture_size": 64,
                  "outer_iterations": 3}]})");
  // Start from a flat grey, so that the uv stage has something left to fit.
  ScheduleStart start = start_;
  ASSERT_TRUE(LoadMaterial(R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5, "resolution": 2})",
                           start.mesh, &start.material)
                  .ok());
  std::unique_ptr<Schedule> schedule;
  ASSERT_TRUE(
      Schedule::Start(dataset_, out.Join("r"), stages, start, {{"dataset", "ds"}}, &schedule).ok());
  std::vector<std::string> events;
  ScheduleCallbacks callbacks;
  callbacks.on_event = [&](const std::string& line) { events.push_back(line); };
  // Stop inside the uv stage, after its first outer iteration.
  callbacks.on_iteration = [&](const IterationRecord& r) {
    return !(r.stage == "uv" && r.outer == 2);
  };
  ASSERT_TRUE(schedule->Run(callbacks).ok());
  ASSERT_TRUE(schedule->stopped());
  bool atlas_line = false;
  for (const std::string& line : events) {
    atlas_line = atlas_line || line.find("uv: UV atlas 64") != std::string::npos;
  }
  EXPECT_TRUE(atlas_line);

  // The checkpoint: UV textures in PNGs, the corner UVs in mesh.obj.
  const json material_json = json::parse(testing::ReadTestFile(out.Join("r/material.json")));
  EXPECT_EQ(material_json["uv_albedo"], "material_albedo.png");
  EXPECT_EQ(material_json["uv_mesh"], "mesh.obj");
  TriMesh mesh;
  Material saved;
  std::vector<double> scales;
  ASSERT_TRUE(ReadRunSnapshot(out.Join("r"), dataset_, &mesh, &saved, &scales).ok());
  ASSERT_TRUE(saved.has_uv_textures());
  EXPECT_EQ(saved.uv.albedo.width(), 64);
  EXPECT_EQ(saved.uv.corner_uvs.size(), 3 * mesh.n_faces());

  RunState state;
  ASSERT_TRUE(ReadRunState(out.Join("r"), &state).ok());
  EXPECT_EQ(state.progress.stage, 1);
  EXPECT_EQ(state.progress.stage_outer_done, 1);
  std::unique_ptr<Schedule> resumed;
  ASSERT_TRUE(Schedule::Resume(dataset_, out.Join("r"), stages, state.run_info, state.progress,
                               state.view_gains, &resumed)
                  .ok());
  std::vector<IterationRecord> uv_records;
  callbacks.on_iteration = [&](const IterationRecord& r) {
    uv_records.push_back(r);
    return true;
  };
  ASSERT_TRUE(resumed->Run(callbacks).ok());
  ASSERT_TRUE(resumed->finished());
  ASSERT_GE(uv_records.size(), 2u);
  EXPECT_EQ(uv_records.front().stage, "uv");
  EXPECT_LT(uv_records.back().cost, uv_records.front().cost);

  // The uv stage as a whole: its first recorded cost (a grey bake) is above its last.
  double first_uv_cost = -1.0;
  for (const IterationRecord& r : schedule->records()) {
    if (r.stage == "uv" && first_uv_cost < 0.0) first_uv_cost = r.cost;
  }
  EXPECT_LT(uv_records.back().cost, first_uv_cost);

  const Material final_material = resumed->reconstruction()->CurrentMaterial();
  ASSERT_TRUE(final_material.has_uv_textures());
  // Gutters: dilating again changes nothing (they are the dilation of the fitted texels).
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(resumed->reconstruction()->Mesh(), nullptr, &faces);
  UvMaterialMaps again = final_material.uv;
  DilateUvGutters(faces, &again);
  EXPECT_EQ(again.albedo.values(), final_material.uv.albedo.values());
  const json metrics = json::parse(testing::ReadTestFile(out.Join("r/metrics.json")));
  ASSERT_EQ(metrics["material_switches"].size(), 1u);
  EXPECT_EQ(metrics["material_switches"][0]["to"], "uv");
  EXPECT_EQ(metrics["material_switches"][0]["texture_size"], 64);
}

TEST_F(UvStageTest, StageKeysAreChecked) {
  ScheduleConfig config;
  Status status = MergeScheduleConfig(json::parse(R"({"stages": [{"material_model": "ptex"}]})"),
                                      "cfg.json", &config);
  EXPECT_THAT(status.message(), HasSubstr("stages[0]: material_model: expected mesh_colors or uv"));
  status = MergeScheduleConfig(json::parse(R"({"stages": [{"texture_size": 32}]})"), "cfg.json",
                               &config);
  EXPECT_THAT(status.message(), HasSubstr("stages[0]: texture_size: expected 0"));
}

}  // namespace
}  // namespace sft
