// The report's 3D view: base64, what the section embeds (the GLB's bytes, the start mesh in the
// GLB's Y-up frame), three.js copied beside the report, and the fallbacks.
#include "src/eval/model_viewer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

TEST(ModelViewerTest, Base64MatchesRfc4648) {
  // RFC 4648 §10's test vectors, and a byte above 127.
  EXPECT_EQ(Base64Encode(""), "");
  EXPECT_EQ(Base64Encode("f"), "Zg==");
  EXPECT_EQ(Base64Encode("fo"), "Zm8=");
  EXPECT_EQ(Base64Encode("foo"), "Zm9v");
  EXPECT_EQ(Base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64Encode(std::string("\xff\xfe", 2)), "//4=");
}

class ModelViewerFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    // A fake three.js folder (the viewer copies, it does not parse), an export with a GLB and
    // maps, and a one-triangle start mesh.
    fs::create_directories(tmp_.Join("three/examples/js/loaders"));
    fs::create_directories(tmp_.Join("three/examples/js/controls"));
    fs::create_directories(tmp_.Join("report/export"));
    for (const char* f : {"three.min.js", "examples/js/loaders/GLTFLoader.js",
                          "examples/js/controls/OrbitControls.js"}) {
      testing::WriteTestFile(tmp_.Join(std::string("three/") + f), std::string("// ") + f);
    }
    testing::WriteTestFile(tmp_.Join("report/export/model.glb"), "glTF\x02");
    testing::WriteTestFile(tmp_.Join("report/export/model_albedo.png"), "png");
    testing::WriteTestFile(tmp_.Join("start.obj"), "v 1 2 3\nv 0 0 0\nv 1 0 0\nf 1 2 3\n");
    options_.export_dir = "export";
    options_.start_mesh = tmp_.Join("start.obj");
    options_.three_dir = tmp_.Join("three");
  }

  testing::TempDir tmp_;
  ModelViewerOptions options_;
  Dataset dataset_;  // no source frame: the export is in sft's world frame.
};

TEST_F(ModelViewerFixture, EmbedsTheModelsAndCopiesThreeJs) {
  HtmlReport html(tmp_.Join("report"), "t");
  ASSERT_TRUE(AddModelViewer(options_, dataset_, &html).ok());
  const std::string page = html.Html();
  EXPECT_THAT(page, HasSubstr("<canvas id=\"sft3d-start\""));
  EXPECT_THAT(page, HasSubstr("<canvas id=\"sft3d-result\""));
  EXPECT_THAT(page, HasSubstr("<select id=\"sft3d-light\""));
  EXPECT_THAT(page, HasSubstr("var glb = '" + Base64Encode("glTF\x02") + "'"));
  // The start mesh's first vertex (1, 2, 3) turned Y-up, (x, z, −y) = (1, 3, −2), as float32;
  // its triangle 0 1 2 as uint32.
  const float xyz[9] = {1, 3, -2, 0, 0, 0, 1, 0, 0};
  EXPECT_THAT(
      page,
      HasSubstr("startPositions = '" +
                Base64Encode(std::string(reinterpret_cast<const char*>(xyz), sizeof(xyz))) + "'"));
  const uint32_t tri[3] = {0, 1, 2};
  EXPECT_THAT(
      page,
      HasSubstr("startIndices = '" +
                Base64Encode(std::string(reinterpret_cast<const char*>(tri), sizeof(tri))) + "'"));
  EXPECT_THAT(page, HasSubstr("<img src=\"export/model_albedo.png\""));
  EXPECT_THAT(page, Not(HasSubstr("model_roughness.png")));  // absent, so not shown.
  for (const char* f : {"three.min.js", "GLTFLoader.js", "OrbitControls.js"}) {
    EXPECT_TRUE(fs::exists(tmp_.Join(std::string("report/report_files/three/") + f))) << f;
    EXPECT_THAT(page, HasSubstr(std::string("<script src=\"report_files/three/") + f + "\">"));
  }
}

TEST_F(ModelViewerFixture, SourceFrameIsApplied) {
  dataset_.has_source_from_world = true;
  dataset_.source_from_world.scale = 2.0;
  dataset_.source_from_world.translation = Eigen::Vector3d(10, 0, 0);
  HtmlReport html(tmp_.Join("report"), "t");
  ASSERT_TRUE(AddModelViewer(options_, dataset_, &html).ok());
  // (1, 2, 3) → 2·p + (10, 0, 0) = (12, 4, 6) → Y-up (12, 6, −4).
  const float xyz[9] = {12, 6, -4, 10, 0, 0, 12, 0, 0};
  EXPECT_THAT(
      html.Html(),
      HasSubstr(Base64Encode(std::string(reinterpret_cast<const char*>(xyz), sizeof(xyz)))));
}

// The page opens looking back along view 0's optical axis (in the export's Y-up frame), and from
// a fixed three-quarter direction without views.
TEST_F(ModelViewerFixture, OpensFromTheFirstViewsDirection) {
  {
    HtmlReport html(tmp_.Join("report"), "t");
    ASSERT_TRUE(AddModelViewer(options_, dataset_, &html).ok());
    EXPECT_THAT(html.Html(), HasSubstr("new THREE.Vector3(0.321521, 0.229658, 0.918630)"));
  }
  // A camera at +x looking at the origin: its optical axis is −x in the world, so the viewer looks
  // from +x; the source frame's 90° turn about z takes +x to +y, which is −z in Y-up.
  ViewSpec view;
  view.cam_from_world.rotation =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()) * Eigen::Quaterniond::Identity();
  ASSERT_NEAR((view.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitZ()).x(), -1.0,
              1e-12);
  dataset_.views.push_back(view);
  {
    HtmlReport html(tmp_.Join("report"), "t");
    ASSERT_TRUE(AddModelViewer(options_, dataset_, &html).ok());
    EXPECT_THAT(html.Html(), HasSubstr("new THREE.Vector3(1.000000, 0.000000, 0.000000)"));
  }
  dataset_.has_source_from_world = true;
  dataset_.source_from_world.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  HtmlReport html(tmp_.Join("report"), "t");
  ASSERT_TRUE(AddModelViewer(options_, dataset_, &html).ok());
  EXPECT_THAT(html.Html(), HasSubstr("new THREE.Vector3(0.000000, 0.000000, -1.000000)"));
}

TEST_F(ModelViewerFixture, WithoutStartMeshOnlyTheResult) {
  options_.start_mesh.clear();
  HtmlReport html(tmp_.Join("report"), "t");
  ASSERT_TRUE(AddModelViewer(options_, dataset_, &html).ok());
  EXPECT_THAT(html.Html(), Not(HasSubstr("<canvas id=\"sft3d-start\"")));
  EXPECT_THAT(html.Html(), HasSubstr("startPositions = ''"));
}

TEST_F(ModelViewerFixture, MissingThreeJsSaysHowToInstall) {
  options_.three_dir = tmp_.Join("nowhere");
  HtmlReport html(tmp_.Join("report"), "t");
  ASSERT_TRUE(AddModelViewer(options_, dataset_, &html).ok());
  EXPECT_THAT(html.Html(), HasSubstr("three.js is not installed"));
  EXPECT_THAT(html.Html(), Not(HasSubstr("<canvas")));
  EXPECT_THAT(html.Html(), HasSubstr("export/model_albedo.png"));  // the maps still show.
}

TEST_F(ModelViewerFixture, ErrorsNameTheFile) {
  fs::remove(tmp_.Join("report/export/model.glb"));
  HtmlReport html(tmp_.Join("report"), "t");
  const Status missing = AddModelViewer(options_, dataset_, &html);
  ASSERT_FALSE(missing.ok());
  EXPECT_THAT(missing.message(), HasSubstr("model.glb"));

  testing::WriteTestFile(tmp_.Join("report/export/model.glb"), "glTF");
  testing::WriteTestFile(tmp_.Join("start.obj"), "v 1 2\n");
  const Status bad_mesh = AddModelViewer(options_, dataset_, &html);
  ASSERT_FALSE(bad_mesh.ok());
  EXPECT_THAT(bad_mesh.message(), HasSubstr("start.obj"));

  options_.export_dir = "../outside";
  const Status bad_dir = AddModelViewer(options_, dataset_, &html);
  ASSERT_FALSE(bad_dir.ok());
  EXPECT_THAT(bad_dir.message(), HasSubstr("export_dir"));
}

}  // namespace
}  // namespace sft
