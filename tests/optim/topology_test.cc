// Topology changes between stages (src/optim/topology.h): the visual hull that bounds a Poisson
// resampling is carved without the held-out views' masks, which are not even read.
#include "src/optim/topology.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "src/geometry/material.h"
#include "src/optim/start_mesh.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

// Resamples the dataset's true mesh, fitting `views` and holding out `held_out`.
Status ResampleTruth(const Dataset& dataset, const std::vector<int>& views,
                     const std::vector<int>& held_out, TriMesh* mesh) {
  SFT_RETURN_IF_ERROR(ReadMesh(dataset.root + "/gt/mesh.ply", mesh));
  Material material;
  SFT_RETURN_IF_ERROR(LoadMaterial(kInitialMaterial, *mesh, &material));
  nlohmann::json record;
  SFT_RETURN_IF_ERROR(ApplyTopologyChange(TopologyChange::kResample, TopologyOptions(), dataset,
                                          views, 0, 0, mesh, &material, &record, held_out));
  EXPECT_EQ(record["trimmed_to_hull"], true);
  return Status::Ok();
}

TEST(TopologyTest, ResamplingHullIgnoresHeldOutMasks) {
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(tmp.Join("ds"), "--cameras 6 --zooms 1 --res 32 --spp 4"), "");
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  const std::vector<int> fitted = {1, 2, 4, 5};
  TriMesh clean;
  Status status = ResampleTruth(dataset, fitted, {0, 3}, &clean);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_GT(clean.n_faces(), 100u);
  // View 0's mask empty (carving refuses it), view 3's cut through: held out, nothing changes.
  ASSERT_EQ(testing::CorruptMask(tmp.Join("ds"), 0, /*hole=*/false), "");
  ASSERT_EQ(testing::CorruptMask(tmp.Join("ds"), 3, /*hole=*/true), "");
  TriMesh corrupted;
  status = ResampleTruth(dataset, fitted, {0, 3}, &corrupted);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(corrupted.n_vertices(), clean.n_vertices());
  for (auto vh : clean.vertices()) ASSERT_EQ(corrupted.point(vh), clean.point(vh));
  // Not held out, view 0's empty mask is read and refused.
  TriMesh used;
  EXPECT_THAT(ResampleTruth(dataset, fitted, {}, &used).message(), HasSubstr("views[0]"));
}

}  // namespace
}  // namespace sft
