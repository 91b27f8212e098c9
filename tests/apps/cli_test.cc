// End-to-end tests of the `sft` command line: real files in and out, exit codes, one-line errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "src/core/image.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountLines;
using testing::RunSft;

using ::testing::HasSubstr;

TEST(CliTest, HelpListsCommands) {
  std::string out;
  EXPECT_EQ(RunSft("--help", &out), 0);
  EXPECT_THAT(out, HasSubstr("synth"));
  EXPECT_THAT(out, HasSubstr("render"));
  EXPECT_EQ(RunSft("render --help", &out), 0);
  EXPECT_THAT(out, HasSubstr("--bounces"));
  EXPECT_THAT(out, HasSubstr("--pass"));
}

// synth writes a complete dataset that ReadDataset/CheckDatasetFiles accept; render re-renders it
// with the ground truth and reproduces the images within Monte Carlo noise.
TEST(CliTest, SynthThenRenderRoundTrip) {
  testing::TempDir tmp;
  const std::string mesh = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
  std::string out;
  ASSERT_EQ(RunSft("synth --quiet --mesh " + mesh + " --out " + tmp.Join("ds") +
                       " --cameras 3 --zooms 1,2 --res 24 --spp 64 --bounces 2 "
                       "--material '{\"albedo\": [0.5, 0.4, 0.3], \"roughness\": 0.3, "
                       "\"specular\": 0.2}'",
                   &out),
            0)
      << out;
  Dataset dataset;
  const Status read = ReadDataset(tmp.Join("ds"), &dataset);
  ASSERT_TRUE(read.ok()) << read.message();
  EXPECT_EQ(dataset.views.size(), 6u);
  EXPECT_EQ(dataset.cameras.size(), 2u);
  ASSERT_TRUE(CheckDatasetFiles(dataset).ok());
  EXPECT_TRUE(std::filesystem::exists(tmp.Join("ds/gt/mesh.ply")));
  EXPECT_FALSE(std::filesystem::exists(tmp.Join("ds.partial")));

  ASSERT_EQ(
      RunSft("render --quiet --dataset " + tmp.Join("ds") + " --mesh " +
                 tmp.Join("ds/gt/mesh.ply") + " --material " + tmp.Join("ds/gt/material.json") +
                 " --spp 64 --bounces 2 --seed 7 --out " + tmp.Join("r"),
             &out),
      0)
      << out;
  for (int v = 0; v < 6; ++v) {
    Image target, ours;
    ASSERT_TRUE(LoadViewImage(dataset, v, &target).ok());
    char name[64];
    std::snprintf(name, sizeof(name), "/r/images/%03d.exr", v);
    ASSERT_TRUE(ReadImage(tmp.path() + name, &ours).ok());
    double sum_t = 0, sum_o = 0;
    for (int y = 0; y < target.height; ++y) {
      for (int x = 0; x < target.width; ++x) {
        for (int c = 0; c < 3; ++c) {
          sum_t += target.at(x, y, c);
          sum_o += ours.at(x, y, c);
        }
      }
    }
    ASSERT_GT(sum_t, 0.0);
    // Independent seeds, 64 spp over ~300 object pixels (glossy, two bounces): the image means
    // agree within ~1%.
    EXPECT_NEAR(sum_o / sum_t, 1.0, 0.03) << "view " << v;
  }
  EXPECT_TRUE(std::filesystem::exists(tmp.Join("r/render.json")));
}

// --envmap lights the object by a probe copied into the dataset; a procedural material gives a
// spatially varying albedo; --pass albedo renders it back.
TEST(CliTest, SynthWithEnvironmentAndProceduralMaterial) {
  testing::TempDir tmp;
  const std::string mesh = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
  const std::string probe = testing::DataDir() + "/cycles/sphere_env_studio/probes/studio.exr";
  std::string out;
  ASSERT_EQ(
      RunSft("synth --quiet --mesh " + mesh + " --out " + tmp.Join("ds") + " --envmap " + probe +
                 " --background-environment --cameras 2 --zooms 1 --res 16 --spp 8 "
                 "--bounces 1 --material '{\"procedural\": \"wood\", \"colors\": "
                 "[[0.8, 0.6, 0.3], [0.3, 0.2, 0.1]], \"roughness\": 0.4, \"resolution\": 4}'",
             &out),
      0)
      << out;
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  ASSERT_EQ(dataset.lights.size(), 1u);
  EXPECT_EQ(dataset.lights[0].type, LightType::kEnvironment);
  EXPECT_EQ(dataset.background, Background::kEnvironment);
  ASSERT_TRUE(CheckDatasetFiles(dataset).ok());
  Image image;
  ASSERT_TRUE(LoadViewImage(dataset, 0, &image).ok());
  // The background shows the probe: the corner pixel is not black.
  EXPECT_GT(image.at(0, 0, 0) + image.at(0, 0, 1) + image.at(0, 0, 2), 0.0f);

  ASSERT_EQ(
      RunSft("render --quiet --dataset " + tmp.Join("ds") + " --mesh " +
                 tmp.Join("ds/gt/mesh.ply") + " --material " + tmp.Join("ds/gt/material.json") +
                 " --pass albedo --spp 4 --out " + tmp.Join("r"),
             &out),
      0)
      << out;
  Image albedo;
  ASSERT_TRUE(ReadImage(tmp.Join("r/images/000.exr"), &albedo).ok());
  // Spatially varying: fully covered pixels do not all share one albedo.
  float lo = 1e9f, hi = -1e9f;
  for (int y = 0; y < albedo.height; ++y) {
    for (int x = 0; x < albedo.width; ++x) {
      if (albedo.at(x, y, 3) < 1.0f) continue;
      lo = std::min(lo, albedo.at(x, y, 0));
      hi = std::max(hi, albedo.at(x, y, 0));
    }
  }
  EXPECT_GT(hi - lo, 0.05f);
  EXPECT_LE(hi, 0.8f + 1e-4f);
  EXPECT_GE(lo, 0.1f);
}

TEST(CliTest, BadInputGivesOneLineAndNonZeroExit) {
  testing::TempDir tmp;
  std::string out;
  EXPECT_NE(RunSft("synth --mesh " + tmp.Join("missing.obj") + " --out " + tmp.Join("ds"), &out),
            0);
  EXPECT_EQ(CountLines(out), 1) << out;
  EXPECT_THAT(out, HasSubstr("missing.obj"));

  EXPECT_NE(
      RunSft("render --dataset " + tmp.Join("nope") + " --mesh x.obj --out " + tmp.Join("o"), &out),
      0);
  EXPECT_EQ(CountLines(out), 1) << out;
  EXPECT_THAT(out, HasSubstr("nope"));

  const std::string ds = testing::DataDir() + "/cycles/bunny_point_diffuse";
  EXPECT_NE(RunSft("render --dataset " + ds + " --mesh " + ds + "/gt/mesh.ply --bounces 0 --out " +
                       tmp.Join("o"),
                   &out),
            0);
  EXPECT_EQ(CountLines(out), 1) << out;
  EXPECT_THAT(out, HasSubstr("bounces"));

  EXPECT_NE(RunSft("render --dataset " + ds + " --mesh " + ds + "/gt/mesh.ply --pass glow --out " +
                       tmp.Join("o"),
                   &out),
            0);
  EXPECT_THAT(out, HasSubstr("--pass"));

  EXPECT_NE(RunSft("render --dataset " + ds + " --mesh " + ds +
                       "/gt/mesh.ply --material '{\"albedo\": [2, 0, 0]}' --out " + tmp.Join("o"),
                   &out),
            0);
  EXPECT_EQ(CountLines(out), 1) << out;
  EXPECT_THAT(out, HasSubstr("albedo"));

  EXPECT_NE(RunSft("synth --mesh x.obj", &out), 0);  // --out missing: usage error.
  EXPECT_THAT(out, HasSubstr("--out"));
  EXPECT_FALSE(std::filesystem::exists(tmp.Join("o/images")));
}

}  // namespace
}  // namespace sft
