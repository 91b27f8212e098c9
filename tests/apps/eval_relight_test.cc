// `sft eval --relight` end to end on a tiny synthetic dataset: the reconstruction and the true
// object are rendered under lights the capture did not use (a lights file with a point light and
// a probe, and the built-in "side"), the relit truth is what `sft render` makes of the true object
// under those lights, the ground truth scores far above a wrong-albedo material, and bad
// --relight input is one error line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "src/core/image.h"
#include "src/eval/image_compare.h"
#include "src/image/image_io.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using json = nlohmann::json;

// A wood-textured icosphere, two views at 32² lit by the synth's camera flash.
void MakeDataset(const testing::TempDir& tmp) {
  ASSERT_EQ(testing::SynthIcosphere(
                tmp.Join("ds"),
                "--cameras 2 --zooms 1 --res 32 --spp 4 --material '{\"procedural\": \"wood\", "
                "\"scale\": 3, \"roughness_range\": [0.3, 0.6], \"specular\": 0.1}'"),
            "");
}

// A 16×8 equirectangular probe: a bright warm sky over a dark blue ground.
void WriteProbe(const std::string& path) {
  Image probe(16, 8, 3);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 16; ++x) {
      const bool sky = y < 4;
      probe.at(x, y, 0) = sky ? 1.6f : 0.05f;
      probe.at(x, y, 1) = sky ? 1.2f : 0.05f;
      probe.at(x, y, 2) = sky ? 0.6f : 0.2f;
    }
  }
  ASSERT_TRUE(WriteExr(path, probe).ok());
}

json Condition(const json& report, const std::string& name) {
  for (const json& c : report["relight"]["conditions"]) {
    if (c["name"] == name) return c;
  }
  ADD_FAILURE() << "no condition " << name;
  return json::object();
}

Image Read(const std::string& path) {
  Image image;
  EXPECT_TRUE(ReadImage(path, &image).ok()) << path;
  return image;
}

TEST(EvalRelightTest, ScoresTheReconstructionUnderNewLights) {
  testing::TempDir tmp;
  MakeDataset(tmp);
  WriteProbe(tmp.Join("lights/sky.exr"));
  // A world point light below and to the side of the object (the flash sits at the camera), and
  // the probe named relative to the lights file.
  testing::WriteTestFile(tmp.Join("lights/lights.json"), R"({"lights": [
      {"id": "low", "type": "point", "position": [1.2, -0.8, -1.0], "intensity": 3.0},
      {"id": "sky", "type": "environment", "image": "sky.exr"}]})");
  const std::string eval = "eval --spp 16 --dataset " + tmp.Join("ds") + " --relight " +
                           tmp.Join("lights/lights.json") + " --relight side";
  std::string out;
  ASSERT_EQ(testing::RunSft(eval + " --reconstruction " + tmp.Join("ds/gt") + " --out " +
                                tmp.Join("truth_eval") + " --json " + tmp.Join("truth.json"),
                            &out),
            0)
      << out;
  const json truth = json::parse(testing::ReadTestFile(tmp.Join("truth.json")));
  ASSERT_TRUE(truth["relight"].is_object()) << out;
  ASSERT_EQ(truth["relight"]["conditions"].size(), 4u);
  // The wrong albedo: a grey close to the wood's mean, with the true roughness and specular.
  ASSERT_EQ(testing::RunSft(eval + " --reconstruction " + tmp.Join("ds/gt") +
                                " --material '{\"albedo\": [0.45, 0.3, 0.2], \"roughness\": 0.45, "
                                "\"specular\": 0.1}' --json " +
                                tmp.Join("wrong.json"),
                            &out),
            0)
      << out;
  const json wrong = json::parse(testing::ReadTestFile(tmp.Join("wrong.json")));
  for (const char* name : {"capture", "low", "sky", "side"}) {
    SCOPED_TRACE(name);
    const json t = Condition(truth, name), w = Condition(wrong, name);
    std::printf("%-8s truth %.1f dB, wrong albedo %.1f dB (sRGB PSNR)\n", name,
                t["psnr_srgb"].get<double>(), w["psnr_srgb"].get<double>());
    // The same object with the same seed renders the same image.
    EXPECT_GT(t["psnr_srgb"].get<double>(), 60.0);
    EXPECT_GT(t["ssim_srgb"].get<double>(), 0.99);
    EXPECT_LT(w["psnr_srgb"].get<double>(), t["psnr_srgb"].get<double>() - 20.0);
    EXPECT_LT(w["ssim_srgb"].get<double>(), t["ssim_srgb"].get<double>());
  }
  // The relit truth is the true object under the new light: the capture dataset with its lights
  // replaced by "low", rendered by `sft render`, agrees with it, and the capture-lit truth does
  // not.
  std::filesystem::copy(tmp.Join("ds"), tmp.Join("ds_low"),
                        std::filesystem::copy_options::recursive);
  json scene = json::parse(testing::ReadTestFile(tmp.Join("ds/scene.json")));
  scene["lights"] = json::parse(
      R"([{"id": "low", "type": "point", "position": [1.2, -0.8, -1.0], "intensity": 3.0}])");
  for (json& view : scene["views"]) view["lights"] = {"low"};
  testing::WriteTestFile(tmp.Join("ds_low/scene.json"), scene.dump());
  ASSERT_EQ(testing::RunSft("render --quiet --no-report --spp 64 --dataset " + tmp.Join("ds_low") +
                                " --mesh " + tmp.Join("ds/gt/mesh.ply") + " --material " +
                                tmp.Join("ds/gt/material.json") + " --out " + tmp.Join("render"),
                            &out),
            0)
      << out;
  for (const char* view : {"000", "001"}) {
    SCOPED_TRACE(view);
    const std::string file = std::string("/truth/images/") + view + ".exr";
    const Image mask = Read(tmp.Join(std::string("ds/masks/") + view + ".png"));
    const Image rendered = Read(tmp.Join(std::string("render/images/") + view + ".exr"));
    const Image low = Read(tmp.Join("truth_eval/relight/01_low" + file));
    const Image capture = Read(tmp.Join("truth_eval/relight/00_capture" + file));
    const Image side = Read(tmp.Join("truth_eval/relight/03_side" + file));
    const Image sky = Read(tmp.Join("truth_eval/relight/02_sky" + file));
    const ImageAgreement same = CompareImages(low, rendered, mask);
    std::printf("view %s: relit vs sft render %.3f; vs capture %.3f, side %.3f, sky %.3f\n", view,
                same.relative_mean_abs_difference,
                CompareImages(capture, rendered, mask).relative_mean_abs_difference,
                CompareImages(side, capture, mask).relative_mean_abs_difference,
                CompareImages(sky, capture, mask).relative_mean_abs_difference);
    EXPECT_LT(std::abs(same.relative_mean_difference), 0.03);
    EXPECT_LT(same.relative_mean_abs_difference, 0.15);
    EXPECT_GT(CompareImages(capture, rendered, mask).relative_mean_abs_difference, 0.3);
    EXPECT_GT(CompareImages(side, capture, mask).relative_mean_abs_difference, 0.3);
    EXPECT_GT(CompareImages(sky, capture, mask).relative_mean_abs_difference, 0.3);
    // Ours is written beside the truth.
    EXPECT_TRUE(std::filesystem::exists(tmp.Join("truth_eval/relight/01_low/ours/images/") + view +
                                        ".exr"));
  }
}

TEST(EvalRelightTest, BadRelightInputIsOneErrorLine) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 1 --zooms 1 --res 16 --spp 1"), "");
  // The same dataset without ground truth.
  std::filesystem::copy(tmp.Join("ds"), tmp.Join("nogt"), std::filesystem::copy_options::recursive);
  json scene = json::parse(testing::ReadTestFile(tmp.Join("ds/scene.json")));
  scene.erase("ground_truth");
  testing::WriteTestFile(tmp.Join("nogt/scene.json"), scene.dump());
  testing::WriteTestFile(tmp.Join("neg.json"),
                         R"({"lights": [{"id": "a", "type": "point", "position": [0, 0, 2],
                                         "intensity": [1, -1, 1]}]})");
  testing::WriteTestFile(tmp.Join("empty.json"), R"({"lights": []})");
  testing::WriteTestFile(tmp.Join("nolights.json"), R"({"light": []})");
  testing::WriteTestFile(tmp.Join("syntax.json"), R"({"lights": [)");
  testing::WriteTestFile(tmp.Join("type.json"),
                         R"({"lights": [{"id": "a", "type": "area", "position": [0, 0, 2]}]})");
  testing::WriteTestFile(tmp.Join("noprobe.json"),
                         R"({"lights": [{"id": "e", "type": "environment", "image": "no.exr"}]})");
  testing::WriteTestFile(tmp.Join("ok.json"),
                         R"({"lights": [{"id": "a", "type": "point", "position": [0, 0, 2],
                                         "intensity": 1}]})");
  const std::string base = "eval --spp 1 --dataset " + tmp.Join("ds") + " --reconstruction " +
                           tmp.Join("ds/gt") + " --relight ";
  const struct {
    std::string args, expected;
  } cases[] = {
      {base + tmp.Join("missing.json"), "missing.json"},
      {base + tmp.Join("neg.json"), "neg.json: lights[0].intensity: must be non-negative"},
      {base + tmp.Join("empty.json"), "empty.json: lights: expected at least one light"},
      {base + tmp.Join("nolights.json"), "nolights.json: lights: missing"},
      {base + tmp.Join("syntax.json"), "syntax.json: invalid JSON"},
      {base + tmp.Join("type.json"), "type.json: lights[0].type: unknown light type"},
      {base + tmp.Join("noprobe.json"), "no.exr"},
      {base + "probe:" + tmp.Join("absent.exr"), "absent.exr: file not found"},
      {base + "probe:", "expected probe:PATH.exr"},
      {base + tmp.Join("ok.json") + " --relight " + tmp.Join("ok.json"), "appears twice"},
      {"eval --spp 1 --dataset " + tmp.Join("nogt") + " --reconstruction " + tmp.Join("ds/gt") +
           " --relight side",
       "ground_truth.mesh"},
      {"eval --reference " + tmp.Join("ds/gt/mesh.ply") + " --mesh " + tmp.Join("ds/gt/mesh.ply") +
           " --relight side",
       "--relight, --out, --material and --held-out need --dataset"},
      {base + "side --out " + tmp.Join("ds/relit"), "--out"},
      {"eval --spp 1 --dataset " + tmp.Join("ds") + " --reconstruction " + tmp.Join("ds/gt") +
           " --out " + tmp.Join("o"),
       "give --relight"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    std::string out;
    EXPECT_NE(testing::RunSft(c.args, &out), 0);
    EXPECT_EQ(testing::CountLines(out), 1) << out;
    EXPECT_THAT(out, StartsWith("sft eval: error: "));
    EXPECT_THAT(out, HasSubstr(c.expected));
  }
  EXPECT_FALSE(std::filesystem::exists(tmp.Join("ds/relit")));
  EXPECT_FALSE(std::filesystem::exists(tmp.Join("o")));
}

}  // namespace
}  // namespace sft
