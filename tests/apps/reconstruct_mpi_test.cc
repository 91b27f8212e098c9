// `mpirun -np N sft reconstruct` (src/optim/mpi_views.h): the same mesh and material to the last
// bit as one process, with LM (Jacobian rows) and with Adam (adjoint gradients), also under
// unknown lighting (a fitted environment, whose texels the other rank receives); wrong usage is
// one line and a non-zero exit; a rank that dies mid-run ends it with one line and a checkpoint
// that one process resumes. Skipped when sft was built without MPI or mpirun is absent.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// "mpirun --oversubscribe [--allow-run-as-root]" (more ranks than this machine's cores; root
// in containers), or "" when there is none.
std::string Mpirun() {
  const std::string mpirun = SFT_MPIEXEC;
  if (mpirun.empty() || !fs::exists(mpirun)) return "";
  return mpirun + " --oversubscribe" + (geteuid() == 0 ? " --allow-run-as-root" : "");
}

// Every output of a run whose bytes are its result (not timings): the meshes, the material and
// its mesh-colors files, the light scales, the stages' normal images, the exported asset (not its
// export.json, which holds timings).
std::set<std::string> ResultFiles(const std::string& dir) {
  const std::set<std::string> skip = {"metrics.json", "metrics.csv", "state.json", "report.html",
                                      "export/export.json"};
  std::set<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(entry.path(), dir).string();
    if (entry.is_regular_file() && skip.count(name) == 0) files.insert(name);
  }
  return files;
}

class ReconstructMpiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    mpirun_ = Mpirun();
    if (mpirun_.empty()) GTEST_SKIP() << "no MPI (built without SFT_MPI or mpirun missing)";
    ASSERT_EQ(testing::SynthIcosphere(tmp_.Join("ds"),
                                      "--cameras 4 --zooms 1 --res 24 --spp 16 --bounces 1 "
                                      "--material '{\"albedo\": [0.6, 0.5, 0.4], "
                                      "\"roughness\": 0.5}'"),
              "");
    std::string out;
    ASSERT_EQ(testing::RunSft("perturb --mesh " + tmp_.Join("ds/gt/mesh.ply") + " --out " +
                                  tmp_.Join("init.ply") + " --amplitude 0.02 --seed 2",
                              &out),
              0)
        << out;
  }

  // The dataset of SetUp with its lights removed, as "ds_unlit": unknown lighting, which sft
  // reconstruct fits as an environment map (src/optim/fitted_environment.h).
  void MakeUnlitDataset() {
    fs::copy(tmp_.Join("ds"), tmp_.Join("ds_unlit"), fs::copy_options::recursive);
    nlohmann::json scene =
        nlohmann::json::parse(testing::ReadTestFile(tmp_.Join("ds_unlit/scene.json")));
    scene["lights"] = nlohmann::json::array();
    for (nlohmann::json& view : scene["views"]) view["lights"] = nlohmann::json::array();
    testing::WriteTestFile(tmp_.Join("ds_unlit/scene.json"), scene.dump(1));
  }

  // One process, then 2 ranks, on `dataset` (a folder of tmp_): every result file must be
  // identical, and rank 1 must have rendered some of the views.
  // `flags` are added to both runs; `tag` names their folders (DATASET_SOLVERTAG1 and ..2).
  void ExpectSameAcrossRanks(const std::string& solver, const std::string& dataset = "ds",
                             const std::string& flags = "", const std::string& tag = "") {
    const std::string args = "reconstruct --quiet --no-report --dataset " + tmp_.Join(dataset) +
                             " --init " + tmp_.Join("init.ply") +
                             " --spp 4 --bounces 1 --steps 2 --outer 1 --phases alternate"
                             " --threads 1 " +
                             flags + " --solver " + solver + " --out ";
    const std::string one_dir = tmp_.Join(dataset + "_" + solver + tag + "1");
    const std::string two_dir = tmp_.Join(dataset + "_" + solver + tag + "2");
    std::string out;
    ASSERT_EQ(testing::RunSft(args + one_dir, &out), 0) << out;
    ASSERT_EQ(testing::RunCommand(mpirun_ + " -np 2 " + testing::SftBinary() + " " + args + two_dir,
                                  &out),
              0)
        << out;
    const std::set<std::string> files = ResultFiles(one_dir);
    EXPECT_EQ(files, ResultFiles(two_dir));
    for (const char* file : {"mesh.ply", "material.json"}) EXPECT_EQ(files.count(file), 1u) << file;
    for (const std::string& file : files) {
      const std::string one = testing::ReadTestFile(one_dir + "/" + file);
      EXPECT_FALSE(one.empty()) << file;
      EXPECT_TRUE(one == testing::ReadTestFile(two_dir + "/" + file))
          << solver << " on " << dataset << ": " << file << " differs between 1 and 2 ranks";
    }
    // Rank 0 reports where its time went; the other rank rendered views.
    const nlohmann::json metrics = nlohmann::json::parse(
        testing::ReadTestFile(two_dir + "/metrics.json"), nullptr, /*allow_exceptions=*/false);
    ASSERT_TRUE(metrics.is_object() && metrics.contains("mpi")) << metrics.dump(1);
    EXPECT_TRUE(metrics["mpi"]["seconds"].contains("imbalance")) << metrics["mpi"].dump(1);
    EXPECT_GT(metrics["mpi"].value("remote_jobs", int64_t{0}), 0) << metrics["mpi"].dump(1);
  }

  testing::TempDir tmp_;
  std::string mpirun_;
};

TEST_F(ReconstructMpiTest, LevenbergMarquardtIsBitIdenticalOnTwoRanks) {
  ExpectSameAcrossRanks("lm");
}

TEST_F(ReconstructMpiTest, AdamIsBitIdenticalOnTwoRanks) { ExpectSameAcrossRanks("adam"); }

// Unknown lighting: the fitted environment's texels travel with the state, rank 1 renders its
// share under them (rows and adjoint gradients of the texels included), and the fitted map
// (environment.exr) is one of the identical files.
TEST_F(ReconstructMpiTest, FittedEnvironmentIsBitIdenticalOnTwoRanks) {
  MakeUnlitDataset();
  ExpectSameAcrossRanks("lm", "ds_unlit");
  ExpectSameAcrossRanks("adam", "ds_unlit");
  EXPECT_TRUE(fs::exists(tmp_.Join("ds_unlit_lm2/environment.exr")));
  EXPECT_TRUE(fs::exists(tmp_.Join("ds_unlit_adam2/environment.exr")));
}

// A lamp estimated beside the fitted map (--estimate-lights): rank 0 sends it in the handshake,
// rank 1 adds it before the map as rank 0 did, and the fitted lamp (lights.json) is one of the
// identical files.
TEST_F(ReconstructMpiTest, EstimatedLampIsBitIdenticalOnTwoRanks) {
  MakeUnlitDataset();
  testing::WriteTestFile(tmp_.Join("lamp.json"), R"({"lights": [{"id": "lamp", "type": "point",
      "frame": "world", "position": [0.8, -0.6, 1.0], "intensity": [2, 2, 2]}]})");
  ExpectSameAcrossRanks("lm", "ds_unlit", "--estimate-lights " + tmp_.Join("lamp.json"), "_lamp");
  const std::string lights = testing::ReadTestFile(tmp_.Join("ds_unlit_lm_lamp2/lights.json"));
  EXPECT_NE(lights.find("\"lamp\""), std::string::npos) << lights;
  EXPECT_TRUE(fs::exists(tmp_.Join("ds_unlit_lm_lamp2/estimated_lights.json")));
}

// A camera-fixed fitted map (--environment-frame camera): every view turns it with its camera, on
// whichever rank renders the view, and the run records its frame.
TEST_F(ReconstructMpiTest, CameraFixedEnvironmentIsBitIdenticalOnTwoRanks) {
  MakeUnlitDataset();
  ExpectSameAcrossRanks("lm", "ds_unlit", "--environment-frame camera", "_camera");
  const std::string info = testing::ReadTestFile(tmp_.Join("ds_unlit_lm_camera2/environment.json"));
  EXPECT_NE(info.find("\"camera\""), std::string::npos) << info;
  // The same fit with the map fixed in the world gives another map.
  ExpectSameAcrossRanks("lm", "ds_unlit", "", "_world");
  EXPECT_NE(testing::ReadTestFile(tmp_.Join("ds_unlit_lm_camera1/environment.exr")),
            testing::ReadTestFile(tmp_.Join("ds_unlit_lm_world1/environment.exr")));
}

// More ranks than views, and a worker that cannot read the dataset (its working directory has
// no "ds"): one error line on rank 0, a non-zero exit, nothing hangs, nothing is written.
TEST_F(ReconstructMpiTest, WrongUsageIsOneLine) {
  const std::string args = " reconstruct --quiet --no-report --dataset ds --init " +
                           tmp_.Join("init.ply") + " --steps 1 --outer 1 --threads 1 --out ";
  std::string out;
  EXPECT_NE(testing::RunCommand("cd " + tmp_.path() + " && " + mpirun_ + " -np 5 " +
                                    testing::SftBinary() + args + tmp_.Join("five"),
                                &out),
            0);
  EXPECT_THAT(out, HasSubstr("more ranks than the 4 views fitted"));
  EXPECT_FALSE(fs::exists(tmp_.Join("five/state.json")));

  fs::create_directories(tmp_.Join("elsewhere"));
  EXPECT_NE(testing::RunCommand(mpirun_ + " -np 1 --wdir " + tmp_.path() + " " +
                                    testing::SftBinary() + args + tmp_.Join("unshared") +
                                    " : -np 1 --wdir " + tmp_.Join("elsewhere") + " " +
                                    testing::SftBinary() + args + tmp_.Join("unshared"),
                                &out),
            0);
  EXPECT_THAT(out, HasSubstr("rank 1: "));
  EXPECT_THAT(out, HasSubstr("every rank reads the dataset from the same path: ds"));
  EXPECT_FALSE(fs::exists(tmp_.Join("unshared/state.json")));
}

// Rank 1 kills itself (SIGKILL, the test hook SFT_TEST_MPI_DIE_AFTER_JOBS) after 8 results, in
// the first outer iteration: rank 0 finishes the evaluation alone, stops after the solver
// iteration, writes its checkpoint and prints one line; the run ends non-zero and one process
// resumes it to the end. Open MPI's launcher kills every rank 1 + 1 s after a death by default
// (SIGTERM, then SIGKILL: odls_base_sigkill_timeout); 4 s keeps a loaded machine from cutting
// rank 0 short, and mpirun then ends about 8 s after the death.
TEST_F(ReconstructMpiTest, KilledRankEndsTheRunResumably) {
  const std::string out = tmp_.Join("killed");
  const std::string args = " reconstruct --quiet --no-report --dataset " + tmp_.Join("ds") +
                           " --init " + tmp_.Join("init.ply") +
                           " --spp 4 --bounces 1 --steps 3 --outer 3 --phases alternate"
                           " --threads 1 --solver lm --out " +
                           out;
  std::string output;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_NE(testing::RunCommand("SFT_TEST_MPI_DIE_AFTER_JOBS=8 " + mpirun_ +
                                    " --bind-to none --mca odls_base_sigkill_timeout 4 -np 2 " +
                                    testing::SftBinary() + args,
                                &output),
            0);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 60.0) << output;
  EXPECT_THAT(output,
              HasSubstr("sft reconstruct: error: rank 1 stopped answering (died or was "
                        "killed); state written to " +
                        out + " (continue with --resume " + out + ", with any number of ranks)"));
  EXPECT_EQ(testing::CountOccurrences(output, "sft reconstruct: error"), 1) << output;
  const std::string state = testing::ReadTestFile(out + "/state.json");
  ASSERT_FALSE(state.empty()) << output;
  EXPECT_THAT(state, HasSubstr("\"finished\": false"));

  EXPECT_EQ(testing::RunSft("reconstruct --no-report --resume " + out, &output), 0) << output;
  EXPECT_THAT(output, HasSubstr("sft reconstruct: 3 outer iterations"));
}

}  // namespace
}  // namespace sft
