// `sft render --pass normal|depth|albedo|roughness` needs no light: a dataset with unknown
// lighting (every view's `lights` empty) renders exactly what the lit dataset renders, while the
// colour pass still refuses it with one line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

TEST(RenderUnlitPassesTest, GeometryPassesRenderDatasetsWithoutLights) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("lit"), "--cameras 2 --zooms 1 --res 16 --spp 1"), "");
  ASSERT_EQ(testing::RunCommand("cp -r " + tmp.Join("lit") + " " + tmp.Join("unlit")), 0);
  nlohmann::json scene = nlohmann::json::parse(testing::ReadTestFile(tmp.Join("unlit/scene.json")));
  scene["lights"] = nlohmann::json::array();
  for (auto& view : scene["views"]) view["lights"] = nlohmann::json::array();
  scene["lighting"] = "unknown";
  testing::WriteTestFile(tmp.Join("unlit/scene.json"), scene.dump(1));
  const std::string mesh = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
  for (const char* pass : {"normal", "depth", "albedo", "roughness"}) {
    SCOPED_TRACE(pass);
    for (const char* lighting : {"lit", "unlit"}) {
      std::string output;
      ASSERT_EQ(testing::RunSft(std::string("render --quiet --no-report --spp 2 --pass ") + pass +
                                    " --dataset " + tmp.Join(lighting) + " --mesh " + mesh +
                                    " --out " + tmp.Join(std::string(pass) + "_" + lighting),
                                &output),
                0)
          << output;
    }
    for (const char* image : {"/images/000.exr", "/images/001.exr"}) {
      const std::string lit = testing::ReadTestFile(tmp.Join(std::string(pass) + "_lit" + image));
      EXPECT_FALSE(lit.empty());
      EXPECT_TRUE(lit == testing::ReadTestFile(tmp.Join(std::string(pass) + "_unlit" + image)));
    }
  }
  std::string output;
  EXPECT_EQ(testing::RunSft("render --quiet --dataset " + tmp.Join("unlit") + " --mesh " + mesh +
                                " --out " + tmp.Join("color"),
                            &output),
            1);
  EXPECT_THAT(output, HasSubstr("views[0].lights: empty (unknown lighting"));
  EXPECT_EQ(testing::CountLines(output), 1);
}

}  // namespace
}  // namespace sft
