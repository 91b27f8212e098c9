// Where a run starts (src/optim/start_mesh.h): a carved start never depends on the masks of the
// views it excludes (held-out views, `sft reconstruct --holdout`), neither on their content nor
// on whether they can be read.
#include "src/optim/start_mesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

#include "src/core/file_util.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

// A small carve: the test compares meshes, not their accuracy.
InitialMeshOptions SmallCarve() {
  InitialMeshOptions options;
  options.hull.resolution = 48;
  options.faces = 1000;
  options.progress = false;
  return options;
}

bool SameMesh(const TriMesh& a, const TriMesh& b) {
  if (a.n_vertices() != b.n_vertices() || a.n_faces() != b.n_faces()) return false;
  for (auto vh : a.vertices()) {
    if (a.point(vh) != b.point(vh)) return false;
  }
  return true;
}

// Carves `dataset` leaving out `excluded`; fails the test on an error.
TriMesh Carve(const Dataset& dataset, const std::vector<int>& excluded) {
  TriMesh mesh;
  const Status status =
      LoadStartMesh(dataset, {StartKind::kCarved, ""}, SmallCarve(), &mesh, excluded);
  EXPECT_TRUE(status.ok()) << status.message();
  return mesh;
}

TEST(StartMeshTest, CarvingIgnoresExcludedViewsMasks) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 6 --zooms 1 --res 32 --spp 4"), "");
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  const TriMesh clean_all = Carve(dataset, {});
  const TriMesh clean_fitted = Carve(dataset, {0, 3});
  ASSERT_GT(clean_fitted.n_faces(), 100u);
  // The console line names the views carved and the faces.
  TriMesh summarized;
  std::string summary;
  ASSERT_TRUE(
      LoadStartMesh(dataset, {StartKind::kCarved, ""}, SmallCarve(), &summarized, {0, 3}, &summary)
          .ok());
  EXPECT_EQ(summary, "start: the hull carved from 4 views' masks, " +
                         std::to_string(clean_fitted.n_faces()) + " faces");

  // View 0's mask with a hole: used, it changes the hull; excluded, the hull is the carve of the
  // other views to the vertex.
  ASSERT_EQ(testing::CorruptMask(dataset.root, 0, /*hole=*/true), "");
  EXPECT_FALSE(SameMesh(Carve(dataset, {}), clean_all)) << "the corrupted mask must matter";
  EXPECT_TRUE(SameMesh(Carve(dataset, {0, 3}), clean_fitted));

  // An empty mask (which carving refuses) and a missing file: excluded, they are not even read.
  ASSERT_EQ(testing::CorruptMask(dataset.root, 3, /*hole=*/false), "");
  TriMesh mesh;
  const Status used = LoadStartMesh(dataset, {StartKind::kCarved, ""}, SmallCarve(), &mesh, {0});
  EXPECT_THAT(used.message(), HasSubstr("views[3]"));
  EXPECT_TRUE(SameMesh(Carve(dataset, {0, 3}), clean_fitted));
  ASSERT_EQ(std::remove(JoinPath(dataset.root, dataset.views[3].mask).c_str()), 0);
  EXPECT_TRUE(SameMesh(Carve(dataset, {0, 3}), clean_fitted));
}

}  // namespace
}  // namespace sft
