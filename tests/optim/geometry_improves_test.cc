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

// The tests' case under `tmp`: ds/ (8 views of 32² of a unit-diagonal icosphere, Lambertian) and
// init.ply (the true mesh displaced by a smooth field of at most 2% of the diagonal, seed 4).
// Returns "" or what failed.
std::string PerturbedSphere(const testing::TempDir& tmp) {
  const std::string error =
      testing::SynthIcosphere(tmp.Join("ds"),
                              "--cameras 8 --zooms 1 --res 32 --spp 32 --bounces 1 "
                              "--material '{\"albedo\": [0.7, 0.6, 0.5], \"roughness\": 0.5}'");
  if (!error.empty()) return error;
  std::string out;
  if (RunSft("perturb --mesh " + tmp.Join("ds/gt/mesh.ply") + " --out " + tmp.Join("init.ply") +
                 " --amplitude 0.02 --seed 4",
             &out) != 0) {
    return "sft perturb failed: " + out;
  }
  return "";
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
  ASSERT_EQ(PerturbedSphere(tmp), "");
  const std::string truth = tmp.Join("ds/gt/mesh.ply");
  std::string out;
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

// The same sphere and start under Adam on the large-steps parameterisation (λ 25, uniform second
// moment, a new seed per step, minibatches of 4 of the 8 views; src/optim/large_steps.h), one
// outer iteration of 40 steps (~2 s). Measured 2026-11-26: Chamfer 4.14e-3 -> 1.87e-3 (0.45);
// plain Adam (λ 0, per-coordinate moments) reaches 5.5e-4 on this small easy case, so this test
// does not claim that large steps are faster here, only that they descend. It asserts a fall to
// below 0.65 × the start, and a control with the image term off (image_weight 0: the same
// steps driven by regularizers alone) must leave the mesh where it was (above 0.95 × the start).
TEST(GeometryImprovesTest, AdamWithLargeStepsLowersChamferOnAPerturbedSphere) {
  testing::TempDir tmp;
  ASSERT_EQ(PerturbedSphere(tmp), "");
  const std::string truth = tmp.Join("ds/gt/mesh.ply");
  std::string out;
  const auto run = [&](const std::string& name, double image_weight) {
    const std::string config = tmp.Join(name + ".json");
    testing::WriteTestFile(
        config,
        "{\"solver\": \"adam\", \"adam_large_steps\": 25, \"adam_uniform\": true, "
        "\"adam_resample\": true, \"adam_views_per_step\": 4, \"adam_lr_vertices\": 0.002, "
        "\"effects\": \"all\", \"image_weight\": " +
            std::to_string(image_weight) + "}");
    std::string log;
    EXPECT_EQ(RunSft("reconstruct --quiet --no-report --dataset " + tmp.Join("ds") + " --init " +
                         tmp.Join("init.ply") + " --material " + tmp.Join("ds/gt/material.json") +
                         " --out " + tmp.Join(name) + " --config " + config +
                         " --phases geometry --outer 1 --steps 40 --spp 8 --bounces 1",
                     &log),
              0)
        << log;
    return Chamfer(truth, tmp.Join(name + "/mesh.ply"));
  };
  const double before = Chamfer(truth, tmp.Join("init.ply"));
  const double after = run("large", 1.0);
  const double control = run("control", 0.0);
  RecordProperty("chamfer_before", std::to_string(before));
  RecordProperty("chamfer_after", std::to_string(after));
  RecordProperty("chamfer_control", std::to_string(control));
  EXPECT_LT(after, 0.65 * before) << "Chamfer " << before << " -> " << after;
  EXPECT_GT(control, 0.95 * before) << "without the image term: " << before << " -> " << control;
}

}  // namespace
}  // namespace sft
