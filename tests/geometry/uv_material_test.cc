// The UV-texture material forms of LoadMaterial: the JSON form and an MTL file as `sft export`
// writes it, sRGB decoding, constants as 1×1 textures, refusal for fitting, and one-line errors
// naming the file and the field (or MTL statement) for bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "src/core/image.h"
#include "src/geometry/material.h"
#include "src/geometry/mtl_material.h"
#include "src/image/image_io.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

// The 2-face quad of data/meshes with UVs (x, y) ↦ ((x + 1)/2, (y + 1)/2), and without.
TriMesh UvQuad(const testing::TempDir& tmp, bool with_uvs) {
  std::string obj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n";
  if (with_uvs) {
    obj += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  } else {
    obj += "f 1 2 3\nf 1 3 4\n";
  }
  const std::string path = tmp.Join(with_uvs ? "uv_quad.obj" : "quad.obj");
  testing::WriteTestFile(path, obj);
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(path, &mesh).ok());
  return mesh;
}

// 4×2 textures: albedo texel (x, y) = (x/4, y/2, 0.5) (8-bit exact in linear PNG), roughness x/8.
void WriteTextures(const testing::TempDir& tmp) {
  Image albedo(4, 2, 3), roughness(4, 2, 1);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      albedo.at(x, y, 0) = x / 4.0f;
      albedo.at(x, y, 1) = y / 2.0f;
      albedo.at(x, y, 2) = 0.5f;
      roughness.at(x, y) = x / 8.0f;
    }
  }
  ASSERT_TRUE(WriteExr(tmp.Join("albedo.exr"), albedo).ok());
  ASSERT_TRUE(WritePng(tmp.Join("albedo_srgb.png"), albedo, /*srgb=*/true).ok());
  ASSERT_TRUE(WriteExr(tmp.Join("roughness.exr"), roughness).ok());
  ASSERT_TRUE(WritePng(tmp.Join("roughness.png"), roughness, /*srgb=*/false).ok());
}

TEST(UvMaterialTest, JsonFormLoadsTexturesAndUvs) {
  testing::TempDir tmp;
  WriteTextures(tmp);
  const TriMesh mesh = UvQuad(tmp, true);
  testing::WriteTestFile(tmp.Join("m.json"), R"({"uv_albedo": "albedo.exr",
      "uv_roughness": "roughness.exr", "specular": 0.25, "fresnel": "schlick"})");
  Material m;
  const Status status = LoadMaterial(tmp.Join("m.json"), mesh, &m, MaterialUse::kRender);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_TRUE(m.has_uv_textures());
  EXPECT_EQ(m.albedo.num_texels(), 0);  // the mesh colors are unused.
  EXPECT_EQ(m.uv.corner_uvs.size(), 6u);
  EXPECT_EQ(m.uv.corner_uvs[1], Eigen::Vector2d(1, 0));
  EXPECT_EQ(m.uv.albedo.width(), 4);
  EXPECT_EQ(m.uv.albedo.height(), 2);
  EXPECT_EQ(m.uv.albedo.texel(1 * 4 + 3)[0], 0.75);  // texel (3, 1).
  EXPECT_EQ(m.uv.albedo.texel(1 * 4 + 3)[1], 0.5);
  EXPECT_EQ(m.uv.roughness.texel(2)[0], 0.25);
  EXPECT_EQ(m.specular, 0.25);
  EXPECT_EQ(m.fresnel, FresnelMode::kSchlick);
  EXPECT_EQ(m.NumAlbedoTexels(), 8);
  EXPECT_EQ(m.NumRoughnessTexels(), 8);
  EXPECT_EQ(&m.AlbedoValues(), &m.uv.albedo.values());
}

TEST(UvMaterialTest, SrgbDecodedAndConstantsAreOneTexel) {
  testing::TempDir tmp;
  WriteTextures(tmp);
  const TriMesh mesh = UvQuad(tmp, true);
  Material m;
  ASSERT_TRUE(LoadMaterial(R"({"uv_albedo": ")" + tmp.Join("albedo_srgb.png") +
                               R"(", "colorspace": "srgb", "roughness": 0.3})",
                           mesh, &m, MaterialUse::kRender)
                  .ok());
  // The 8-bit sRGB code of 0.75 decodes back to within one code step of 0.75.
  EXPECT_NEAR(m.uv.albedo.texel(3)[0], 0.75, 0.005);
  EXPECT_EQ(m.uv.roughness.num_texels(), 1);
  EXPECT_EQ(m.uv.roughness.texel(0)[0], 0.3);
  // Roughness map with a constant albedo.
  ASSERT_TRUE(LoadMaterial(R"({"albedo": [0.1, 0.2, 0.3], "uv_roughness": ")" +
                               tmp.Join("roughness.png") + R"("})",
                           mesh, &m, MaterialUse::kRender)
                  .ok());
  EXPECT_EQ(m.uv.albedo.num_texels(), 1);
  EXPECT_EQ(m.uv.albedo.texel(0)[2], 0.3);
  EXPECT_NEAR(m.uv.roughness.texel(3)[0], 3.0 / 8, 0.5 / 255);  // linear 8-bit.
}

// The MTL that `sft export` writes (src/export/obj_export.cc), read as the UV form.
TEST(UvMaterialTest, ReadsTheExportsMtl) {
  testing::TempDir tmp;
  WriteTextures(tmp);
  const TriMesh mesh = UvQuad(tmp, true);
  testing::WriteTestFile(tmp.Join("model.mtl"),
                         "# sft export\nnewmtl sft_material\nKd 1 1 1\nKs 0.2 0.2 0.2\nNs 0\n"
                         "illum 2\nmap_Kd albedo_srgb.png\nPr 1\nPm 0\nmap_Pr roughness.png\n");
  Material m;
  const Status status = LoadMaterial(tmp.Join("model.mtl"), mesh, &m, MaterialUse::kRender);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_TRUE(m.has_uv_textures());
  EXPECT_NEAR(m.uv.albedo.texel(3)[0], 0.75, 0.005);  // map_Kd is sRGB.
  EXPECT_NEAR(m.uv.roughness.texel(3)[0], 3.0 / 8, 0.5 / 255);
  EXPECT_EQ(m.specular, 0.2);
  // Without maps: the constant form.
  testing::WriteTestFile(tmp.Join("plain.mtl"), "newmtl a\nKd 0.5 0.25 0.125\nPr 0.75\n");
  ASSERT_TRUE(LoadMaterial(tmp.Join("plain.mtl"), mesh, &m).ok());
  EXPECT_FALSE(m.has_uv_textures());
  EXPECT_EQ(m.albedo.texel(0)[1], 0.25);
  EXPECT_EQ(m.roughness.texel(0)[0], 0.75);
}

TEST(UvMaterialTest, RefusedForFitting) {
  testing::TempDir tmp;
  WriteTextures(tmp);
  const TriMesh mesh = UvQuad(tmp, true);
  Material m;
  const Status status =
      LoadMaterial(R"({"uv_albedo": ")" + tmp.Join("albedo.exr") + R"("})", mesh, &m);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("\"uv_albedo\": a UV-texture material can be rendered"));
  m.uv.corner_uvs.resize(6);
  EXPECT_FALSE(SaveMaterial(tmp.Join("out.json"), m).ok());
}

TEST(UvMaterialTest, ErrorsNameTheFileAndField) {
  testing::TempDir tmp;
  WriteTextures(tmp);
  const TriMesh mesh = UvQuad(tmp, true);
  Image nan_image(2, 2, 3, 0.5f);
  nan_image.at(1, 1, 0) = std::nanf("");
  ASSERT_TRUE(WriteExr(tmp.Join("nan.exr"), nan_image).ok());
  const std::string a = tmp.Join("albedo.exr"), r = tmp.Join("roughness.exr");
  struct Case {
    std::string json;
    std::vector<std::string> expected;
  };
  const Case cases[] = {
      {R"({"uv_albedo": ")" + tmp.Join("absent.png") + R"("})",
       {"\"uv_albedo\": " + tmp.Join("absent.png") + ": file not found"}},
      {R"({"uv_albedo": ")" + r + R"("})", {"\"uv_albedo\": " + r, "expected an RGB image"}},
      {R"({"uv_roughness": ")" + a + R"("})",
       {"\"uv_roughness\": " + a, "expected a grey (1-channel) image, got 3 channels"}},
      {R"({"uv_albedo": ")" + tmp.Join("nan.exr") + R"("})",
       {"\"uv_albedo\": " + tmp.Join("nan.exr") + ": pixel (1, 1) has a non-finite value"}},
      {R"({"uv_albedo": ")" + a + R"(", "albedo": [1, 1, 1]})", {"cannot be combined"}},
      {R"({"uv_albedo": ")" + a + R"(", "resolution": 4})", {"\"resolution\": does not apply"}},
      {R"({"uv_albedo": ")" + a + R"(", "roughness_mesh_colors": "x"})",
       {"\"roughness_mesh_colors\": cannot be combined with \"uv_albedo\""}},
      {R"({"mesh_colors": "x", "uv_roughness": ")" + r + R"("})",
       {"\"uv_roughness\": cannot be combined with \"mesh_colors\""}},
      {R"({"uv_roughness": ")" + r + R"(", "colorspace": "srgb"})", {"\"colorspace\""}},
      {R"({"uv_albedo": 3})", {"\"uv_albedo\": expected a non-empty string"}},
  };
  for (const Case& c : cases) {
    Material m;
    const Status status = LoadMaterial(c.json, mesh, &m, MaterialUse::kRender);
    ASSERT_FALSE(status.ok()) << c.json;
    EXPECT_EQ(status.message().find('\n'), std::string::npos) << status.message();
    for (const std::string& e : c.expected) EXPECT_THAT(status.message(), HasSubstr(e)) << c.json;
  }
  // A mesh without UVs.
  Material m;
  const Status status = LoadMaterial(R"({"uv_albedo": ")" + a + R"("})", UvQuad(tmp, false), &m,
                                     MaterialUse::kRender);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("\"uv_albedo\": the mesh has no texture coordinates"));
}

TEST(UvMaterialTest, MtlErrorsNameTheStatement) {
  testing::TempDir tmp;
  WriteTextures(tmp);
  const TriMesh mesh = UvQuad(tmp, true);
  struct Case {
    std::string mtl;
    std::string expected;
  };
  const Case cases[] = {
      {"newmtl a\nmap_Kd absent.png\n",
       "\"map_Kd\": " + tmp.Join("absent.png") + ": file not found"},
      {"newmtl a\nmap_Kd roughness.png\n",
       "\"map_Kd\": " + tmp.Join("roughness.png") + ": expected an RGB image"},
      {"newmtl a\nnewmtl b\n", ":2: \"newmtl\": a second material"},
      {"newmtl a\nKd 0.5 1 1\nmap_Kd albedo.exr\n", ":2: \"Kd\": must be 1 1 1 with map_Kd"},
      {"newmtl a\nKs 0.1 0.2 0.3\n", ":2: \"Ks\": expected three equal numbers"},
      {"newmtl a\nPr nan\n", ":2: \"Pr\": \"nan\" is not a finite number"},
      {"newmtl a\nmap_Kd -s 2 2 1 albedo.exr\n", "\"map_Kd\": texture options (-s)"},
      {"newmtl a\nPm 1\n", "\"Pm\": must be 0"},
      {"newmtl a\nPr 2\n", "\"Pr\": expected a number in [0, 1], got 2"},
  };
  for (const Case& c : cases) {
    testing::WriteTestFile(tmp.Join("bad.mtl"), c.mtl);
    Material m;
    const Status status = LoadMaterial(tmp.Join("bad.mtl"), mesh, &m, MaterialUse::kRender);
    ASSERT_FALSE(status.ok()) << c.mtl;
    EXPECT_THAT(status.message(), HasSubstr(tmp.Join("bad.mtl"))) << c.mtl;
    EXPECT_THAT(status.message(), HasSubstr(c.expected)) << c.mtl;
  }
}

}  // namespace
}  // namespace sft
