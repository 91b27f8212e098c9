// `sft export` opened by a real client: Blender 3.4 (Debian's `blender`, headless) imports the
// OBJ (bpy.ops.wm.obj_import) and the GLB (the glTF add-on) of an exported wood-textured
// icosphere through scripts/blender_check_export.py, and what Blender holds is checked against
// what sft wrote: every vertex, every face and its corner UVs, the albedo texture on the
// Principled BSDF's Base Color (map_Kd / baseColorTexture, sRGB), the roughness texture on its
// Roughness (map_Pr / the metallic-roughness texture's G channel), and the texels Blender reads
// at every face's UV centroid equal to the PNG's. Skips with one line when Blender is absent
// (docs/export.md says how to install it).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/image/image_io.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using json = nlohmann::json;

// The v, vt and f v/vt lines of sft's model.obj (1-based indices made 0-based).
struct Obj {
  std::vector<std::array<double, 3>> v;
  std::vector<std::array<double, 2>> vt;
  std::vector<std::array<int, 3>> fv, ft;
};

Obj ReadObj(const std::string& path) {
  Obj obj;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      std::array<double, 3> p;
      s >> p[0] >> p[1] >> p[2];
      obj.v.push_back(p);
    } else if (tag == "vt") {
      std::array<double, 2> t;
      s >> t[0] >> t[1];
      obj.vt.push_back(t);
    } else if (tag == "f") {
      std::array<int, 3> fv, ft;
      for (int k = 0; k < 3; ++k) {
        char slash;
        s >> fv[k] >> slash >> ft[k];
        --fv[k];
        --ft[k];
      }
      obj.fv.push_back(fv);
      obj.ft.push_back(ft);
    }
  }
  return obj;
}

// Raw texel (byte / 255, no colour decoding) of `image` at UV (u, v), v up, nearest texel as the
// script samples it.
float Texel(const Image& image, double u, double v, int c) {
  const int x = std::min(std::max(static_cast<int>(u * image.width), 0), image.width - 1);
  const int y = std::min(std::max(static_cast<int>(v * image.height), 0), image.height - 1);
  return image.at(x, image.height - 1 - y, c);
}

// Checks Blender's texel samples of one texture: channel `blender_channel` of each sample against
// channel `channel` of sft's PNG. Returns the largest difference.
double CheckSamples(const json& samples, const Image& png, int channel, int blender_channel) {
  double worst = 0.0;
  for (const json& s : samples) {
    const double u = s[0].get<double>(), v = s[1].get<double>();
    worst =
        std::max(worst, std::abs(s[2 + blender_channel].get<double>() - Texel(png, u, v, channel)));
  }
  return worst;
}

// Blender's faces, vertices and UVs against sft's OBJ, corner by corner (positions, so that the
// glTF import's split vertices compare too).
void CheckMesh(const json& blender, const Obj& obj, const char* what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(blender["faces"].size(), obj.fv.size());
  EXPECT_EQ(blender["uv_layers"], 1);
  double position_error = 0.0, uv_error = 0.0;
  for (size_t f = 0; f < obj.fv.size(); ++f) {
    const json& face = blender["faces"][f];
    ASSERT_EQ(face["v"].size(), 3u);
    ASSERT_EQ(face["uv"].size(), 3u);
    for (int k = 0; k < 3; ++k) {
      const json& p = blender["vertices"][face["v"][k].get<int>()];
      for (int c = 0; c < 3; ++c) {
        position_error =
            std::max(position_error, std::abs(p[c].get<double>() - obj.v[obj.fv[f][k]][c]));
      }
      for (int c = 0; c < 2; ++c) {
        uv_error =
            std::max(uv_error, std::abs(face["uv"][k][c].get<double>() - obj.vt[obj.ft[f][k]][c]));
      }
    }
  }
  std::printf("%s: %zu faces, largest position difference %.2g, UV difference %.2g\n", what,
              obj.fv.size(), position_error, uv_error);
  EXPECT_LT(position_error, 1e-5);
  EXPECT_LT(uv_error, 1e-5);
}

TEST(BlenderRoundTripTest, BlenderReadsTheExport) {
  if (testing::RunCommand("command -v blender > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "blender not installed (apt-get install blender; docs/export.md)";
  }
  testing::TempDir tmp;
  ASSERT_EQ(testing::SynthIcosphere(
                tmp.Join("ds"),
                "--cameras 1 --zooms 1 --res 16 --spp 1 --material '{\"procedural\": \"wood\", "
                "\"scale\": 3, \"roughness_range\": [0.2, 0.7], \"specular\": 0.1}'"),
            "");
  std::string out;
  ASSERT_EQ(testing::RunSft("export --reconstruction " + tmp.Join("ds/gt") + " --out " +
                                tmp.Join("exp") + " --texture-size 256",
                            &out),
            0)
      << out;
  const std::string script = testing::DataDir() + "/../scripts/blender_check_export.py";
  ASSERT_EQ(testing::RunCommand("blender -b --factory-startup --python " + script + " -- " +
                                    tmp.Join("exp") + " " + tmp.Join("blender.json"),
                                &out),
            0)
      << out;
  const json report = json::parse(testing::ReadTestFile(tmp.Join("blender.json")));
  ASSERT_TRUE(report.contains("obj") && report.contains("glb")) << report.dump().substr(0, 2000);
  ASSERT_EQ(report["obj"].size(), 1u);
  ASSERT_EQ(report["glb"].size(), 1u);
  const Obj obj = ReadObj(tmp.Join("exp/model.obj"));
  Image albedo, roughness;
  ASSERT_TRUE(ReadImage(tmp.Join("exp/model_albedo.png"), &albedo, /*srgb=*/false).ok());
  ASSERT_TRUE(ReadImage(tmp.Join("exp/model_roughness.png"), &roughness, /*srgb=*/false).ok());

  // OBJ: the mesh, map_Kd on Base Color (sRGB), map_Pr on Roughness, Ks as Specular.
  const json& o = report["obj"][0];
  CheckMesh(o, obj, "obj");
  EXPECT_EQ(o["vertices"].size(), obj.v.size());
  ASSERT_EQ(o["materials"].size(), 1u);
  const json& om = o["materials"][0];
  EXPECT_EQ(om["base_color"]["image"], "model_albedo.png");
  EXPECT_EQ(om["base_color"]["colorspace"], "sRGB");
  EXPECT_EQ(om["roughness"]["image"], "model_roughness.png");
  EXPECT_NEAR(om["specular"]["value"].get<double>(), 0.1, 1e-6);
  // Blender 3.4's OBJ importer tags every texture sRGB, map_Pr included (MTL cannot say
  // otherwise); the glTF import below tags it Non-Color. Printed, not asserted.
  std::printf("obj: roughness texture colour space in Blender: %s\n",
              om["roughness"]["colorspace"].get<std::string>().c_str());
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    worst = std::max(worst, CheckSamples(om["samples"]["base_color"], albedo, c, c));
  }
  const double worst_roughness = CheckSamples(om["samples"]["roughness"], roughness, 0, 0);
  std::printf("obj: %zu texel samples; largest albedo difference %.2g, roughness %.2g\n",
              om["samples"]["base_color"].size(), worst, worst_roughness);
  EXPECT_EQ(om["samples"]["base_color"].size(), obj.fv.size());
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worst_roughness, 1e-6);

  // GLB: the same faces and UVs; baseColorTexture sRGB; roughness = G of the metallic-roughness
  // texture (Non-Color), which holds sft's roughness.
  const json& g = report["glb"][0];
  CheckMesh(g, obj, "glb");
  ASSERT_EQ(g["materials"].size(), 1u);
  const json& gm = g["materials"][0];
  EXPECT_EQ(gm["base_color"]["colorspace"], "sRGB");
  EXPECT_EQ(gm["roughness"]["colorspace"], "Non-Color");
  EXPECT_EQ(gm["roughness"]["from_socket"], "Green");
  worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    worst = std::max(worst, CheckSamples(gm["samples"]["base_color"], albedo, c, c));
  }
  const double worst_glb_roughness = CheckSamples(gm["samples"]["roughness"], roughness, 0, 1);
  std::printf("glb: largest albedo difference %.2g, roughness (G) %.2g; Specular %.3f\n", worst,
              worst_glb_roughness, gm["specular"].value("value", -1.0));
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worst_glb_roughness, 1e-6);
}

}  // namespace
}  // namespace sft
