// sft reconstruct and sft eval end to end on a tiny synthesized dataset: outputs, resume,
// re-render with the fitted lights, refusal of bad outputs and config keys.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "src/core/image.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/lights_file.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountLines;
using testing::RunSft;

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A refused run: exit 1 and one line holding `message`; with `out`, nothing written there.
void ExpectRefused(const std::string& args, const std::string& message,
                   const std::string& out = "") {
  SCOPED_TRACE(args);
  std::string output;
  EXPECT_EQ(RunSft(args, &output), 1) << output;
  EXPECT_THAT(output, HasSubstr(message));
  EXPECT_EQ(CountLines(output), 1) << output;
  if (!out.empty()) {
    EXPECT_FALSE(fs::exists(out));
  }
}

// Geometry and texture from a perturbed sphere: the run writes every output, the cost drops,
// eval scores it, a resumed run continues from the checkpoint, render re-renders it.
TEST(ReconstructCliTest, ReconstructEvalResume) {
  testing::TempDir tmp;
  ASSERT_EQ(
      testing::SynthIcosphere(tmp.Join("ds"),
                              "--cameras 4 --zooms 1 --res 24 --spp 32 --bounces 1 "
                              "--material '{\"albedo\": [0.6, 0.5, 0.4], \"roughness\": 0.5}'"),
      "");
  std::string out;
  ASSERT_EQ(RunSft("perturb --mesh " + tmp.Join("ds/gt/mesh.ply") + " --out " +
                       tmp.Join("init.ply") + " --amplitude 0.02 --seed 2",
                   &out),
            0)
      << out;
  const std::string common = "reconstruct --quiet --dataset " + tmp.Join("ds") +
                             " --spp 8 --bounces 1 --steps 2 --phases alternate";
  ASSERT_EQ(
      RunSft(common + " --init " + tmp.Join("init.ply") + " --out " + tmp.Join("r") + " --outer 1",
             &out),
      0)
      << out;
  for (const char* file : {"mesh.ply", "mesh.obj", "material.json", "lights.json", "metrics.csv",
                           "metrics.json", "state.json", "report.html", "initial_mesh.ply"}) {
    EXPECT_TRUE(fs::exists(tmp.Join(std::string("r/") + file))) << file;
  }
  // The asset for other programs, and the report's 3D view of it beside the start mesh.
  for (const char* file : {"model.obj", "model.mtl", "model_albedo.png", "model_roughness.png",
                           "model.glb", "model.ply", "export.json"}) {
    EXPECT_TRUE(fs::exists(tmp.Join(std::string("r/export/") + file))) << file;
  }
  const std::string report = testing::ReadTestFile(tmp.Join("r/report.html"));
  EXPECT_THAT(report, HasSubstr("export/model_albedo.png"));
  if (fs::exists("/usr/share/javascript/three/three.min.js")) {
    EXPECT_THAT(report, HasSubstr("<canvas id=\"sft3d-start\""));
    EXPECT_THAT(report, HasSubstr("<canvas id=\"sft3d-result\""));
    EXPECT_TRUE(fs::exists(tmp.Join("r/report_files/three/GLTFLoader.js")));
  } else {
    EXPECT_THAT(report, HasSubstr("three.js is not installed"));
  }
  const nlohmann::json metrics =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/metrics.json")));
  const auto& iterations = metrics["iterations"];
  ASSERT_GE(iterations.size(), 2u);
  EXPECT_EQ(iterations.front()["phase"], "texture");
  EXPECT_EQ(iterations.back()["phase"], "geometry");
  EXPECT_EQ(iterations.front()["view_psnr"].size(), 4u);
  EXPECT_EQ(CountLines(testing::ReadTestFile(tmp.Join("r/metrics.csv"))),
            1 + static_cast<int>(iterations.size()));

  // Resume to two outer iterations: the earlier records are kept, new ones follow, and folded
  // faces are still counted against the run's start (initial_mesh.ply, not rewritten).
  const std::string initial_mesh = testing::ReadTestFile(tmp.Join("r/initial_mesh.ply"));
  ASSERT_EQ(RunSft("reconstruct --quiet --resume " + tmp.Join("r") + " --outer 2", &out), 0) << out;
  EXPECT_EQ(testing::ReadTestFile(tmp.Join("r/initial_mesh.ply")), initial_mesh);
  const nlohmann::json resumed =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/metrics.json")));
  EXPECT_GT(resumed["iterations"].size(), iterations.size());
  EXPECT_EQ(resumed["iterations"].back()["outer"], 1);
  const nlohmann::json state =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/state.json")));
  EXPECT_EQ(state["outer_done"], 2);
  EXPECT_TRUE(state["finished"].get<bool>());
  EXPECT_EQ(state["run"]["init"], tmp.Join("init.ply"));
  EXPECT_EQ(state["run"]["start"], "init");
  EXPECT_EQ(state["format"], "sft-reconstruct-state/2");

  // eval, both modes.
  ASSERT_EQ(RunSft("eval --dataset " + tmp.Join("ds") + " --reconstruction " + tmp.Join("r") +
                       " --spp 16 --bounces 1",
                   &out),
            0)
      << out;
  const nlohmann::json images = nlohmann::json::parse(out);
  EXPECT_GT(images["full"]["psnr_linear"].get<double>(), 20.0);
  EXPECT_GT(images["albedo"]["psnr_linear"].get<double>(), 15.0);
  // The display (sRGB) measures and the relative RMSE come with every pass and view.
  for (const char* pass : {"full", "albedo", "roughness"}) {
    for (const char* key : {"psnr_srgb", "ssim_srgb", "ssim_linear", "rel_rmse"}) {
      EXPECT_TRUE(images[pass][key].is_number()) << pass << " " << key;
      EXPECT_TRUE(images[pass]["views"][0][key].is_number()) << pass << " " << key;
    }
  }
  EXPECT_GT(images["full"]["psnr_srgb"].get<double>(), 15.0);
  EXPECT_LT(images["full"]["rel_rmse"].get<double>(), 0.5);
  EXPECT_EQ(images["views"].size(), 4u);
  ASSERT_EQ(RunSft("eval --reference " + tmp.Join("ds/gt/mesh.ply") + " --mesh " +
                       tmp.Join("r/mesh.ply") + " --samples 20000",
                   &out),
            0)
      << out;
  EXPECT_GT(nlohmann::json::parse(out)["f1"].get<double>(), 0.0);

  // The fitted lights re-render through sft render.
  ASSERT_EQ(
      RunSft("render --quiet --no-report --dataset " + tmp.Join("ds") + " --mesh " +
                 tmp.Join("r/mesh.ply") + " --material " + tmp.Join("r/material.json") +
                 " --lights " + tmp.Join("r/lights.json") + " --spp 2 --out " + tmp.Join("rr"),
             &out),
      0)
      << out;
  EXPECT_TRUE(fs::exists(tmp.Join("rr/images/000.exr")));
}

// Ctrl-C: the run stops after the current iteration, writes its checkpoint and exits 130;
// --resume continues from it. The signal is sent once the first checkpoint exists (not after a
// fixed delay, which races with slow builds).
TEST(ReconstructCliTest, InterruptWritesACheckpointAndResumes) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 2 --zooms 1 --res 16 --spp 8"), "");
  std::string out;
  const std::string run = testing::SftBinary() + " reconstruct --quiet --dataset " +
                          tmp.Join("ds") + " --init " + tmp.Join("ds/gt/mesh.ply") + " --out " +
                          tmp.Join("r") +
                          " --outer 10000 --steps 2 --spp 4 --bounces 1 --phases texture";
  // Waits (at most 120 s) for state.json, then interrupts; prints the run's exit status last.
  const std::string script = run + " & pid=$!; for i in $(seq 1200); do [ -f " +
                             tmp.Join("r/state.json") +
                             " ] && break; sleep 0.1; done; kill -INT $pid; wait $pid; "
                             "echo \"exit=$?\"";
  ASSERT_EQ(testing::RunCommand("bash -c '" + script + "'", &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("exit=130"));
  EXPECT_THAT(out, HasSubstr("--resume"));
  const nlohmann::json state =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/state.json")));
  EXPECT_FALSE(state["finished"].get<bool>());
  const int done = state["outer_done"].get<int>();
  EXPECT_GE(done, 1);
  EXPECT_TRUE(fs::exists(tmp.Join("r/mesh.ply")));
  ASSERT_EQ(RunSft("reconstruct --quiet --resume " + tmp.Join("r") + " --outer " +
                       std::to_string(done + 1) + " --no-report",
                   &out),
            0)
      << out;
  const nlohmann::json resumed =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/state.json")));
  EXPECT_EQ(resumed["outer_done"].get<int>(), done + 1);
  EXPECT_TRUE(resumed["finished"].get<bool>());
}

// --print-schedule prints the effective stages and writes nothing: the built-in "large_steps" list
// with --init (the one-stage "refine" list when a flag describes one stage's loop), the "hull" list
// when the start would be carved (no --init, no initial_mesh, masks), and flags applied to every
// stage.
TEST(ReconstructCliTest, PrintScheduleFollowsTheStart) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 2 --zooms 1 --res 8 --spp 2"), "");
  std::string out;
  const std::string base = "reconstruct --dataset " + tmp.Join("ds") + " --print-schedule";
  ASSERT_EQ(RunSft(base + " --init " + tmp.Join("ds/gt/mesh.ply") + " --spp 7", &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("shape_half"));
  EXPECT_THAT(out, HasSubstr("adam"));
  EXPECT_THAT(out, HasSubstr("   7 "));
  EXPECT_GE(CountLines(out), 6) << out;
  // --outer describes one stage's loop: the one-stage refine list.
  ASSERT_EQ(RunSft(base + " --init " + tmp.Join("ds/gt/mesh.ply") + " --outer 2", &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("refine"));
  EXPECT_EQ(CountLines(out), 2) << out;
  ASSERT_EQ(RunSft(base + " --out " + tmp.Join("o"), &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("remesh"));
  EXPECT_THAT(out, HasSubstr("1/4"));
  EXPECT_GE(CountLines(out), 4) << out;
  EXPECT_FALSE(fs::exists(tmp.Join("o")));
}

// Unknown lighting (a probe-lit dataset with its lights removed): the schedule starts with the
// automatic environment stage (not with "environment_stage": false), a resumed run refuses the
// environment keys, and sft eval --true-environment scores the fitted map against the probe.
TEST(ReconstructCliTest, UnknownLightingStartsWithTheEnvironmentStage) {
  testing::TempDir tmp;
  Image probe(8, 4, 3);
  for (size_t k = 0; k < probe.data.size(); ++k) probe.data[k] = (k / 3) % 8 < 4 ? 2.0f : 0.3f;
  ASSERT_TRUE(WriteExr(tmp.Join("probe.exr"), probe).ok());
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"),
                                    "--cameras 3 --zooms 1 --res 12 --spp 4 "
                                    "--bounces 1 --envmap " +
                                        tmp.Join("probe.exr")),
            "");
  nlohmann::json scene = nlohmann::json::parse(testing::ReadTestFile(tmp.Join("ds/scene.json")));
  scene["lights"] = nlohmann::json::array();
  for (nlohmann::json& view : scene["views"]) view["lights"] = nlohmann::json::array();
  testing::WriteTestFile(tmp.Join("ds/scene.json"), scene.dump(1));
  const std::string base = "reconstruct --dataset " + tmp.Join("ds") + " --init " +
                           tmp.Join("ds/gt/mesh.ply") + " --outer 1 --steps 1 --spp 2";
  std::string out;
  ASSERT_EQ(RunSft(base + " --print-schedule", &out), 0) << out;
  EXPECT_EQ(CountLines(out), 3) << out;  // the header, environment, refine.
  EXPECT_LT(out.find("environment"), out.find("refine")) << out;
  testing::WriteTestFile(tmp.Join("cfg.json"), R"({"environment_stage": false})");
  ASSERT_EQ(RunSft(base + " --print-schedule --config " + tmp.Join("cfg.json"), &out), 0) << out;
  EXPECT_EQ(out.find("environment"), std::string::npos) << out;

  ASSERT_EQ(RunSft(base + " --quiet --no-report --out " + tmp.Join("o"), &out), 0) << out;
  EXPECT_TRUE(fs::exists(tmp.Join("o/environment.exr")));
  EXPECT_EQ(
      RunSft("reconstruct --quiet --resume " + tmp.Join("o") + " --config " + tmp.Join("cfg.json"),
             &out),
      1);
  EXPECT_THAT(out, HasSubstr("environment_stage/environment_size"));
  // The run fitted a world-fixed map; a resume keeps that frame (the same frame is accepted).
  ExpectRefused(
      "reconstruct --quiet --resume " + tmp.Join("o") + " --environment-frame camera",
      "environment_frame camera: the run in " + tmp.Join("o") + " fits a world-fixed environment");
  ASSERT_EQ(RunSft("reconstruct --quiet --no-report --resume " + tmp.Join("o") +
                       " --environment-frame world",
                   &out),
            0)
      << out;
  ASSERT_EQ(RunSft("eval --dataset " + tmp.Join("ds") + " --reconstruction " + tmp.Join("o") +
                       " --spp 2 --true-environment " + tmp.Join("probe.exr") + " --json " +
                       tmp.Join("eval.json"),
                   &out),
            0)
      << out;
  const nlohmann::json eval = nlohmann::json::parse(testing::ReadTestFile(tmp.Join("eval.json")));
  EXPECT_EQ(eval["lighting"], "estimated");
  ASSERT_TRUE(eval["environment"].is_object()) << eval.dump(1);
  EXPECT_GT(eval["environment"]["irradiance_rel_rmse"].get<double>(), 0.0);
  EXPECT_EQ(eval["environment"]["width"], 32);
}

// A lamp estimated beside the fitted map (--estimate-lights): the run keeps the lamp's start in
// estimated_lights.json and its fitted place in lights.json, sft eval renders with both, a resume
// refuses new lights, and bad lights files or known lighting are one line with no output folder.
TEST(ReconstructCliTest, EstimatedLampBesideTheFittedEnvironment) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 3 --zooms 1 --res 12 --spp 4"), "");
  const std::string known = "reconstruct --quiet --dataset " + tmp.Join("ds") + " --init " +
                            tmp.Join("ds/gt/mesh.ply") + " --outer 1 --steps 1 --spp 2";
  nlohmann::json scene = nlohmann::json::parse(testing::ReadTestFile(tmp.Join("ds/scene.json")));
  scene["lights"] = nlohmann::json::array();
  for (nlohmann::json& view : scene["views"]) view["lights"] = nlohmann::json::array();
  testing::WriteTestFile(tmp.Join("ds/scene.json"), scene.dump(1));
  testing::WriteTestFile(tmp.Join("lamp.json"), R"({"lights": [{"id": "lamp", "type": "point",
      "frame": "camera", "position": [0.2, -0.1, 0], "intensity": [0.5, 0.5, 0.5]}]})");
  const std::string base = known + " --estimate-lights " + tmp.Join("lamp.json");
  std::string out;
  ASSERT_EQ(RunSft(base + " --print-schedule", &out), 0) << out;
  EXPECT_LT(out.find("environment"), out.find("refine")) << out;
  ASSERT_EQ(RunSft(base + " --no-report --out " + tmp.Join("o"), &out), 0) << out;
  std::vector<LightSpec> start;
  ASSERT_TRUE(ReadLightsFile(tmp.Join("o/estimated_lights.json"), &start).ok());
  ASSERT_EQ(start.size(), 1u);
  EXPECT_EQ(start[0].frame, LightFrame::kCamera);
  EXPECT_EQ(start[0].position, Eigen::Vector3d(0.2, -0.1, 0));
  const nlohmann::json lights =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("o/lights.json")));
  ASSERT_EQ(lights["lights"].size(), 2u) << lights.dump(1);
  EXPECT_EQ(lights["lights"][0]["id"], "lamp");
  EXPECT_EQ(lights["lights"][0]["frame"], "camera");
  EXPECT_EQ(lights["lights"][0]["position"].size(), 3u) << "the environment stage fits its place";
  ASSERT_EQ(RunSft("eval --dataset " + tmp.Join("ds") + " --reconstruction " + tmp.Join("o") +
                       " --spp 2 --json " + tmp.Join("eval.json"),
                   &out),
            0)
      << out;
  ExpectRefused("reconstruct --quiet --resume " + tmp.Join("o") + " --estimate-lights " +
                    tmp.Join("lamp.json"),
                "--estimate-lights: a resumed run keeps its fitted lighting");
  ASSERT_EQ(
      RunSft("reconstruct --quiet --no-report --resume " + tmp.Join("o") + " --outer 2", &out), 0)
      << out;

  testing::WriteTestFile(tmp.Join("probe.json"), R"({"lights": [{"id": "room",
      "type": "environment", "image": "room.exr"}]})");
  ExpectRefused(known + " --out " + tmp.Join("p") + " --estimate-lights " + tmp.Join("probe.json"),
                "--estimate-lights: " + tmp.Join("probe.json") +
                    ": lights[0] (\"room\"): an environment light",
                tmp.Join("p"));
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("lit"), "--cameras 1 --zooms 1 --res 8 --spp 2"), "");
  ExpectRefused("reconstruct --quiet --dataset " + tmp.Join("lit") + " --init " +
                    tmp.Join("lit/gt/mesh.ply") + " --out " + tmp.Join("q") +
                    " --estimate-lights " + tmp.Join("lamp.json"),
                "estimate_lights: the dataset lists its lights", tmp.Join("q"));
}

// --find-lamp with no lamp given, on a capture lit by its camera's flash (0.15 to the side of the
// lens): the camera-fixed map fitted alone has its lobe towards the camera, so the lamp starts on
// the camera's side of the object (measured 3.9° off the flash's direction from the object) and the
// run fits it; the run folder keeps its start. A given lamp, known lighting, or a resume refuse
// the flag in one line.
TEST(ReconstructCliTest, FindLampWithNoGuess) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 6 --zooms 1 --res 32 --spp 16"), "");
  Dataset truth;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &truth).ok());
  const Eigen::Vector3d flash = truth.lights.at(0).position;
  nlohmann::json scene = nlohmann::json::parse(testing::ReadTestFile(tmp.Join("ds/scene.json")));
  scene["lights"] = nlohmann::json::array();
  for (nlohmann::json& view : scene["views"]) view["lights"] = nlohmann::json::array();
  testing::WriteTestFile(tmp.Join("ds/scene.json"), scene.dump(1));
  testing::WriteTestFile(tmp.Join("small.json"), R"({"environment_size": [8, 4]})");
  const std::string base = "reconstruct --dataset " + tmp.Join("ds") + " --init " +
                           tmp.Join("ds/gt/mesh.ply") +
                           " --outer 1 --steps 8 --spp 8 --environment-frame camera "
                           "--find-lamp --config " +
                           tmp.Join("small.json");
  std::string out;
  ASSERT_EQ(RunSft(base + " --out " + tmp.Join("o"), &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("find_lamp: the map fitted alone has a lobe")) << out;
  // The report shows the fitted map and the lamp's start and fitted place.
  const std::string report = testing::ReadTestFile(tmp.Join("o/report.html"));
  EXPECT_THAT(report, HasSubstr("Fitted lighting"));
  EXPECT_THAT(report, HasSubstr("found_lamp (point, camera frame)"));
  EXPECT_THAT(report, HasSubstr("report_files/environment.png"));
  EXPECT_TRUE(fs::exists(tmp.Join("o/report_files/environment.png")));
  std::vector<LightSpec> start;
  ASSERT_TRUE(ReadLightsFile(tmp.Join("o/estimated_lights.json"), &start).ok());
  ASSERT_EQ(start.size(), 1u);
  EXPECT_EQ(start[0].id, "found_lamp");
  EXPECT_EQ(start[0].frame, LightFrame::kCamera);
  // The object's centre (the origin) in the cameras: on the optical axis at the same distance.
  const Eigen::Vector3d centre = truth.views[0].cam_from_world * Eigen::Vector3d::Zero();
  const double cosine =
      (start[0].position - centre).normalized().dot((flash - centre).normalized());
  EXPECT_GT(cosine, std::cos(0.3)) << start[0].position.transpose();
  const nlohmann::json lights =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("o/lights.json")));
  ASSERT_EQ(lights["lights"].size(), 2u) << lights.dump(1);
  EXPECT_EQ(lights["lights"][0]["id"], "found_lamp");
  EXPECT_EQ(lights["lights"][0]["position"].size(), 3u) << "the environment stage fits its place";

  ExpectRefused("reconstruct --quiet --resume " + tmp.Join("o") + " --find-lamp",
                "--find-lamp: a resumed run keeps its fitted lighting");
  testing::WriteTestFile(tmp.Join("lamp.json"), R"({"lights": [{"id": "lamp", "type": "point",
      "position": [0, 0, 2], "intensity": [1, 1, 1]}]})");
  ExpectRefused(
      base + " --quiet --out " + tmp.Join("p") + " --estimate-lights " + tmp.Join("lamp.json"),
      "--find-lamp: looks for a lamp when none is given", tmp.Join("p"));
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("lit"), "--cameras 1 --zooms 1 --res 8 --spp 2"), "");
  ExpectRefused("reconstruct --quiet --dataset " + tmp.Join("lit") + " --init " +
                    tmp.Join("lit/gt/mesh.ply") + " --out " + tmp.Join("q") + " --find-lamp",
                "find_lamp: the dataset lists its lights", tmp.Join("q"));
  // The search is the environment stage run once: without that stage there is none.
  testing::WriteTestFile(tmp.Join("no_stage.json"), R"({"environment_stage": false})");
  ExpectRefused("reconstruct --quiet --dataset " + tmp.Join("ds") + " --init " +
                    tmp.Join("ds/gt/mesh.ply") + " --out " + tmp.Join("s") +
                    " --find-lamp --config " + tmp.Join("no_stage.json"),
                "find_lamp: needs the environment stage", tmp.Join("s"));
}

TEST(ReconstructCliTest, BadInputIsOneLine) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 1 --zooms 1 --res 8 --spp 2"), "");
  const std::string base =
      "reconstruct --quiet --dataset " + tmp.Join("ds") + " --init " + tmp.Join("ds/gt/mesh.ply");
  std::string out;
  ExpectRefused(base + " --out " + tmp.Join("ds"), "--out");
  testing::WriteTestFile(tmp.Join("cfg.json"), "{\"stepz\": 3}");
  ExpectRefused(base + " --out " + tmp.Join("o") + " --config " + tmp.Join("cfg.json"),
                "stepz: unknown key");
  EXPECT_EQ(RunSft(base + " --out " + tmp.Join("o") + " --steps 0", &out), 1);
  EXPECT_THAT(out, HasSubstr("--steps"));
  EXPECT_EQ(RunSft(base + " --out " + tmp.Join("o") + " --solver newton", &out), 1);
  EXPECT_THAT(out, HasSubstr("--solver"));
  EXPECT_EQ(RunSft("reconstruct --quiet --resume " + tmp.Join("nothing"), &out), 1);
  EXPECT_THAT(out, HasSubstr("state.json"));
  EXPECT_FALSE(fs::exists(tmp.Join("o/state.json")));
  // A checkpoint of an older version is refused with one line.
  fs::create_directories(tmp.Join("old"));
  testing::WriteTestFile(tmp.Join("old/state.json"),
                         "{\"format\": \"sft-reconstruct-state/1\", \"dataset\": \"" +
                             tmp.Join("ds") + "\", \"config\": {}, \"outer_done\": 1}");
  ExpectRefused("reconstruct --quiet --resume " + tmp.Join("old"), "sft-reconstruct-state/1");
}

}  // namespace
}  // namespace sft
