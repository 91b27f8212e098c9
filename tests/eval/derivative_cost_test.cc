#include "src/eval/derivative_cost.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "src/core/file_util.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

constexpr int kViews = 2;
constexpr int kRes = 32;
constexpr int kSpp = 2;

DerivativeCostOptions SmallOptions() {
  DerivativeCostOptions options;
  options.views = kViews;
  options.resolution = kRes;
  options.spp = kSpp;
  return options;
}

// The forward pass traces exactly one camera ray per sample; the derivative passes trace at least
// those (edge sampling of vertex derivatives may add rays of its own).
void ExpectPassOk(const DerivativePassCost& pass, const char* name, bool derivatives) {
  EXPECT_GT(pass.seconds, 0.0) << name;
  EXPECT_TRUE(std::isfinite(pass.seconds)) << name;
  EXPECT_GT(pass.ratio, 0.0) << name;
  EXPECT_TRUE(std::isfinite(pass.ratio)) << name;
  const int64_t samples = int64_t{kViews} * kRes * kRes * kSpp;
  if (derivatives) {
    EXPECT_GE(pass.rays.camera_rays, samples) << name;
  } else {
    EXPECT_EQ(pass.rays.camera_rays, samples) << name;
  }
}

// Performance is not asserted: only that the passes run and the counts are consistent.
TEST(DerivativeCostTest, SmallRunIsConsistent) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/bunny_watertight_5k.obj", &mesh).ok());
  DerivativeCostReport report;
  const Status status = MeasureDerivativeCost(SmallOptions(), mesh, &report);
  ASSERT_TRUE(status.ok()) << status.message();

  EXPECT_EQ(report.num_faces, static_cast<int>(mesh.n_faces()));
  EXPECT_EQ(report.views, kViews);
  EXPECT_GE(report.threads, 1);
  // The mesh fills ~60% of the image: seen, but not everywhere.
  EXPECT_GT(report.covered_pixels, kViews * kRes * kRes / 20);
  EXPECT_LT(report.covered_pixels, kViews * kRes * kRes);
  ExpectPassOk(report.forward, "forward", false);
  ExpectPassOk(report.jacobian_rows, "jacobian_rows", true);
  ExpectPassOk(report.adjoint, "adjoint", true);
  EXPECT_DOUBLE_EQ(report.forward.ratio, 1.0);
  // The same sample paths in every pass, plus the edge samples of the derivative passes (the
  // same in both: they do not depend on what is output).
  EXPECT_GE(report.jacobian_rows.rays.TotalRays(), report.forward.rays.TotalRays());
  EXPECT_EQ(report.adjoint.rays.TotalRays(), report.jacobian_rows.rays.TotalRays());

  // Every parameter is differentiated: vertex coordinates, albedo (RGB) and roughness texels at
  // resolution 2, the specular weight, one light.
  const int texels = static_cast<int>(mesh.n_faces()) * 6;
  EXPECT_EQ(report.num_parameters,
            3 * static_cast<int>(mesh.n_vertices()) + 3 * texels + texels + 1 + 1);
  EXPECT_EQ(report.num_differentiated, report.num_parameters);

  EXPECT_GT(report.jacobian_entries, 0);
  EXPECT_GE(report.rows_bytes_total,
            report.jacobian_entries * static_cast<int64_t>(sizeof(JacobianEntry)));
  EXPECT_GE(report.rows_bytes_peak_view, report.rows_bytes_total / kViews);
  EXPECT_LE(report.rows_bytes_peak_view, report.rows_bytes_total);
  EXPECT_EQ(report.rows_bytes_resident, report.rows_bytes_peak_view);  // one view at a time.
  EXPECT_GT(report.gradient_norm, 0.0);
  EXPECT_TRUE(std::isfinite(report.gradient_norm));

  const nlohmann::json json = DerivativeCostReportToJson(report);
  EXPECT_EQ(json["jacobian_rows"]["entries"].get<int64_t>(), report.jacobian_entries);
  EXPECT_EQ(json["parameters"]["kinds"][0].get<std::string>(), "vertices");
  EXPECT_FALSE(json["parameters"].contains("not_implemented"));
  EXPECT_TRUE(json["passes"].contains("adjoint"));
  const std::string table = DerivativeCostReportTable(report);
  EXPECT_NE(table.find("(vertices, albedo"), std::string::npos) << table;
  EXPECT_EQ(table.find("not implemented"), std::string::npos) << table;
}

// Holding every view's rows: the same entries, all resident at once.
TEST(DerivativeCostTest, KeepRowsHoldsTheTotal) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &mesh).ok());
  DerivativeCostOptions options = SmallOptions();
  DerivativeCostReport one_at_a_time, kept;
  ASSERT_TRUE(MeasureDerivativeCost(options, mesh, &one_at_a_time).ok());
  options.keep_rows = true;
  ASSERT_TRUE(MeasureDerivativeCost(options, mesh, &kept).ok());
  EXPECT_EQ(kept.jacobian_entries, one_at_a_time.jacobian_entries);  // deterministic.
  EXPECT_EQ(kept.rows_bytes_resident, kept.rows_bytes_total);
  EXPECT_TRUE(kept.keep_rows);
}

// The noise measurement falls with the samples (8× the samples: at least 1/√8 of the noise; at
// 2 spp the few edge samples also give heavy tails, so it falls further), and cost × variance is
// reported with it.
TEST(DerivativeCostTest, NoiseFallsWithSamples) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &mesh).ok());
  DerivativeCostOptions options = SmallOptions();
  options.bounces = 1;
  options.noise_seeds = 6;
  double noise[2];
  for (int i = 0; i < 2; ++i) {
    options.spp = i == 0 ? 2 : 16;
    DerivativeCostReport report;
    ASSERT_TRUE(MeasureDerivativeCost(options, mesh, &report).ok());
    EXPECT_EQ(report.noise_seeds, 6);
    EXPECT_GT(report.vertex_noise, 0.0);
    EXPECT_TRUE(std::isfinite(report.vertex_noise));
    EXPECT_GT(report.noise_adjoint_seconds, 0.0);
    EXPECT_GT(report.noise_forward_seconds, 0.0);
    EXPECT_NEAR(report.cost_times_variance,
                report.noise_adjoint_seconds / report.noise_forward_seconds * report.vertex_noise *
                    report.vertex_noise,
                1e-9 * report.cost_times_variance);
    EXPECT_TRUE(DerivativeCostReportToJson(report).contains("noise"));
    noise[i] = report.vertex_noise;
  }
  EXPECT_LT(noise[1], 0.5 * noise[0]) << noise[0] << " " << noise[1];
}

TEST(DerivativeCostTest, OptionsCheck) {
  std::string why;
  DerivativeCostOptions options;
  EXPECT_TRUE(options.Check(&why));
  options.views = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("views"), std::string::npos);
  options = DerivativeCostOptions();
  options.resolution = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("res"), std::string::npos);
  options = DerivativeCostOptions();
  options.spp = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("spp"), std::string::npos);
  options = DerivativeCostOptions();
  options.bounces = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("bounces"), std::string::npos);
  for (int seeds : {1, 65}) {
    options = DerivativeCostOptions();
    options.noise_seeds = seeds;
    EXPECT_FALSE(options.Check(&why));
    EXPECT_NE(why.find("noise-seeds"), std::string::npos);
  }

  TriMesh empty;
  DerivativeCostReport report;
  EXPECT_FALSE(MeasureDerivativeCost(DerivativeCostOptions(), empty, &report).ok());
}

TEST(BenchGradientCommandTest, BadViewsIsOneErrorLine) {
  std::string output;
  const int code = testing::RunCommand(testing::SftBinary() + " bench gradient --views 0", &output);
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("--views"), std::string::npos) << output;
  ASSERT_FALSE(output.empty());
  EXPECT_EQ(output.find('\n'), output.size() - 1) << output;  // exactly one line.
}

TEST(BenchGradientCommandTest, MissingMeshIsOneErrorLine) {
  testing::TempDir dir;
  std::string output;
  const int code = testing::RunCommand(
      testing::SftBinary() + " bench gradient --mesh " + dir.Join("absent.obj"), &output);
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("--mesh"), std::string::npos) << output;
  EXPECT_EQ(output.find('\n'), output.size() - 1) << output;
}

TEST(BenchGradientCommandTest, SmallRunWritesJson) {
  testing::TempDir dir;
  std::string output;
  const std::string json_path = dir.Join("gradient.json");
  const int code =
      testing::RunCommand(testing::SftBinary() + " bench gradient --mesh " + testing::DataDir() +
                              "/meshes/icosphere_r1_320f.obj --views 2 --res 16 "
                              "--spp 1 --secondary-edge-samples 0 --texel-edge-ratio 0.5 "
                              "--quiet --json " +
                              json_path,
                          &output);
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find("forward + Jacobian rows"), std::string::npos) << output;
  std::string text;
  ASSERT_TRUE(ReadTextFile(json_path, &text).ok());
  const nlohmann::json json = nlohmann::json::parse(text);
  EXPECT_EQ(json["mesh_faces"].get<int>(), 320);
  EXPECT_EQ(json["views"].get<int>(), 2);
  EXPECT_GT(json["jacobian_rows"]["entries"].get<int64_t>(), 0);
  EXPECT_TRUE(json["passes"].contains("forward"));
  // The edge budgets given on the command line are the ones used and reported.
  EXPECT_EQ(json["edge_budgets"]["secondary_edge_samples"].get<double>(), 0.0);
  EXPECT_EQ(json["edge_budgets"]["texel_edge_ratio"].get<double>(), 0.5);
  EXPECT_EQ(json["edge_budgets"]["primary_edge_ratio"].get<double>(),
            DerivativeRequest().primary_edge_ratio);
}

TEST(BenchGradientCommandTest, BadEdgeBudgetIsOneErrorLine) {
  std::string output;
  const int code = testing::RunCommand(
      testing::SftBinary() + " bench gradient --views 1 --primary-edge-ratio 17", &output);
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("--primary-edge-ratio"), std::string::npos) << output;
  EXPECT_EQ(output.find('\n'), output.size() - 1) << output;
}

// `sft bench gradient --dataset`: the passes run on the dataset's own views (sizes, lights),
// with the dataset's light as the light-scale parameter, and a bad view index is an error.
TEST(DerivativeCostTest, DatasetViews) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 3 --zooms 1 --res 20 --spp 4"), "");
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(tmp.Join("ds/gt/mesh.ply"), &mesh).ok());
  Material material;
  ASSERT_TRUE(LoadMaterial(tmp.Join("ds/gt/material.json"), mesh, &material).ok());
  DerivativeCostOptions options;
  options.spp = 2;
  DerivativeCostReport report;
  ASSERT_TRUE(MeasureDatasetDerivativeCost(options, dataset, {0, 2}, mesh, material, &report).ok());
  EXPECT_EQ(report.views, 2);
  EXPECT_EQ(report.width, 20);
  EXPECT_EQ(report.forward.rays.camera_rays, int64_t{2} * 20 * 20 * 2);
  EXPECT_GT(report.covered_pixels, 0);
  EXPECT_GT(report.jacobian_entries, 0);
  EXPECT_GT(report.gradient_norm, 0.0);
  EXPECT_GT(report.jacobian_rows.ratio, 0.0);
  EXPECT_GT(report.adjoint.ratio, 0.0);

  const Status bad = MeasureDatasetDerivativeCost(options, dataset, {3}, mesh, material, &report);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("3"), std::string::npos) << bad.message();
}

}  // namespace
}  // namespace sft
