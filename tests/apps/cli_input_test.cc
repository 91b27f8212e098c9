// The `sft` command line on hostile and careless input (issue 9): huge cameras and out-of-range
// synth flags give one error line naming the field or flag and a non-zero exit, never a crash.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "src/core/memory.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountLines;
using testing::RunSft;

using ::testing::HasSubstr;

// A copy of the bunny point-light dataset's scene.json whose camera is width × height (the
// images are not needed: the commands stop before reading them).
std::string HugeCameraDataset(const testing::TempDir& tmp, int width, int height) {
  const std::string source = testing::DataDir() + "/cycles/bunny_point_diffuse/scene.json";
  nlohmann::json scene = nlohmann::json::parse(std::ifstream(source));
  for (auto& camera : scene["cameras"]) {
    camera["width"] = width;
    camera["height"] = height;
  }
  const std::string dir = tmp.Join("huge");
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/scene.json") << scene.dump(1);
  return dir;
}

TEST(CliInputTest, HugeCameraIsOneErrorNotBadAlloc) {
  testing::TempDir tmp;
  const std::string mesh = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
  std::string out;
  std::string dataset = HugeCameraDataset(tmp, 100000, 100000);
  EXPECT_EQ(
      RunSft("render --quiet --dataset " + dataset + " --mesh " + mesh + " --out " + tmp.Join("o"),
             &out),
      1)
      << out;
  EXPECT_EQ(CountLines(out), 1) << out;
  EXPECT_THAT(out, HasSubstr("cameras[0].width: 100000 is larger than the maximum 65536"));

  dataset = HugeCameraDataset(tmp, 32768, 32768);  // Within the read limits: 48 GiB to render.
  if (AvailableMemoryBytes() >= 48 * (uint64_t{1} << 30)) GTEST_SKIP() << "48 GiB available";
  EXPECT_EQ(
      RunSft("render --quiet --dataset " + dataset + " --mesh " + mesh + " --out " + tmp.Join("o"),
             &out),
      1)
      << out;
  EXPECT_EQ(CountLines(out), 1) << out;
  EXPECT_THAT(out, HasSubstr("needs an estimated 48 GB, more than the "));
  EXPECT_FALSE(std::filesystem::exists(tmp.Join("o/images")));
}

TEST(CliInputTest, SynthFlagsOutOfRangeNameTheFlag) {
  testing::TempDir tmp;
  const std::string base = "synth --quiet --mesh " + testing::DataDir() +
                           "/meshes/icosphere_r1_320f.obj --out " + tmp.Join("ds") + " ";
  const std::pair<const char*, const char*> cases[] = {
      {"--light-offset nan,0,0", "--light-offset: must be 3 finite numbers, got nan"},
      {"--light-offset 0,inf,0", "--light-offset: must be 3 finite numbers, got inf"},
      {"--light-intensity nan", "--light-intensity: must be in (0, 1e30] W/sr, got nan"},
      {"--light-intensity -1", "--light-intensity: must be in (0, 1e30] W/sr, got -1"},
      {"--light-intensity 0", "--light-intensity: must be in (0, 1e30] W/sr, got 0"},
      {"--fov nan", "--fov: must be in (0, 179) degrees, got nan"},
      {"--fov 180", "--fov: must be in (0, 179) degrees, got 180"},
      {"--fill nan", "--fill: must be in (0, 10], got nan"},
      {"--fill -0.5", "--fill: must be in (0, 10], got -0.5"},
      {"--res 0", "--res: must be in [1, 16384], got 0"},
      {"--res 100000", "--res: must be in [1, 16384], got 100000"},
      {"--cameras 0", "--cameras: must be in [1, 10000], got 0"},
      {"--zooms 1,nan", "--zooms: values must be in (0, 1000], got nan"},
      {"--zooms 1e300", "--zooms: values must be in (0, 1000], got 1e+300"},
      {"--envmap-scale inf", "--envmap-scale: must be in [0, 1e30], got inf"},
      {"--sun 0,0,0", "--sun: needs 3 finite numbers x,y,z, not all 0"},
      {"--sun 0,nan,1", "--sun: needs 3 finite numbers x,y,z, not all 0"},
      {"--sun 0,0,-1 --envmap p.exr", "--sun: give either --sun or --envmap, not both"},
      {"--sun 0,0,-1 --sun-irradiance 0", "--sun-irradiance: must be in (0, 1e30] W/m², got 0"},
      {"--spp 0", "spp: must be in [1, 1048576]"},
      {"--bounces 0", "bounces: must be in [1, 16]"},
  };
  for (const auto& [flags, message] : cases) {
    SCOPED_TRACE(flags);
    std::string out;
    EXPECT_EQ(RunSft(base + flags, &out), 1) << out;
    EXPECT_EQ(CountLines(out), 1) << out;
    EXPECT_THAT(out, HasSubstr(message));
    EXPECT_FALSE(std::filesystem::exists(tmp.Join("ds")));
  }
  // The flags given explicitly at valid values are used (the intensity is not replaced by the
  // automatic value): the dataset's light has intensity 2.
  std::string out;
  ASSERT_EQ(
      RunSft(
          base + "--cameras 1 --zooms 1 --res 8 --spp 1 --light-intensity 2 --light-offset 0.1,0,0",
          &out),
      0)
      << out;
  const nlohmann::json scene = nlohmann::json::parse(std::ifstream(tmp.Join("ds/scene.json")));
  EXPECT_EQ(scene["lights"][0]["intensity"], nlohmann::json::parse("[2.0, 2.0, 2.0]"));
}

}  // namespace
}  // namespace sft
