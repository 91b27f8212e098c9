#include "src/eval/throughput.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "src/core/file_util.h"
#include "src/geometry/mesh.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

constexpr int kRes = 32;

void ExpectRateOk(const RayRate& rate, const char* name) {
  EXPECT_GT(rate.seconds, 0.0) << name;
  EXPECT_TRUE(std::isfinite(rate.RaysPerSecond())) << name;
  EXPECT_GT(rate.RaysPerSecond(), 0.0) << name;
}

// Performance numbers are not asserted: only that everything runs and the counts agree.
TEST(ThroughputTest, CountsAreConsistent) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/bunny_watertight_5k.obj", &mesh).ok());
  ThroughputOptions options;
  options.resolution = kRes;
  options.spp = 1;
  options.repeats = 1;
  ThroughputReport report;
  const Status status = MeasureMeshThroughput(mesh, options, &report);
  ASSERT_TRUE(status.ok()) << status.message();

  const int64_t primary = int64_t{kRes} * kRes * options.spp;
  EXPECT_EQ(report.num_faces, static_cast<int>(mesh.n_faces()));
  EXPECT_GE(report.threads, 1);
  EXPECT_EQ(report.intersect1.rays, primary);
  EXPECT_EQ(report.intersect8.rays, primary);
  EXPECT_EQ(report.direct.camera_rays, primary);
  EXPECT_EQ(report.two_bounces.camera_rays, primary);
  // Packets and single rays find the same hits; the camera sees the mesh but not only the mesh.
  EXPECT_EQ(report.intersect8.hits, report.intersect1.hits);
  EXPECT_GT(report.intersect1.hits, primary / 20);
  EXPECT_LT(report.intersect1.hits, primary);
  // One light: at most one shadow ray per camera ray, only from hits.
  EXPECT_GT(report.occluded1.rays, 0);
  EXPECT_LE(report.occluded1.rays, report.intersect1.hits);
  EXPECT_LE(report.direct.shadow_rays, report.direct.camera_rays);
  EXPECT_EQ(report.direct.bounce_rays, 0);
  EXPECT_GT(report.two_bounces.bounce_rays, 0);
  // The raw shadow rays are the renderer's (RaySetIsTheRenderers checks the rays themselves).
  EXPECT_EQ(report.occluded1.rays, report.direct.shadow_rays);

  ExpectRateOk(report.intersect1, "intersect1");
  ExpectRateOk(report.intersect8, "intersect8");
  ExpectRateOk(report.occluded1, "occluded1");
  EXPECT_GT(report.DirectRaysPerSecond(), 0.0);
  EXPECT_TRUE(std::isfinite(report.DirectRaysPerSecond()));
  EXPECT_GT(report.TwoBouncesRaysPerSecond(), 0.0);
  EXPECT_TRUE(std::isfinite(report.TwoBouncesRaysPerSecond()));
  EXPECT_GT(report.raw_direct_seconds, 0.0);
  EXPECT_GT(report.ratio, 0.0);
  EXPECT_TRUE(std::isfinite(report.ratio));

  const nlohmann::json json = ThroughputReportToJson(report);
  EXPECT_EQ(json["embree"]["intersect1"]["rays"].get<int64_t>(), primary);
  EXPECT_EQ(json["ours"]["direct"]["camera_rays"].get<int64_t>(), primary);
  EXPECT_FALSE(ThroughputReportTable(report).empty());
}

// The raw ray set is the renderer's: the camera rays hit exactly where RenderView's do (its alpha
// channel is the per-pixel hit fraction) and the shadow rays are exactly RenderView's. If this
// fails, CameraRays/ShadowRays in src/eval/throughput.cc no longer replicate render.cc.
TEST(ThroughputTest, RaySetIsTheRenderers) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/bunny_watertight_5k.obj", &mesh).ok());
  const RenderScene scene(mesh);
  const Material material =
      ConstantMaterial(static_cast<int>(mesh.n_faces()), Eigen::Vector3d::Constant(0.7), 0.5, 0.0);
  const ViewSetup view = ThroughputView(scene, kRes);
  RenderOptions options;
  options.spp = 3;
  options.bounces = 1;
  options.seed = 7;
  Image image;
  RenderStats stats;
  RenderView(scene, material, view, options, &image, &stats);
  double alpha_sum = 0.0;
  for (int y = 0; y < kRes; ++y) {
    for (int x = 0; x < kRes; ++x) alpha_sum += image.at(x, y, 3);
  }
  const std::vector<BenchRay> camera_rays = CameraRays(view, options.spp, options.seed);
  ASSERT_EQ(static_cast<int64_t>(camera_rays.size()), stats.camera_rays);
  const RayRate traced =
      TraceEmbree(scene.embree_scene(), camera_rays, EmbreeQuery::kIntersect1, 0);
  EXPECT_GT(traced.hits, 0);
  EXPECT_EQ(traced.hits, std::llround(alpha_sum * options.spp));
  const std::vector<BenchRay> shadow_rays = ShadowRays(scene, view, options.spp, options.seed, 0);
  EXPECT_EQ(static_cast<int64_t>(shadow_rays.size()), stats.shadow_rays);
}

TEST(ThroughputTest, CameraRaysFollowSpp) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &mesh).ok());
  const RenderScene scene(mesh);
  const ViewSetup view = ThroughputView(scene, 8);
  EXPECT_EQ(CameraRays(view, 3, 0).size(), 8u * 8u * 3u);
  // Every camera ray starts at the camera centre with a unit direction.
  for (const BenchRay& ray : CameraRays(view, 1, 0)) {
    const double len2 = ray.dir[0] * ray.dir[0] + ray.dir[1] * ray.dir[1] + ray.dir[2] * ray.dir[2];
    EXPECT_NEAR(len2, 1.0, 1e-5);
  }
}

TEST(ThroughputTest, OptionsCheck) {
  std::string why;
  ThroughputOptions options;
  EXPECT_TRUE(options.Check(&why));
  options.resolution = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("res"), std::string::npos);
  options = ThroughputOptions();
  options.spp = 0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("spp"), std::string::npos);
  options = ThroughputOptions();
  options.repeats = 0;
  EXPECT_FALSE(options.Check(&why));
}

TEST(BenchCommandTest, BadResolutionIsOneErrorLine) {
  std::string output;
  const int code = testing::RunCommand(testing::SftBinary() + " bench render --res 0", &output);
  EXPECT_NE(code, 0);
  EXPECT_NE(output.find("--res"), std::string::npos) << output;
  ASSERT_FALSE(output.empty());
  EXPECT_EQ(output.find('\n'), output.size() - 1) << output;  // exactly one line.
}

TEST(BenchCommandTest, MissingMeshIsOneErrorLine) {
  testing::TempDir dir;
  std::string output;
  const int code = testing::RunCommand(
      testing::SftBinary() + " bench render --mesh " + dir.Join("absent.obj"), &output);
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("--mesh"), std::string::npos) << output;
  EXPECT_EQ(output.find('\n'), output.size() - 1) << output;
}

TEST(BenchCommandTest, SmallRunWritesJson) {
  testing::TempDir dir;
  std::string output;
  const std::string json_path = dir.Join("bench.json");
  const int code =
      testing::RunCommand(testing::SftBinary() + " bench render --mesh " + testing::DataDir() +
                              "/meshes/icosphere_r1_320f.obj --res 16 --spp 1 "
                              "--repeats 1 --json " +
                              json_path,
                          &output);
  EXPECT_EQ(code, 0) << output;
  std::string text;
  ASSERT_TRUE(ReadTextFile(json_path, &text).ok());
  const nlohmann::json json = nlohmann::json::parse(text);
  EXPECT_EQ(json["mesh_faces"].get<int>(), 320);
  EXPECT_EQ(json["embree"]["intersect1"]["rays"].get<int64_t>(), 16 * 16);
  EXPECT_TRUE(json.contains("ratio"));
}

}  // namespace
}  // namespace sft
