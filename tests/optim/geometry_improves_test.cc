// A geometry phase improves a mesh: a small synthesized sphere dataset, a start displaced by a
// smooth random field (`sft perturb`), a short geometry-only `sft reconstruct` with the true
// material, and the Chamfer distance to the true mesh (src/eval/mesh_metrics.h) must fall by a
// stated margin. Through the CLI, whose flags are the stable interface of the schedule.
#include <gtest/gtest.h>

#include <string>

#include "src/eval/mesh_metrics.h"
#include "src/geometry/mesh.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::RunSft;

// Chamfer distance of `mesh_path` to `reference_path` (fraction of the reference's diagonal),
// 50k samples per surface as `sft reconstruct --reference` uses.
double Chamfer(const std::string& reference_path, const std::string& mesh_path) {
  TriMesh reference, mesh;
  EXPECT_TRUE(ReadMesh(reference_path, &reference).ok()) << reference_path;
  EXPECT_TRUE(ReadMesh(mesh_path, &mesh).ok()) << mesh_path;
  MeshMetricsOptions options;
  options.samples = 50000;
  MeshMetrics metrics;
  const Status status = ComputeMeshMetrics(reference, mesh, options, &metrics);
  EXPECT_TRUE(status.ok()) << status.message();
  return metrics.chamfer;
}

// 8 views of 32² of a unit-diagonal icosphere, start displaced by at most 2% of the diagonal,
// 2 outer iterations × 5 LM steps of geometry at 8 spp with the true material (~4 s on 2 cores).
// Measured 2026-11-26 over perturbation seeds 1–6: Chamfer 4.1e-3–6.5e-3 before, 4.9e-4–5.9e-4
// after (a noise floor), after/before 0.088, 0.094, 0.088, 0.126 (seed 4), 0.093, 0.105. The test
// runs the worst seed (4) and asserts a fall of at least 70% (after < 0.3 × before), a margin of
// 2.4× over the worst measured ratio; with the image term off (config image_weight 0) the same run
// leaves the Chamfer distance unchanged (ratio 1.0), so a geometry phase that does not follow the
// images fails it.
TEST(GeometryImprovesTest, ChamferFallsBySeventyPercentOnAPerturbedSphere) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"),
                                    "--cameras 8 --zooms 1 --res 32 --spp 32 --bounces 1 "
                                    "--material '{\"albedo\": [0.7, 0.6, 0.5], \"roughness\": "
                                    "0.5}'"),
            "");
  const std::string truth = tmp.Join("ds/gt/mesh.ply");
  std::string out;
  ASSERT_EQ(RunSft("perturb --mesh " + truth + " --out " + tmp.Join("init.ply") +
                       " --amplitude 0.02 --seed 4",
                   &out),
            0)
      << out;
  ASSERT_EQ(RunSft("reconstruct --quiet --no-report --dataset " + tmp.Join("ds") + " --init " +
                       tmp.Join("init.ply") + " --material " + tmp.Join("ds/gt/material.json") +
                       " --out " + tmp.Join("r") +
                       " --phases geometry --outer 2 --steps 5 --spp 8 --bounces 1",
                   &out),
            0)
      << out;
  const double before = Chamfer(truth, tmp.Join("init.ply"));
  const double after = Chamfer(truth, tmp.Join("r/mesh.ply"));
  RecordProperty("chamfer_before", std::to_string(before));
  RecordProperty("chamfer_after", std::to_string(after));
  EXPECT_GT(before, 0.002) << "the start is not perturbed enough to measure an improvement";
  EXPECT_LT(after, 0.3 * before) << "Chamfer " << before << " -> " << after;
}

}  // namespace
}  // namespace sft
