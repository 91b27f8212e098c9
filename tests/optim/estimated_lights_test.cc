// Lights estimated beside unknown lighting's fitted environment (`estimate_lights`,
// src/optim/fitted_environment.h): the config key and its errors, what the environment stage then
// fits, how PrepareUnknownLighting adds them (and takes them back from a run folder), and a fit
// on a small synthetic capture lit by a dim room and a lamp near the object, whose place the fit
// is given 20% of the object's size off.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/lights_file.h"
#include "src/optim/fitted_environment.h"
#include "src/optim/lamp_finder.h"
#include "src/optim/reconstruct.h"
#include "src/optim/schedule_config.h"
#include "tests/testing/light_fits.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

// The lamp: a world-frame point light above one side of the object (bounding-box diagonal 1,
// centred at 0), about 1.6 from its centre; where the fit starts: 0.2 off (20% of the object).
const Eigen::Vector3d kTrueLamp(0.9, -0.7, 1.1);
const Eigen::Vector3d kDisplacement = 0.2 * Eigen::Vector3d(-0.6, 0.6, 0.5).normalized();

LightSpec Lamp(const Eigen::Vector3d& position, double intensity) {
  LightSpec lamp;
  lamp.id = "lamp";
  lamp.type = LightType::kPoint;
  lamp.frame = LightFrame::kWorld;
  lamp.position = position;
  lamp.intensity = Eigen::Vector3d::Constant(intensity);
  return lamp;
}

// The config key reads a lights file; the environment stage then fits the lights' intensities and
// places with the map; bad files and bad lights are one error naming the key and the file.
TEST(EstimatedLightsConfigTest, KeyStageAndErrors) {
  testing::TempDir tmp;
  LightSpec sun;
  sun.id = "sun";
  sun.type = LightType::kDirectional;
  sun.direction = Eigen::Vector3d(0, 0, -1);
  sun.irradiance = Eigen::Vector3d::Ones();
  ASSERT_TRUE(WriteLightsFile(tmp.Join("lamp.json"), {Lamp(kTrueLamp, 6.0)}).ok());
  ASSERT_TRUE(WriteLightsFile(tmp.Join("both.json"), {Lamp(kTrueLamp, 6.0), sun}).ok());

  StageOptions stage;
  ASSERT_TRUE(EnvironmentStage(ScheduleConfig(), StageOptions(), &stage).ok());
  EXPECT_FALSE(stage.fit.fit_lights);
  EXPECT_FALSE(stage.fit.fit_light_positions);

  ScheduleConfig config;
  ASSERT_TRUE(
      MergeScheduleConfig({{"estimate_lights", tmp.Join("lamp.json")}}, "cfg.json", &config).ok());
  ASSERT_EQ(config.environment.lights.size(), 1u);
  EXPECT_EQ(config.environment.lights[0].position, kTrueLamp);
  EXPECT_TRUE(config.environment_given);  // a resumed run refuses it.
  ASSERT_TRUE(EnvironmentStage(config, StageOptions(), &stage).ok());
  EXPECT_TRUE(stage.fit.fit_lights);
  EXPECT_TRUE(stage.fit.fit_light_positions);
  EXPECT_FALSE(stage.fit.fit_light_directions);
  EXPECT_FALSE(stage.fit.fit_albedo);
  ASSERT_TRUE(
      MergeScheduleConfig({{"estimate_lights", tmp.Join("both.json")}}, "cfg.json", &config).ok());
  ASSERT_TRUE(EnvironmentStage(config, StageOptions(), &stage).ok());
  EXPECT_TRUE(stage.fit.fit_light_directions);
  // The stage object still has the last word.
  config.environment_stage_keys = {{"fit_light_positions", false}};
  ASSERT_TRUE(EnvironmentStage(config, StageOptions(), &stage).ok());
  EXPECT_FALSE(stage.fit.fit_light_positions);

  LightSpec probe;
  probe.id = "room";
  probe.type = LightType::kEnvironment;
  probe.image = tmp.Join("room.exr");
  ASSERT_TRUE(WriteLightsFile(tmp.Join("probe.json"), {probe}).ok());
  ASSERT_TRUE(
      WriteLightsFile(tmp.Join("twice.json"), {Lamp(kTrueLamp, 1), Lamp(kTrueLamp, 2)}).ok());
  LightSpec named = Lamp(kTrueLamp, 1);
  named.id = kFittedEnvironmentId;
  ASSERT_TRUE(WriteLightsFile(tmp.Join("named.json"), {named}).ok());
  testing::WriteTestFile(tmp.Join("negative.json"),
                         R"({"lights": [{"id": "l", "type": "point", "position": [0, 0, 1],
                             "intensity": [1, -1, 1]}]})");
  const std::vector<std::pair<nlohmann::json, std::string>> bad = {
      {3, "estimate_lights: expected the path of a lights file"},
      {tmp.Join("missing.json"), "missing.json"},
      {tmp.Join("negative.json"), "negative.json: lights[0].intensity"},
      {tmp.Join("probe.json"), "probe.json: lights[0] (\"room\"): an environment light"},
      {tmp.Join("twice.json"), "twice.json: lights[1].id: duplicate light id"},
      {tmp.Join("named.json"), "the id is the fitted environment's"}};
  for (const auto& [value, expected] : bad) {
    ScheduleConfig c;
    const Status status = MergeScheduleConfig({{"estimate_lights", value}}, "cfg.json", &c);
    ASSERT_FALSE(status.ok()) << value;
    EXPECT_THAT(status.message(), HasSubstr("cfg.json: estimate_lights")) << value;
    EXPECT_THAT(status.message(), HasSubstr(expected)) << value;
  }
}

// PrepareUnknownLighting adds the estimated lights, then the map, to every view; the run folder
// keeps their start and gives them back (a resume, sft eval); known lighting refuses them.
TEST(EstimatedLightsConfigTest, PreparationAndRunFolder) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 2 --zooms 1 --res 8 --spp 2"), "");
  Dataset known;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &known).ok());
  Dataset dataset = known;
  testing::RemoveLights(&dataset);
  EnvironmentEstimateOptions estimate;
  estimate.lights = {Lamp(kTrueLamp, 6.0)};
  std::string note;
  ASSERT_TRUE(PrepareUnknownLighting("", estimate, &dataset, &note).ok());
  EXPECT_THAT(note, HasSubstr("environment and 1 estimated light (lamp)"));
  ASSERT_EQ(dataset.lights.size(), 2u);
  EXPECT_EQ(dataset.lights[0].id, "lamp");
  EXPECT_EQ(FittedEnvironmentLight(dataset), 1);
  for (const ViewSpec& view : dataset.views) {
    EXPECT_EQ(view.lights, std::vector<int>({0, 1}));
    EXPECT_EQ(view.light_ids, std::vector<std::string>({"lamp", kFittedEnvironmentId}));
  }
  // The run writes the lights as they started (Schedule::Start); a run folder gives them back.
  ASSERT_TRUE(MakeDirectories(tmp.Join("run")).ok());
  ASSERT_TRUE(WriteEstimatedLights(tmp.Join("run"), dataset).ok());
  ASSERT_TRUE(
      WriteFittedEnvironment(tmp.Join("run"), dataset.lights[1].pixels, LightFrame::kWorld).ok());
  Dataset resumed = known;
  testing::RemoveLights(&resumed);
  ASSERT_TRUE(
      PrepareUnknownLighting(tmp.Join("run"), EnvironmentEstimateOptions(), &resumed, &note).ok());
  EXPECT_THAT(note, HasSubstr("continuing"));
  EXPECT_THAT(note, HasSubstr("1 estimated light (lamp)"));
  ASSERT_EQ(resumed.lights.size(), 2u);
  EXPECT_EQ(resumed.lights[0].position, kTrueLamp);
  EXPECT_EQ(resumed.lights[0].intensity, Eigen::Vector3d::Constant(6.0));
  EXPECT_EQ(resumed.views[1].lights, std::vector<int>({0, 1}));
  // Without estimated lights no file is written.
  Dataset plain = known;
  testing::RemoveLights(&plain);
  ASSERT_TRUE(PrepareUnknownLighting("", EnvironmentEstimateOptions(), &plain, &note).ok());
  EXPECT_THAT(note, ::testing::Not(HasSubstr("estimated light")));
  ASSERT_TRUE(WriteEstimatedLights(tmp.Join("plain"), plain).ok());
  EXPECT_FALSE(FileExists(JoinPath(tmp.Join("plain"), kEstimatedLightsFile)));

  const Status status = PrepareUnknownLighting("", estimate, &known, &note);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("estimate_lights: the dataset lists its lights"));
  // A dataset light of the same id.
  Dataset clash = known;
  testing::RemoveLights(&clash);
  clash.lights.push_back(Lamp(kTrueLamp, 1.0));
  EXPECT_THAT(PrepareUnknownLighting("", estimate, &clash, &note).message(),
              HasSubstr("the dataset has a light of that id"));
}

// The small light-fit icosphere (6 views at 32², albedo 0.6/0.5/0.4, roughness 0.4, specular
// 0.2) in a dim, slightly top-lit room, with a lamp at kTrueLamp; read back with its lights
// removed.
class EstimatedLampFitTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    Image room(16, 8, 3);
    for (size_t k = 0; k < room.data.size(); ++k) room.data[k] = (k / 3) < 32 ? 0.5f : 0.2f;
    ASSERT_TRUE(WriteExr(dir_->Join("room.exr"), room).ok());
    ASSERT_EQ(
        testing::SynthLightFitIcosphere(dir_->Join("room"), "--envmap " + dir_->Join("room.exr")),
        "");
    ASSERT_EQ(testing::RelightDataset(dir_->Join("room"), dir_->Join("ds"),
                                      [](Dataset* dataset) {
                                        dataset->lights.push_back(Lamp(kTrueLamp, 6.0));
                                        for (ViewSpec& view : dataset->views) {
                                          view.lights.push_back(1);
                                          view.light_ids.push_back("lamp");
                                        }
                                      }),
              "");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  // The environment stage's options (as `sft reconstruct` builds them, made small) with `lights`
  // estimated beside the 8 × 4 map; dataset_ becomes the dataset with unknown lighting prepared
  // for them, and *fit holds the true mesh and material.
  ReconstructOptions Prepare(const std::vector<LightSpec>& lights, testing::LightFit* fit) {
    EXPECT_EQ(testing::ReadLightFit(dir_->Join("ds"), fit), "");
    testing::RemoveLights(&fit->dataset);
    ScheduleConfig config;
    config.environment.width = 8;
    config.environment.height = 4;
    config.environment.lights = lights;
    std::string note;
    EXPECT_TRUE(PrepareUnknownLighting("", config.environment, &fit->dataset, &note).ok());
    StageOptions stage;
    EXPECT_TRUE(EnvironmentStage(config, StageOptions(), &stage).ok());
    ReconstructOptions options = stage.fit;
    options.cache = fit->options.cache;  // 8 spp, one segment, flat shading, 3 levels.
    options.planner.enabled = false;
    options.outer_iterations = 3;
    dataset_ = fit->dataset;
    return options;
  }

  // Runs the environment stage (as `sft reconstruct` builds it, made small) on the dataset with
  // unknown lighting and `lights` estimated beside the 8 × 4 map, from the true material. Returns
  // the mean PSNR of the fitted views after the last step, and the reconstruction.
  double Fit(const std::vector<LightSpec>& lights, std::unique_ptr<Reconstruction>* r) {
    testing::LightFit fit;
    const ReconstructOptions options = Prepare(lights, &fit);
    EXPECT_TRUE(Reconstruction::Create(dataset_, fit.mesh, fit.material, {}, options, r).ok());
    double psnr = 0.0;
    for (int k = 0; k < options.outer_iterations; ++k) {
      EXPECT_TRUE((*r)->RunOuter(k,
                                 [&](const IterationRecord& record) {
                                   psnr = std::accumulate(record.view_psnr.begin(),
                                                          record.view_psnr.end(), 0.0) /
                                          std::max<size_t>(1, record.view_psnr.size());
                                   return true;
                                 })
                      .ok());
    }
    return psnr;
  }

  static testing::TempDir* dir_;
  Dataset dataset_;  // the dataset of the last Fit (its reconstruction points to it).
};

testing::TempDir* EstimatedLampFitTest::dir_ = nullptr;

// The lamp, given 0.2 off and at two thirds of its intensity, moves to within half that of the
// truth, and the views fit much better than with the map alone, which can hold the lamp's
// direction but not its fall-off across the object. Measured: 0.074 from the truth after (the
// rest mostly along its distance, which its intensity scale absorbs), and 33.6 dB against 21.2 dB;
// the bound is half that gain.
TEST_F(EstimatedLampFitTest, LampMovesTowardsTheTruthAndBeatsTheMapAlone) {
  std::unique_ptr<Reconstruction> alone;
  const double map_alone = Fit({}, &alone);
  alone.reset();  // before Fit replaces the dataset it points to.
  std::unique_ptr<Reconstruction> r;
  const Eigen::Vector3d start = kTrueLamp + kDisplacement;
  const double with_lamp = Fit({Lamp(start, 4.0)}, &r);
  const std::vector<Eigen::Vector3d> positions = r->LightPositions();
  ASSERT_EQ(positions.size(), 2u);  // the lamp, then the map (no position).
  const double before = (start - kTrueLamp).norm(), after = (positions[0] - kTrueLamp).norm();
  std::printf(
      "lamp %.4f from the truth at the start, %.4f after (%.4f %.4f %.4f), scale %.3f; "
      "mean view PSNR: map alone %.2f dB, map and lamp %.2f dB\n",
      before, after, positions[0].x(), positions[0].y(), positions[0].z(), r->LightScales()[0],
      map_alone, with_lamp);
  EXPECT_LT(after, 0.5 * before);
  EXPECT_GT(with_lamp, map_alone + 6.0);
}

// The lamp's basin (docs/design-notes.md, "How far off a lamp's guess may be"): started twice as
// far from the object as the truth and turned 0.9 rad (52°) around it, 2.5 away, it still ends
// within 0.1 of the truth (measured 0.069). Turned 1.0 rad at the true distance it is lost: its
// scale goes to 0 and the map takes over.
TEST_F(EstimatedLampFitTest, LampFoundFromFiftyDegreesAroundTheObject) {
  const Eigen::Vector3d side = kTrueLamp.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = kTrueLamp.cross(side).normalized();
  const Eigen::Vector3d start = 2.0 * (Eigen::AngleAxisd(-0.9, up) * kTrueLamp);
  std::unique_ptr<Reconstruction> r;
  const double psnr = Fit({Lamp(start, 4.0)}, &r);
  const Eigen::Vector3d lamp = r->LightPositions()[0];
  std::printf("lamp %.3f from the truth at the start, %.4f after; mean view PSNR %.2f dB\n",
              (start - kTrueLamp).norm(), (lamp - kTrueLamp).norm(), psnr);
  EXPECT_GT((start - kTrueLamp).norm(), 2.0);
  EXPECT_LT((lamp - kTrueLamp).norm(), 0.1);
}

// No guess at all (find_lamp, src/optim/lamp_finder.h): the map fitted alone points to the lamp,
// and the lamp started along that direction, at 4 half diagonals (2.0; the truth is at 1.58), is
// fitted to within 0.1 of the truth, as a guessed lamp is.
TEST_F(EstimatedLampFitTest, LampFoundWithNoGuess) {
  testing::LightFit fit;
  const ReconstructOptions options = Prepare({}, &fit);
  LampSearch search;
  ASSERT_TRUE(FindLamp(dataset_, fit.mesh, fit.material, options, 4.0, {}, &search).ok());
  ASSERT_TRUE(search.found) << search.Describe();
  const double angle =
      std::acos(std::clamp(search.direction.dot(kTrueLamp.normalized()), -1.0, 1.0));
  std::unique_ptr<Reconstruction> r;
  const double psnr = Fit({search.lamp}, &r);
  const Eigen::Vector3d lamp = r->LightPositions()[0];
  std::printf(
      "%s\nlobe %.1f° from the lamp's direction; start %.3f from the truth, %.4f after; "
      "mean view PSNR %.2f dB\n",
      search.Describe().c_str(), angle * 180.0 / M_PI, (search.lamp.position - kTrueLamp).norm(),
      (lamp - kTrueLamp).norm(), psnr);
  EXPECT_LT(angle, 0.5);
  EXPECT_LT((lamp - kTrueLamp).norm(), 0.1);
}

}  // namespace
}  // namespace sft
