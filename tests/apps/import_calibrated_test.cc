// `sft import nerf`, `idr` and `middlebury` end to end: a dataset rendered by `sft synth` (16
// views of the icosphere, half of them zoomed so that the object leaves the frame) is written in
// each format (tests/testing/calibrated_fixtures.h), imported, and compared with the truth: every
// camera maps back onto its true pose through source_from_world, the object's box fits the
// icosphere, `sft init` carves the import, and the geometry passes render it without lights.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>

#include "src/core/file_util.h"
#include "src/io/dataset.h"
#include "tests/testing/calibrated_fixtures.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::RunSft;

class ImportCalibratedTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new testing::TempDir();
    const std::string error =
        testing::SynthIcosphere(tmp_->Join("synth"), "--cameras 8 --zooms 1,3 --res 64 --spp 4");
    ASSERT_EQ(error, "");
    truth_ = new Dataset();
    ASSERT_TRUE(ReadDataset(tmp_->Join("synth"), truth_).ok());
  }
  static void TearDownTestSuite() {
    delete truth_;
    delete tmp_;
  }

  // Imports with `args` into a fresh folder and reads the result.
  static Dataset Import(const std::string& args, std::string* output) {
    const std::string out = tmp_->Join("out" + std::to_string(counter_++));
    EXPECT_EQ(RunSft("import " + args + " --out " + out, output), 0) << *output;
    Dataset dataset;
    const Status status = ReadDataset(out, &dataset);
    EXPECT_TRUE(status.ok()) << status.message();
    EXPECT_TRUE(CheckDatasetFiles(dataset).ok());
    return dataset;
  }

  static testing::TempDir* tmp_;
  static Dataset* truth_;
  static int counter_;
};

testing::TempDir* ImportCalibratedTest::tmp_ = nullptr;
Dataset* ImportCalibratedTest::truth_ = nullptr;
int ImportCalibratedTest::counter_ = 0;

Eigen::Vector3d Centre(const Rigid3d& pose) { return pose.Inverse().translation; }

// Every imported view's camera and pose against the truth (view `rotated` is the 90° copy).
void ExpectPosesMatch(const Dataset& truth, const Dataset& imported, int rotated = -1) {
  ASSERT_EQ(imported.views.size(), truth.views.size());
  const Similarity3d& s = imported.source_from_world;
  for (size_t v = 0; v < truth.views.size(); ++v) {
    SCOPED_TRACE("view " + std::to_string(v));
    const Rigid3d& a = truth.views[v].cam_from_world;
    const Rigid3d& b = imported.views[v].cam_from_world;
    EXPECT_LT((s * Centre(b) - Centre(a)).norm(), 1e-9 * Centre(a).norm());
    const Camera& ct = truth.cameras[truth.views[v].camera];
    const Camera& ci = imported.cameras[imported.views[v].camera];
    if (static_cast<int>(v) == rotated) {
      EXPECT_EQ(ci.width, ct.height);
      EXPECT_NEAR(b.rotation.angularDistance(a.rotation), M_PI / 2, 1e-9);
      continue;
    }
    EXPECT_LT(b.rotation.angularDistance(a.rotation), 1e-9);
    ASSERT_EQ(ci.params.size(), ct.params.size());
    for (size_t i = 0; i < ct.params.size(); ++i) {
      EXPECT_NEAR(ci.params[i], ct.params[i], 1e-9 * ct.params[0]);
    }
  }
}

// synth normalised the icosphere to its box's diagonal 1 at the origin: the import's box (from
// the masks' hull) holds it, a little larger (16 views of 64² carved at 64 voxels).
void ExpectBoxFitsTheIcosphere(const Dataset& imported) {
  const Similarity3d& s = imported.source_from_world;
  EXPECT_GT(s.scale, 0.98);
  EXPECT_LT(s.scale, 1.2);
  EXPECT_LT(s.translation.norm(), 0.05);
  const nlohmann::json& n = imported.extra["import"]["normalization"];
  EXPECT_EQ(n["method"], "visual hull of the masks");
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(n["fill_ratio"][a].get<double>(), 0.577, 0.06);
}

TEST_F(ImportCalibratedTest, NerfWithMaskFolder) {
  const std::string transforms = testing::WriteNerfTransforms(*truth_);
  std::string output;
  const Dataset d =
      Import("nerf --transforms " + transforms + " --masks " + tmp_->Join("synth/masks"), &output);
  ExpectPosesMatch(*truth_, d);
  ExpectBoxFitsTheIcosphere(d);
  EXPECT_EQ(d.lighting, "unknown");
  EXPECT_EQ(d.views[0].image, "images/000.exr");
  EXPECT_EQ(d.views[0].mask, "masks/000.png");
  EXPECT_EQ(d.extra["import"]["from"], "nerf");
  EXPECT_THAT(output, HasSubstr("sft import nerf: 16 frames; 16 views, 2 camera(s); masks: "
                                "folder; object box from the visual hull of the masks"));
  EXPECT_THAT(output, HasSubstr("fill ratio 0."));

  // The import carves with `sft init`, and the geometry passes render it without lights.
  ASSERT_EQ(RunSft("init --quiet --dataset " + d.root, &output), 0) << output;
  for (const char* pass : {"normal", "depth"}) {
    ASSERT_EQ(RunSft(std::string("render --quiet --no-report --spp 1 --pass ") + pass +
                         " --dataset " + d.root + " --mesh " + d.root + "/init/mesh.ply --out " +
                         tmp_->Join(std::string("render_") + pass),
                     &output),
              0)
        << output;
    EXPECT_TRUE(fs::exists(tmp_->Join(std::string("render_") + pass + "/images/000.exr")));
  }
  EXPECT_EQ(RunSft("render --quiet --dataset " + d.root + " --mesh " + d.root +
                       "/init/mesh.ply --out " + tmp_->Join("render_color"),
                   &output),
            1);
  EXPECT_THAT(output, HasSubstr("views[0].lights: empty (unknown lighting"));
}

TEST_F(ImportCalibratedTest, MiddleburyWithThresholdMasksAndARotatedView) {
  const std::string par = testing::WriteMiddleburyPar(*truth_, 3);
  std::string output;
  const Dataset d =
      Import("middlebury --par " + par + " --masks threshold --threshold 0.01 --dilate 1 --erode 1",
             &output);
  // One warning line for the entry without an image, even though everything else worked.
  EXPECT_THAT(output, HasSubstr("sft import middlebury: warning: 1 of 17 entries have no image "
                                "file and were skipped (first: missing.png)"));
  ExpectPosesMatch(*truth_, d, 3);
  ExpectBoxFitsTheIcosphere(d);
  EXPECT_EQ(d.views[3].image, "images/rotated.exr");  // EXR is copied as EXR.
}

TEST_F(ImportCalibratedTest, IdrWithSortedMaskFolderAndWithoutMasks) {
  const std::string idr = testing::WriteIdrFolder(*truth_, 0.6);
  std::string output;
  const Dataset d =
      Import("idr --cameras " + idr + "/cameras.npz --masks " + idr + "/mask", &output);
  ExpectPosesMatch(*truth_, d);
  ExpectBoxFitsTheIcosphere(d);
  EXPECT_EQ(d.views[1].image, "images/a001.exr");
  EXPECT_EQ(d.views[1].mask, "masks/a001.png");
  // Without masks the bounding sphere (radius 0.6 at the origin) is the object's box.
  const Dataset sphere = Import("idr --quiet --cameras " + idr + "/cameras.npz", &output);
  EXPECT_EQ(output, "");
  ExpectPosesMatch(*truth_, sphere);
  EXPECT_NEAR(sphere.source_from_world.scale, 1.2 * std::sqrt(3.0), 1e-9);
  EXPECT_LT(sphere.source_from_world.translation.norm(), 1e-12);
  EXPECT_TRUE(sphere.views[0].mask.empty());
}

}  // namespace
}  // namespace sft
