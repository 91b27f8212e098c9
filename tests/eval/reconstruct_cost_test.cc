// `sft bench reconstruct`'s measurement: the time split of a solver call adds up to its wall time,
// every part that ran is positive, and the report and its JSON carry the problem's size.
#include "src/eval/reconstruct_cost.h"

#include <gtest/gtest.h>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

// Every field of the split, listed here rather than through TimeSplitParts, so that a part the
// list forgets makes the sum disagree.
double Sum(const SolverTimeSplit& t) {
  return t.superset_renders + t.problem_assembly + t.solve_startup + t.render + t.pyramid +
         t.evaluation + t.linear_solver + t.other;
}

class ReconstructCostTest : public ::testing::TestWithParam<const char*> {};

TEST_P(ReconstructCostTest, TimeSplitAddsUpToTheWallTime) {
  testing::TempDir dir;
  ASSERT_EQ(testing::SynthIcosphere(dir.Join("ds"),
                                    "--cameras 2 --zooms 1 --res 24 --spp 16 --bounces 1"),
            "");
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.Join("ds"), &dataset).ok());
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(dir.Join("ds/gt/mesh.ply"), &mesh).ok());
  Material material;
  ASSERT_TRUE(
      LoadMaterial(R"({"albedo": [0.5, 0.5, 0.5], "roughness": 0.5})", mesh, &material).ok());
  ReconstructCostOptions options;
  ASSERT_TRUE(SolverKindFromName(GetParam(), &options.reconstruct.solver.kind));
  options.reconstruct.phases = PhaseSchedule::kAlternate;
  options.reconstruct.solver.steps = 2;
  options.reconstruct.cache.render.spp = 4;
  options.reconstruct.cache.render.bounces = 1;
  ReconstructCostReport report;
  ASSERT_TRUE(MeasureReconstructCost(dataset, mesh, material, options, &report).ok());

  EXPECT_EQ(report.views, 2);
  EXPECT_EQ(report.pixels, 2 * 24 * 24);
  EXPECT_EQ(report.faces, static_cast<int>(mesh.n_faces()));
  EXPECT_GT(report.forward_seconds, 0.0);
  ASSERT_EQ(report.phases_run.size(), 2u);  // texture, then geometry.
  const bool trust_region = std::string(GetParam()) == "lm";
  for (const PhaseRecord& phase : report.phases_run) {
    const SolverRunStats& s = phase.stats;
    SCOPED_TRACE(phase.phase);
    EXPECT_GT(s.iterations, 0);
    EXPECT_GE(s.evaluations, s.iterations);
    EXPECT_GT(s.time.render, 0.0);
    EXPECT_GE(s.time.other, 0.0);
    // The parts add up to the call's wall time (the remainder is `other`, never negative).
    EXPECT_NEAR(Sum(s.time), s.seconds, 1e-9 + 1e-9 * s.seconds);
    if (trust_region) {
      EXPECT_GT(s.time.superset_renders, 0.0);
      EXPECT_GT(s.problem.residual_blocks, 0);
    } else {
      EXPECT_EQ(s.time.superset_renders, 0.0);
      EXPECT_EQ(s.time.linear_solver, 0.0);
    }
  }
  const nlohmann::json json = ReconstructCostToJson(report);
  ASSERT_EQ(json["phase_runs"].size(), 2u);
  EXPECT_TRUE(json["phase_runs"][1]["time_split"].contains("linear_solver"));
  EXPECT_GT(json["phase_runs"][1]["seconds_per_iteration"].get<double>(), 0.0);
  EXPECT_NE(ReconstructCostTable(report).find("per iteration"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Solvers, ReconstructCostTest, ::testing::Values("lm", "lbfgs", "adam"));

}  // namespace
}  // namespace sft
