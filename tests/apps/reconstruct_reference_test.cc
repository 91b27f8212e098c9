// sft reconstruct --reference MESH: after every outer iteration metrics.json's "outer" entry
// carries the Chamfer distance and F1 of the current mesh against the reference (and the F1
// tolerance used); a --reference that cannot be read is one error line naming it, and the run
// writes nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "src/eval/mesh_metrics.h"
#include "src/geometry/mesh.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using testing::CountLines;
using ::testing::HasSubstr;
using testing::RunSft;

// A tiny geometry run (2 views of 16², 2 outer iterations of 1 LM step) from a perturbed start,
// with the true mesh as --reference and a tolerance other than the default, so that the flag's
// value is seen to reach metrics.json.
TEST(ReconstructReferenceTest, EveryOuterEntryCarriesChamferAndF1) {
  testing::TempDir tmp;
  ASSERT_EQ(
      testing::SynthIcosphere(tmp.Join("ds"), "--cameras 2 --zooms 1 --res 16 --spp 8 --bounces 1"),
      "");
  std::string out;
  ASSERT_EQ(RunSft("perturb --mesh " + tmp.Join("ds/gt/mesh.ply") + " --out " +
                       tmp.Join("init.ply") + " --amplitude 0.02 --seed 3",
                   &out),
            0)
      << out;
  const std::string reference = tmp.Join("ds/gt/mesh.ply");
  ASSERT_EQ(RunSft("reconstruct --quiet --no-report --dataset " + tmp.Join("ds") + " --init " +
                       tmp.Join("init.ply") + " --out " + tmp.Join("r") +
                       " --phases geometry --outer 2 --steps 1 --spp 4 --bounces 1 --reference " +
                       reference + " --reference-tolerance 0.02",
                   &out),
            0)
      << out;
  const nlohmann::json metrics =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("r/metrics.json")), nullptr, false);
  ASSERT_TRUE(metrics.is_object()) << "metrics.json does not parse";
  ASSERT_TRUE(metrics.contains("outer") && metrics["outer"].is_array());
  ASSERT_EQ(metrics["outer"].size(), 2u);
  for (const nlohmann::json& entry : metrics["outer"]) {
    SCOPED_TRACE(entry.dump());
    for (const char* key : {"chamfer", "f1", "f1_tolerance"}) {
      ASSERT_TRUE(entry.contains(key) && entry[key].is_number()) << key;
      EXPECT_TRUE(std::isfinite(entry[key].get<double>())) << key;
    }
    // A 2% perturbation of a unit-diagonal sphere: the mesh is near the reference but not on it.
    EXPECT_GT(entry["chamfer"].get<double>(), 0.0);
    EXPECT_LT(entry["chamfer"].get<double>(), 0.05);
    EXPECT_GE(entry["f1"].get<double>(), 0.0);
    EXPECT_LE(entry["f1"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(entry["f1_tolerance"].get<double>(), 0.02);
  }

  // The last entry scores the mesh the run wrote: recomputed here from mesh.ply with the same
  // sample count (PLY stores floats, hence the small relative tolerance).
  TriMesh truth, fitted;
  ASSERT_TRUE(ReadMesh(reference, &truth).ok());
  ASSERT_TRUE(ReadMesh(tmp.Join("r/mesh.ply"), &fitted).ok());
  MeshMetricsOptions options;
  options.samples = 50000;
  options.tolerance = 0.02;
  MeshMetrics expected;
  ASSERT_TRUE(ComputeMeshMetrics(truth, fitted, options, &expected).ok());
  const nlohmann::json& last = metrics["outer"].back();
  EXPECT_NEAR(last["chamfer"].get<double>(), expected.chamfer, 0.01 * expected.chamfer);
  EXPECT_NEAR(last["f1"].get<double>(), expected.f1, 0.01);
}

// A --reference that does not exist, or is not a mesh: exit 1, one line naming the file, and no
// output folder (the reference is read before anything is written).
TEST(ReconstructReferenceTest, UnreadableReferenceIsOneLineAndWritesNothing) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 1 --zooms 1 --res 8 --spp 2"), "");
  testing::WriteTestFile(tmp.Join("garbage.ply"), "ply\nformat ascii 1.0\nelement vertex 3\n");
  const std::string base = "reconstruct --quiet --dataset " + tmp.Join("ds") + " --init " +
                           tmp.Join("ds/gt/mesh.ply") + " --steps 1 --outer 1 --spp 2";
  for (const std::string& reference :
       {tmp.Join("no_such_reference.ply"), tmp.Join("garbage.ply")}) {
    SCOPED_TRACE(reference);
    const std::string out_dir = tmp.Join("r");
    std::string out;
    EXPECT_EQ(RunSft(base + " --out " + out_dir + " --reference " + reference, &out), 1);
    EXPECT_THAT(out, HasSubstr(reference));
    EXPECT_EQ(CountLines(out), 1) << out;
    EXPECT_FALSE(fs::exists(out_dir)) << "the failed run wrote " << out_dir;
  }
}

}  // namespace
}  // namespace sft
