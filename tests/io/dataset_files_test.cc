// The files a dataset names: sizes against the cameras, loading images, masks and probes, the
// reference datasets, and ViewOutputPaths.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "src/core/memory.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "tests/testing/dataset_scenes.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using json = nlohmann::json;
using testing::CyclesDatasets;
using testing::MinimalScene;
using testing::TempDir;
using testing::WriteDataset;

constexpr int kWidth = testing::kMinimalSceneWidth;

TEST(DatasetOutputPaths, MirrorUnderImagesAndNeverCollide) {
  Dataset dataset;
  for (const char* image : {"images/000.exr", "images/cam1/000.png", "images/cam2/000.png",
                            "photos/a.jpg", "images/000.png", "images/000.exr", "b.png"}) {
    ViewSpec view;
    view.image = image;
    dataset.views.push_back(view);
  }
  EXPECT_THAT(ViewOutputPaths(dataset, ".exr"),
              ::testing::ElementsAre("images/000.exr", "images/cam1/000.exr", "images/cam2/000.exr",
                                     "images/photos/a.exr", "images/000_view004.exr",
                                     "images/000_view005.exr", "images/b.exr"));
}

TEST(DatasetFiles, GroundTruthPathStaysInsideTheDataset) {
  Dataset dataset;
  dataset.root = "/data/set";
  std::string path = "stale";
  ASSERT_TRUE(GroundTruthPath(dataset, "material", &path).ok());  // no ground_truth at all.
  EXPECT_EQ(path, "");
  dataset.ground_truth = json::parse(
      R"({"material": "gt/material.json", "albedo": 3, "roughness": "../elsewhere",
          "mesh": "/abs/mesh.ply"})");
  ASSERT_TRUE(GroundTruthPath(dataset, "material", &path).ok());
  EXPECT_EQ(path, "gt/material.json");
  ASSERT_TRUE(GroundTruthPath(dataset, "albedo", &path).ok());  // not a string: absent.
  EXPECT_EQ(path, "");
  ASSERT_TRUE(GroundTruthPath(dataset, "shading", &path).ok());
  EXPECT_EQ(path, "");
  const Status up = GroundTruthPath(dataset, "roughness", &path);
  EXPECT_THAT(up.message(), HasSubstr("/data/set/scene.json: ground_truth.roughness: "));
  EXPECT_EQ(path, "");
  EXPECT_THAT(GroundTruthPath(dataset, "mesh", &path).message(),
              HasSubstr("/data/set/scene.json: ground_truth.mesh: "));
}

TEST(DatasetFiles, ImageSizeDiffersFromCamera) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  ASSERT_TRUE(WritePng(dir.Join("images/001.png"), Image(20, 10, 3)).ok());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  Status status = CheckDatasetFiles(dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr(dir.Join("images/001.png")), HasSubstr("20x10"), HasSubstr("16x12")));
  Image image;
  status = LoadViewImage(dataset, 1, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr("images/001.png"), HasSubstr("20x10")));
}

TEST(DatasetFiles, MaskSizeDiffersFromCamera) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  ASSERT_TRUE(WritePng(dir.Join("masks/000.png"), Image(8, 6, 1), false).ok());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  const Status status = CheckDatasetFiles(dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr(dir.Join("masks/000.png")), HasSubstr("8x6")));
}

TEST(DatasetFiles, MissingImageFile) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  std::filesystem::remove(dir.Join("images/000.exr"));
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());  // ReadDataset does not open images.
  Status status = CheckDatasetFiles(dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr(dir.Join("images/000.exr")), HasSubstr("not found")));
  Image image;
  status = LoadViewImage(dataset, 0, &image);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("images/000.exr")));
}

TEST(DatasetFiles, UnreadableProbe) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  std::ofstream(dir.Join("probes/env.exr"), std::ios::trunc) << "not an exr";
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  Status status = CheckDatasetFiles(dataset);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("probes/env.exr")));
  Image probe;
  status = LoadProbe(dataset, 1, &probe);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(dir.Join("probes/env.exr")));

  std::filesystem::remove(dir.Join("probes/env.exr"));
  status = LoadProbe(dataset, 1, &probe);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr(dir.Join("probes/env.exr")), HasSubstr("not found")));
}

TEST(DatasetFiles, LoadProbeClampsNegativeTexelsAndReturnsRgb) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  Image probe;
  Status status = LoadProbe(dataset, 1, &probe);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(probe.width, 8);
  EXPECT_EQ(probe.height, 4);
  EXPECT_EQ(probe.channels, 3);
  EXPECT_EQ(probe.at(1, 1, 0), 0.0f);  // was -2.
  EXPECT_EQ(probe.at(1, 1, 1), 1.0f);

  // A 4-channel probe loses its alpha; a 1-channel one is replicated to grey.
  Image grey(6, 3, 1, 0.75f);
  ASSERT_TRUE(WriteExr(dir.Join("probes/env.exr"), grey).ok());
  status = LoadProbe(dataset, 1, &probe);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(probe.channels, 3);
  EXPECT_EQ(probe.at(5, 2, 2), 0.75f);
}

TEST(DatasetFiles, LoadViewImageAndMask) {
  TempDir dir;
  WriteDataset(dir, MinimalScene());
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(dir.path(), &dataset).ok());
  Image image;
  ASSERT_TRUE(LoadViewImage(dataset, 0, &image).ok());  // RGBA EXR -> RGB
  EXPECT_EQ(image.channels, 3);
  EXPECT_EQ(image.width, kWidth);
  EXPECT_EQ(image.at(2, 3, 2), 0.25f);
  ASSERT_TRUE(LoadViewImage(dataset, 1, &image).ok());  // sRGB PNG -> linear
  EXPECT_NEAR(image.at(0, 0, 0), 0.5f, 0.005f);         // written as linear 0.5, 8-bit quantized.

  Image mask;
  ASSERT_TRUE(LoadViewMask(dataset, 0, &mask).ok());
  EXPECT_EQ(mask.channels, 1);
  EXPECT_EQ(mask.at(3, 4), 1.0f);
  EXPECT_EQ(mask.at(4, 3), 0.0f);
  const Status status = LoadViewMask(dataset, 1, &mask);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), AllOf(HasSubstr("scene.json"), HasSubstr("views[1].mask")));
}

TEST(DatasetCycles, EveryReferenceDatasetReadsAndChecks) {
  const std::vector<std::string> dirs = CyclesDatasets();
  ASSERT_GE(dirs.size(), 4u);
  int environment_lights = 0;
  for (const std::string& dir : dirs) {
    SCOPED_TRACE(dir);
    Dataset dataset;
    Status status = ReadDataset(dir, &dataset);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(dataset.views.size(), 8u);
    EXPECT_EQ(dataset.gt_mesh, "gt/mesh.ply");
    status = CheckDatasetFiles(dataset);
    EXPECT_TRUE(status.ok()) << status.message();
    for (const ViewSpec& view : dataset.views) {
      EXPECT_NEAR(view.cam_from_world.rotation.norm(), 1.0, 1e-12);
      EXPECT_FALSE(view.lights.empty());
    }
    for (int l = 0; l < static_cast<int>(dataset.lights.size()); ++l) {
      if (dataset.lights[l].type != LightType::kEnvironment) continue;
      ++environment_lights;
      Image probe;
      status = LoadProbe(dataset, l, &probe);
      ASSERT_TRUE(status.ok()) << status.message();
      EXPECT_EQ(probe.width, 2 * probe.height);  // equirectangular
      EXPECT_GE(*std::min_element(probe.data.begin(), probe.data.end()), 0.0f);
    }
  }
  EXPECT_GE(environment_lights, 1);  // sphere_env_studio
}

}  // namespace
}  // namespace sft
