// ExportReconstruction (src/export/export.h) of a run whose material is UV textures (a uv stage's
// checkpoint): the fitted textures are written as they are, not re-baked from mesh colors.
#include "src/export/export.h"

#include <gtest/gtest.h>

#include "src/core/file_util.h"
#include "src/core/rng.h"
#include "src/export/export_formats.h"
#include "src/geometry/material.h"
#include "src/image/image_io.h"
#include "src/optim/uv_stage.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

TEST(ExportTest, WritesTheFittedUvTextures) {
  testing::TempDir dir;
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &mesh).ok());
  Material material =
      ConstantMaterial(static_cast<int>(mesh.n_faces()), Eigen::Vector3d(0.5, 0.5, 0.5), 0.5, 0.1);
  nlohmann::json record;
  ASSERT_TRUE(SwitchToUvTextures(mesh, Dataset(), 64, &material, &record).ok());
  // Texels no bake of a constant material gives: noise per texel.
  std::vector<double>& albedo = material.uv.albedo.values();
  for (size_t k = 0; k < albedo.size(); ++k) albedo[k] = (Mix64(k) >> 11) * 0x1.0p-53;
  for (double& v : material.uv.roughness.values()) v = 0.3;
  // The run folder as a uv stage's checkpoint writes it.
  const std::string rec = dir.Join("rec");
  ASSERT_TRUE(MakeDirectories(rec).ok());
  ASSERT_TRUE(WriteMesh(rec + "/mesh.ply", mesh).ok());
  TriMesh with_uvs = mesh;
  SetFaceCornerUvs(material.uv.corner_uvs, &with_uvs);
  ASSERT_TRUE(WriteMesh(rec + "/mesh.obj", with_uvs).ok());
  ASSERT_TRUE(SaveUvMaterial(rec + "/material.json", material, "mesh.obj").ok());

  ExportOptions options;
  options.reconstruction = rec;
  options.out = dir.Join("exp");
  options.texture_size = 128;  // ignored, with a warning: the textures keep their size.
  nlohmann::json summary;
  const Status status = ExportReconstruction(options, &summary);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(summary["atlas"]["baked"], false);
  EXPECT_EQ(summary["atlas"]["texture_size"], 64);
  ASSERT_EQ(summary["warnings"].size(), 2u);  // no state.json; --texture-size ignored.
  EXPECT_NE(summary["warnings"][1].get<std::string>().find("--texture-size 128 ignored"),
            std::string::npos);

  // The exported albedo PNG is the run's, byte for byte in value.
  Image run_albedo, exported;
  ASSERT_TRUE(ReadImage(rec + "/material_albedo.png", &run_albedo, /*srgb=*/false).ok());
  ASSERT_TRUE(ReadImage(options.out + "/" + kAlbedoPngFile, &exported, /*srgb=*/false).ok());
  ASSERT_EQ(exported.width, 64);
  EXPECT_EQ(exported.data, run_albedo.data);

  // Read back through the MTL: the same texels and UVs (8-bit sRGB rounding).
  TriMesh exported_mesh;
  ASSERT_TRUE(ReadMesh(options.out + "/" + kObjFile, &exported_mesh).ok());
  Material back;
  ASSERT_TRUE(
      LoadMaterial(options.out + "/" + kMtlFile, exported_mesh, &back, MaterialUse::kRender).ok());
  ASSERT_TRUE(back.has_uv_textures());
  ASSERT_EQ(back.uv.albedo.values().size(), material.uv.albedo.values().size());
  double worst = 0.0;
  for (size_t k = 0; k < back.uv.albedo.values().size(); ++k) {
    worst = std::max(worst, std::abs(back.uv.albedo.values()[k] - material.uv.albedo.values()[k]));
  }
  EXPECT_LT(worst, 0.01);
  EXPECT_NEAR(back.uv.roughness.values()[0], 0.3, 0.003);
}

}  // namespace
}  // namespace sft
