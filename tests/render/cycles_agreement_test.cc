// Forward renders agree with Blender Cycles 3.4 (1024 spp) on the reference datasets in data/cycles
// (issue 2, data/cycles/README.md): same mesh, material, lights and bounces. Thresholds: mean over
// object pixels of |ours − cycles| ≤ 2% of mean(cycles) with direct light, ≤ 3% with GI or an
// environment map; every 8×8 block average (blocks at least half covered by the mask and not darker
// than 10% of the mean) within 5%.
#include <gtest/gtest.h>

#include <cstdio>

#include "src/eval/image_compare.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/render/render.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

struct CyclesCase {
  const char* name;
  int spp;
  double max_relative_mean_abs;  // per the issue: 2% direct, 3% GI / environment.
};

class CyclesAgreementTest : public ::testing::TestWithParam<CyclesCase> {};

TEST_P(CyclesAgreementTest, MatchesReference) {
  const CyclesCase& param = GetParam();
  const std::string root = testing::DataDir() + "/cycles/" + param.name;
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(root, &dataset).ok());
  const nlohmann::json& gt = dataset.ground_truth;
  const nlohmann::json& spec = gt["material"];
  TriMesh mesh;
  std::string material_json;
  if (spec["type"] == "textured") {
    ASSERT_TRUE(ReadMesh(root + "/" + gt["mesh_uv"].get<std::string>(), &mesh).ok());
    material_json =
        nlohmann::json{{"albedo_texture", root + "/" + gt["texture"].get<std::string>()},
                       {"colorspace", "linear"},
                       {"resolution", 8},
                       {"specular", spec.value("specular", 0.0)}}
            .dump();
  } else {
    ASSERT_TRUE(ReadMesh(root + "/" + gt["mesh"].get<std::string>(), &mesh).ok());
    material_json = nlohmann::json{{"albedo", spec["albedo"]},
                                   {"roughness", spec.value("roughness", 0.5)},
                                   {"specular", spec.value("specular", 0.0)}}
                        .dump();
  }
  Material material;
  const Status material_status = LoadMaterial(material_json, mesh, &material);
  ASSERT_TRUE(material_status.ok()) << material_status.message();
  DatasetViews views;
  ASSERT_TRUE(MakeDatasetViews(dataset, &views).ok());
  const RenderScene scene(mesh);
  RenderOptions options;
  options.spp = param.spp;
  options.bounces = gt["max_bounces_cycles"].get<int>() + 1;
  options.seed = 1;
  options.shading = DatasetShading(dataset);  // ground_truth.shading, as Blender shaded it.
  double worst_mean = 0.0, worst_block = 0.0;
  for (size_t v = 0; v < views.views.size(); ++v) {
    Image ours, reference, mask;
    RenderView(scene, material, views.views[v], options, &ours);
    ASSERT_TRUE(LoadViewImage(dataset, static_cast<int>(v), &reference).ok());
    ASSERT_TRUE(LoadViewMask(dataset, static_cast<int>(v), &mask).ok());
    const ImageAgreement a = CompareImages(ours, reference, mask);
    std::printf("%s view %zu: mean|d|/mean %.4f, mean bias %+.4f, blocks %d, worst block %.4f\n",
                param.name, v, a.relative_mean_abs_difference, a.relative_mean_difference,
                a.blocks_compared, a.max_block_relative_difference);
    EXPECT_GT(a.object_pixels, 500);
    EXPECT_GT(a.blocks_compared, 20);
    EXPECT_LE(a.relative_mean_abs_difference, param.max_relative_mean_abs) << "view " << v;
    EXPECT_LE(a.max_block_relative_difference, 0.05) << "view " << v;
    worst_mean = std::max(worst_mean, a.relative_mean_abs_difference);
    worst_block = std::max(worst_block, a.max_block_relative_difference);
  }
  std::printf("%s: worst mean|d|/mean %.4f, worst 8x8 block %.4f\n", param.name, worst_mean,
              worst_block);
}

INSTANTIATE_TEST_SUITE_P(Cycles, CyclesAgreementTest,
                         ::testing::Values(CyclesCase{"bunny_point_diffuse", 64, 0.02},
                                           CyclesCase{"bunny_point_ggx_gi", 512, 0.03},
                                           CyclesCase{"bunny_point_ggx_gi_smooth", 512, 0.03},
                                           CyclesCase{"sphere_env_studio", 256, 0.03},
                                           CyclesCase{"spot_textured_point", 64, 0.03}),
                         [](const ::testing::TestParamInfo<CyclesCase>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace sft
