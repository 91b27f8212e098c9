// `sft export` rendered by a real client: Blender 3.4's Cycles renders the exported OBJ (through
// scripts/blender_render_export.py: the OBJ importer's Principled BSDF, its roughness texture
// retagged Non-Color) from a dataset's camera under a point light the export was never fitted or
// baked under, and sft renders the same model.obj + model.mtl (`sft render --material
// EXP/model.mtl`, the UV-texture material) from the same camera under the same light. The two
// images are compared by the mean absolute difference over the object relative to the mean of
// Cycles' (CompareImages, as the renderer's own Cycles validation). A specular-0 object must agree
// within 3%; a glossy one is only reported, since the Principled BSDF is not sft's BSDF
// (docs/export.md, "glTF material: the mapping and what it loses"). Both are also rendered with
// sft's BSDF built from Cycles nodes on the same imported textures, which must agree within 1%:
// that isolates the files from the BSDF model. Skips with one line when Blender is absent
// (docs/export.md says how to install it).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "src/core/image.h"
#include "src/eval/image_compare.h"
#include "src/image/image_io.h"
#include "tests/testing/synth_dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using json = nlohmann::json;

// The icosphere fills about 80% of the image's width (--fill 1.4 puts its bounding sphere, not
// the sphere itself, at 1.4 half-widths): ~3400 interior pixels at 80².
constexpr int kResolution = 80;
// Samples per pixel of both renderers. The object is convex and lit by one point light with direct
// light only, so the only Monte Carlo noise is the pixel-area integration of the texture (and of
// the flat faces' shading steps): a few tenths of a percent at this count.
constexpr int kSpp = 32;
// Pixels whose coverage is below this in either render are left out: at the silhouette the
// coverage itself is a Monte Carlo estimate (several percent at kSpp), unrelated to the export.
constexpr float kInteriorCoverage = 0.999f;

// 1 where both renders' alpha (pixel coverage) is at least kInteriorCoverage.
Image InteriorMask(const Image& a, const Image& b) {
  Image mask(a.width, a.height, 1);
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      mask.at(x, y) =
          a.at(x, y, 3) >= kInteriorCoverage && b.at(x, y, 3) >= kInteriorCoverage ? 1.0f : 0.0f;
    }
  }
  return mask;
}

// Turns the dataset at `dir` (one view, lit by sft synth's camera flash) into the same view lit
// only by a world-fixed point light: the camera centre turned 60° about the vertical axis through
// the object and raised by half its distance, so that most of the visible side is lit at
// oblique angles the flash never lit it from. Its intensity puts radiance ~0.5 on a white patch
// facing it at the object's centre (I = π·d²/2, as sft synth's flash).
void RelightWithSideLamp(const std::string& dir) {
  json scene = json::parse(testing::ReadTestFile(dir + "/scene.json"));
  const json& pose = scene["views"][0]["cam_from_world"];
  const double w = pose["rotation"][0], x = pose["rotation"][1], y = pose["rotation"][2],
               z = pose["rotation"][3];
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  double c[3];  // camera centre −Rᵀt.
  for (int k = 0; k < 3; ++k) {
    c[k] = 0.0;
    for (int j = 0; j < 3; ++j) c[k] -= r[j][k] * pose["translation"][j].get<double>();
  }
  const double distance = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  const double angle = M_PI / 3.0;
  const double p[3] = {std::cos(angle) * c[0] - std::sin(angle) * c[1],
                       std::sin(angle) * c[0] + std::cos(angle) * c[1], c[2] + 0.5 * distance};
  const double d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
  scene["lights"] = json::array({{{"id", "lamp"},
                                  {"type", "point"},
                                  {"frame", "world"},
                                  {"position", {p[0], p[1], p[2]}},
                                  {"intensity", M_PI * d2 / 2.0}}});
  scene["views"][0]["lights"] = json::array({"lamp"});
  testing::WriteTestFile(dir + "/scene.json", scene.dump(1));
}

// One Cycles render of the export at `exp` through the script into `out`/000.exr; "" on success,
// else the script's output.
std::string RenderWithCycles(const std::string& exp, const std::string& dataset,
                             const std::string& out, const std::string& flags) {
  const std::string script = testing::DataDir() + "/../scripts/blender_render_export.py";
  std::string output;
  const int code = testing::RunCommand("blender -b --factory-startup --python " + script + " -- " +
                                           exp + " " + dataset + " " + out + " --views 0 --spp " +
                                           std::to_string(kSpp) + " --bounces 1 " + flags,
                                       &output);
  return code == 0 ? std::string() : "blender failed (" + std::to_string(code) + "): " + output;
}

// sft's and Cycles' renders of one material's export under the side lamp, compared.
struct Comparison {
  ImageAgreement principled;  // Cycles with the importer's Principled BSDF.
  ImageAgreement sft_bsdf;    // Cycles with sft's BSDF in nodes on the same textures.
};

// Synthesizes the wood icosphere with specular weight `specular`, exports it, relights it and
// compares the renders. `specular_flag` is the script's --specular for the Principled render.
void CompareRenders(const testing::TempDir& tmp, const std::string& name, double specular,
                    const std::string& specular_flag, Comparison* result) {
  const std::string ds = tmp.Join(name + "_ds"), exp = tmp.Join(name + "_exp");
  char material[160];
  std::snprintf(material, sizeof(material),
                "'{\"procedural\": \"wood\", \"scale\": 3, \"roughness_range\": [0.2, 0.7], "
                "\"specular\": %g}'",
                specular);
  ASSERT_EQ(
      testing::SynthIcosphere(ds, "--cameras 1 --zooms 1 --res " + std::to_string(kResolution) +
                                      " --fill 1.4 --spp 1 --material " + material),
      "");
  std::string out;
  ASSERT_EQ(testing::RunSft("export --reconstruction " + ds + "/gt --out " + exp +
                                " --format obj --texture-size 256",
                            &out),
            0)
      << out;
  RelightWithSideLamp(ds);
  const std::string sft_out = tmp.Join(name + "_sft");
  ASSERT_EQ(testing::RunSft("render --quiet --no-report --dataset " + ds + " --mesh " + exp +
                                "/model.obj --material " + exp + "/model.mtl --shading flat" +
                                " --bounces 1 --spp " + std::to_string(kSpp) + " --out " + sft_out,
                            &out),
            0)
      << out;
  Image ours;
  const Status read = ReadImage(sft_out + "/images/000.exr", &ours);
  ASSERT_TRUE(read.ok()) << read.message();
  ASSERT_EQ(ours.channels, 4);
  for (const bool principled : {true, false}) {
    const std::string cycles_out = tmp.Join(name + (principled ? "_principled" : "_nodes"));
    ASSERT_EQ(RenderWithCycles(exp, ds, cycles_out,
                               principled ? "--specular " + specular_flag : "--shader sft"),
              "");
    Image cycles;
    const Status status = ReadImage(cycles_out + "/000.exr", &cycles);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_EQ(cycles.width, ours.width);
    ASSERT_EQ(cycles.height, ours.height);
    ASSERT_EQ(cycles.channels, 4);
    const ImageAgreement a = CompareImages(ours, cycles, InteriorMask(ours, cycles));
    std::printf("%s, Cycles with %s: mean|sft - cycles|/mean %.4f, bias %+.4f over %d pixels\n",
                name.c_str(), principled ? "the Principled BSDF" : "sft's BSDF in nodes",
                a.relative_mean_abs_difference, a.relative_mean_difference, a.object_pixels);
    (principled ? result->principled : result->sft_bsdf) = a;
  }
}

TEST(BlenderRenderTest, CyclesRendersTheExportAsSftDoes) {
  if (testing::RunCommand("command -v blender > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "blender not installed (bash scripts/setup.sh --with-blender; docs/export.md)";
  }
  testing::TempDir tmp;
  Comparison diffuse;
  ASSERT_NO_FATAL_FAILURE(CompareRenders(tmp, "diffuse", 0.0, "mtl", &diffuse));
  EXPECT_GT(diffuse.principled.object_pixels, 1000);
  // 3% (issue 21). Most of it is the BSDF: Cycles 3.4's Principled BSDF has Burley's (Disney)
  // diffuse lobe, not Lambert's (darker towards grazing view and light, plus a roughness-dependent
  // retro-reflection), which is not noise and does not shrink with spp; under this oblique lamp
  // it is worth 2–2.5% (docs/export.md). The rest is Monte Carlo noise at kSpp, a few tenths of
  // a percent; the two renderers' filtering of the 8-bit textures differs by less than that.
  EXPECT_LE(diffuse.principled.relative_mean_abs_difference, 0.03);
  // The same textures through sft's own BSDF in Cycles nodes leave only that noise and filtering:
  // 1% is several times their size and well below what a wrong UV, texel row order, colour space
  // (sRGB against linear changes the albedo by tens of percent) or light unit would cause.
  EXPECT_LE(diffuse.sft_bsdf.relative_mean_abs_difference, 0.01);

  // Glossy: reported only. --specular f0 gives the Principled BSDF sft's F0 (the MTL's Ks is
  // imported as Specular = Ks, F0 = 0.08·Ks); its Fresnel, which rises towards grazing angles
  // where sft's lobe has none, remains.
  Comparison glossy;
  ASSERT_NO_FATAL_FAILURE(CompareRenders(tmp, "glossy", 0.3, "f0", &glossy));
  // Through sft's BSDF in nodes the glossy export must agree as the diffuse one does: this checks
  // the roughness texture (Non-Color, α = roughness²) and the specular weight of the MTL.
  EXPECT_LE(glossy.sft_bsdf.relative_mean_abs_difference, 0.01);
}

}  // namespace
}  // namespace sft
