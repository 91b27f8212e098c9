// The hostile-input suite: runs the `sft` CLI on generated bad or unusual inputs (meshes,
// materials, datasets, options) and checks, for every case,
//   - a case meant to fail: an exit code in 1..125 (a clean error, not a signal or a crash) and
//     exactly one output line, which names the offending file, field or flag;
//   - a case meant to succeed: exit 0, every expected output written, and the outputs plausible
//     (render.json parses and lists the expected images; each image is a finite EXR of the
//     camera's size, not black unless the case expects black);
//   - either way: no file outside the output folder was created, changed or removed, and in
//     particular the dataset's files are byte-identical afterwards.
// Each case runs in its own folder holding a copy of a small synthesized dataset ("ds"), a mesh,
// a material file and an empty place for the output ("out").
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/image/image_io.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountLines;
using testing::RunSft;

namespace fs = std::filesystem;

// Every regular file and symlink below `root` (relative path -> contents, or "-> target"),
// except below the relative folders in `skip`.
std::map<std::string, std::string> Snapshot(const fs::path& root,
                                            const std::vector<std::string>& skip) {
  std::map<std::string, std::string> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    const std::string rel = fs::relative(it->path(), root).string();
    bool skipped = false;
    for (const std::string& s : skip) skipped = skipped || rel == s || rel.rfind(s + "/", 0) == 0;
    if (skipped) {
      if (it->is_directory() && !it->is_symlink()) it.disable_recursion_pending();
      continue;
    }
    if (it->is_symlink()) {
      files[rel] = "-> " + fs::read_symlink(it->path()).string();
      it.disable_recursion_pending();
    } else if (it->is_regular_file()) {
      std::ifstream in(it->path(), std::ios::binary);
      std::ostringstream ss;
      ss << in.rdbuf();
      files[rel] = ss.str();
    } else if (it->is_directory()) {
      files[rel + "/"] = "";
    }
  }
  return files;
}

// The render command most cases run.
constexpr char kRender[] = "render --quiet --dataset {ds} --mesh {mesh} --spp 2 --out {out}";

// A case: `prepare` edits the case folder; `args` is the command line after `sft`, in which
// {ds}, {out}, {mesh}, {material} and {dir} are replaced by paths in the case folder.
// `succeeds`: the command must exit 0 and write `outputs` (relative to the case folder), which
// `check` (when set) inspects further; otherwise it must fail with one line containing
// `error_mentions` (required: the file, field or flag at fault).
struct HostileCase {
  std::string name;
  std::function<void(const fs::path& dir)> prepare;
  std::string args;
  bool succeeds = false;
  std::vector<std::string> outputs;
  std::string error_mentions;
  std::function<void(const fs::path& dir)> check = nullptr;
};

class HostileInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    base_ = new testing::TempDir();
    const std::string mesh = testing::DataDir() + "/meshes/icosphere_r1_320f.obj";
    std::string out;
    const int code = testing::RunCommand(
        testing::SftBinary() + " synth --quiet --mesh " + mesh + " --out " + base_->Join("ds") +
            " --cameras 2 --zooms 1 --res 16 --spp 4 --bounces 1 --material "
            "'{\"albedo\": [0.6, 0.5, 0.4], \"roughness\": 0.5, \"specular\": 0.1}'",
        &out);
    ASSERT_EQ(code, 0) << out;
    fs::copy_file(mesh, base_->Join("mesh.obj"));
    testing::WriteTestFile(base_->Join("material.json"),
                           "{\"albedo\": [0.5, 0.5, 0.5], \"roughness\": 0.4}");
    // The plain mesh's render, for the cases that must render exactly as without their oddity.
    baseline_ = new testing::TempDir();
    ASSERT_EQ(
        testing::RunCommand(
            testing::SftBinary() + " " + Expand(kRender, base_->path()) + " --no-report", &out),
        0)
        << out;
    fs::rename(base_->Join("out"), baseline_->Join("out"));
  }
  static void TearDownTestSuite() {
    delete base_;
    base_ = nullptr;
    delete baseline_;
    baseline_ = nullptr;
  }

  // Checks that out/images/000.exr and 001.exr equal the plain mesh's render (same seed).
  static void SameAsBaseline(const fs::path& dir) {
    for (const char* name : {"images/000.exr", "images/001.exr"}) {
      Image ours, baseline;
      ASSERT_TRUE(ReadImage((dir / "out" / name).string(), &ours).ok()) << name;
      ASSERT_TRUE(ReadImage(baseline_->Join(std::string("out/") + name), &baseline).ok()) << name;
      ASSERT_EQ(ours.data.size(), baseline.data.size()) << name;
      double max_difference = 0.0;
      for (size_t i = 0; i < ours.data.size(); ++i) {
        max_difference =
            std::max(max_difference, std::abs(double{ours.data[i]} - baseline.data[i]));
      }
      EXPECT_LE(max_difference, 1e-5) << name;
    }
  }

  static std::string Expand(std::string args, const fs::path& dir) {
    const std::vector<std::pair<std::string, std::string>> keys = {
        {"{ds}", (dir / "ds").string()},
        {"{out}", (dir / "out").string()},
        {"{mesh}", (dir / "mesh.obj").string()},
        {"{material}", (dir / "material.json").string()},
        {"{dir}", dir.string()}};
    for (const auto& [key, value] : keys) {
      for (size_t at = args.find(key); at != std::string::npos; at = args.find(key, at)) {
        args.replace(at, key.size(), value);
        at += value.size();
      }
    }
    return args;
  }

  // Runs every case (each failure is reported under the case's name).
  void RunCases(const std::vector<HostileCase>& cases) {
    for (const HostileCase& c : cases) {
      SCOPED_TRACE(c.name);
      testing::TempDir tmp;
      const fs::path dir(tmp.path());
      fs::copy(base_->path(), dir, fs::copy_options::recursive);
      if (c.prepare) c.prepare(dir);
      const auto before = Snapshot(dir, {"out", "out.partial"});
      std::string output;
      const std::string command = testing::SftBinary() + " " + Expand(c.args, dir);
      const int code = testing::RunCommand(command, &output);
      if (c.succeeds) {
        EXPECT_EQ(code, 0) << command << "\n" << output;
        // --quiet: at most a warning or two (e.g. a comparison skipped), never a flood.
        EXPECT_LE(CountLines(output), 4) << output;
        if (code == 0) {
          for (const std::string& o : c.outputs) EXPECT_TRUE(fs::exists(dir / o)) << o;
          if (c.check) c.check(dir);
        }
      } else {
        EXPECT_FALSE(c.error_mentions.empty()) << "a failing case must say what the error names";
        EXPECT_TRUE(code >= 1 && code <= 125) << "exit " << code << " for: " << command << "\n"
                                              << output;
        EXPECT_EQ(CountLines(output), 1) << command << "\n" << output;
        EXPECT_THAT(output, ::testing::HasSubstr(c.error_mentions)) << command;
      }
      const auto after = Snapshot(dir, {"out", "out.partial"});
      EXPECT_TRUE(before == after) << "files outside out/ changed: " << command;
      for (const auto& [path, contents] : after) {
        const auto it = before.find(path);
        EXPECT_TRUE(it != before.end() && it->second == contents) << "touched: " << path;
      }
      for (const auto& [path, contents] : before) {
        EXPECT_TRUE(after.count(path) > 0) << "removed: " << path;
      }
      EXPECT_FALSE(fs::exists(dir / "out.partial")) << "temporary folder left behind";
    }
  }

  static testing::TempDir* base_;
  static testing::TempDir* baseline_;
};

testing::TempDir* HostileInputTest::base_ = nullptr;
testing::TempDir* HostileInputTest::baseline_ = nullptr;

void Write(const fs::path& path, const std::string& contents) {
  fs::create_directories(path.parent_path());
  testing::WriteTestFile(path.string(), contents);
}

std::string Read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Checks a successful `sft render` of the two-view dataset into out/: render.json parses and
// lists one entry per view whose "image" is `images[v]`; every image is a finite 16×16 EXR (the
// dataset's camera) that is black exactly when `black` (the test meshes cover part of every
// view). `skipped` lists the views whose comparison with the dataset image must be skipped
// (with a reason) rather than made.
std::function<void(const fs::path&)> RenderOutputs(const std::vector<std::string>& images,
                                                   bool black = false,
                                                   const std::vector<int>& skipped = {}) {
  return [images, black, skipped](const fs::path& dir) {
    const nlohmann::json report =
        nlohmann::json::parse(Read(dir / "out/render.json"), nullptr, /*allow_exceptions=*/false);
    ASSERT_TRUE(report.is_object()) << "render.json does not parse";
    ASSERT_TRUE(report["views"].is_array());
    ASSERT_EQ(report["views"].size(), images.size());
    for (size_t v = 0; v < images.size(); ++v) {
      const nlohmann::json& view = report["views"][v];
      EXPECT_EQ(view.value("image", ""), images[v]) << "view " << v;
      const bool skip =
          std::find(skipped.begin(), skipped.end(), static_cast<int>(v)) != skipped.end();
      EXPECT_EQ(view["comparison"].is_null(), skip) << "view " << v;
      if (skip) {
        EXPECT_FALSE(view.value("comparison_skipped", "").empty()) << "view " << v;
      }
      Image image;
      ASSERT_TRUE(ReadImage((dir / "out" / images[v]).string(), &image).ok()) << images[v];
      EXPECT_EQ(image.width, 16) << images[v];
      EXPECT_EQ(image.height, 16) << images[v];
      double sum = 0.0;
      bool finite = true;
      for (float x : image.data) {
        finite = finite && std::isfinite(x);
        sum += x;
      }
      EXPECT_TRUE(finite) << images[v];
      EXPECT_EQ(sum == 0.0, black) << images[v] << ": sum of values " << sum;
    }
  };
}

// Replaces the first occurrence of `from` in ds/scene.json by `to`.
std::function<void(const fs::path&)> EditScene(const std::string& from, const std::string& to) {
  return [from, to](const fs::path& dir) {
    std::string scene = Read(dir / "ds/scene.json");
    const size_t at = scene.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    scene.replace(at, from.size(), to);
    Write(dir / "ds/scene.json", scene);
  };
}

TEST_F(HostileInputTest, Datasets) {
  const std::string render = kRender;
  RunCases({
      {"no scene.json",
       [](const fs::path& d) { fs::remove(d / "ds/scene.json"); },
       render,
       false,
       {},
       "scene.json"},
      {"empty scene.json",
       [](const fs::path& d) { Write(d / "ds/scene.json", ""); },
       render,
       false,
       {},
       "scene.json"},
      {"garbage scene.json",
       [](const fs::path& d) { Write(d / "ds/scene.json", std::string("\x00\xff{[\"", 5)); },
       render,
       false,
       {},
       "scene.json"},
      {"truncated scene.json",
       [](const fs::path& d) {
         const std::string s = Read(d / "ds/scene.json");
         Write(d / "ds/scene.json", s.substr(0, s.size() / 2));
       },
       render,
       false,
       {},
       "scene.json"},
      {"wrong format tag",
       EditScene("sft-dataset/1", "sft-dataset/9"),
       render,
       false,
       {},
       "format"},
      {"absolute image path onto the dataset's own image",
       [](const fs::path& d) {
         EditScene("\"images/000.exr\"", "\"" + (d / "ds/images/000.exr").string() + "\"")(d);
       },
       render,
       false,
       {},
       "views[0].image"},
      {"image path escaping with ..",
       EditScene("\"images/000.exr\"", "\"../victim.exr\""),
       render,
       false,
       {},
       "views[0].image"},
      {"mask path escaping with ..",
       EditScene("\"masks/001.png\"", "\"masks/../../x.png\""),
       render,
       false,
       {},
       "views[1].mask"},
      {"missing image (render, comparison skipped with a warning)",
       [](const fs::path& d) { fs::remove(d / "ds/images/001.exr"); },
       render,
       true,
       {"out/images/000.exr", "out/images/001.exr", "out/render.json"},
       "",
       RenderOutputs({"images/000.exr", "images/001.exr"}, false, {1})},
      {"image of the wrong size (render, comparison skipped with a warning)",
       [](const fs::path& d) {
         ASSERT_TRUE(WritePng((d / "ds/images/x.png").string(), Image(8, 5, 3, 0.5f)).ok());
         EditScene("\"images/001.exr\"", "\"images/x.png\"")(d);
       },
       render,
       true,
       {"out/images/000.exr", "out/images/x.exr", "out/render.json"},
       "",
       RenderOutputs({"images/000.exr", "images/x.exr"}, false, {1})},
      {"unknown camera",
       EditScene("\"camera\": \"zoom0\"", "\"camera\": \"nope\""),
       render,
       false,
       {},
       "camera"},
      {"zero quaternion",
       EditScene("\"rotation\": [", "\"rotation\": [0, 0, 0, 0], \"x\": ["),
       render,
       false,
       {},
       "rotation"},
      {"camera width 0", EditScene("\"width\": 16", "\"width\": 0"), render, false, {}, "width"},
      {"camera of 100000 x 100000",
       [](const fs::path& d) {
         EditScene("\"width\": 16", "\"width\": 100000")(d);
         EditScene("\"height\": 16", "\"height\": 100000")(d);
       },
       render,
       false,
       {},
       "scene.json"},
      {"two views of one image: two outputs",
       EditScene("\"images/001.exr\"", "\"images/000.exr\""),
       render,
       true,
       {"out/images/000.exr", "out/images/000_view001.exr", "out/render.json"},
       "",
       [](const fs::path& d) {
         RenderOutputs({"images/000.exr", "images/000_view001.exr"})(d);
         // Two renders from two poses, not one file written twice.
         EXPECT_NE(Read(d / "out/images/000.exr"), Read(d / "out/images/000_view001.exr"));
       }},
      {"views in per-camera subfolders stay apart",
       [](const fs::path& d) {
         fs::create_directories(d / "ds/images/a");
         fs::create_directories(d / "ds/images/b");
         fs::copy_file(d / "ds/images/000.exr", d / "ds/images/a/0.exr");
         fs::copy_file(d / "ds/images/001.exr", d / "ds/images/b/0.exr");
         EditScene("\"images/000.exr\"", "\"images/a/0.exr\"")(d);
         EditScene("\"images/001.exr\"", "\"images/b/0.exr\"")(d);
       },
       render,
       true,
       {"out/images/a/0.exr", "out/images/b/0.exr", "out/render.json"},
       "",
       [](const fs::path& d) {
         RenderOutputs({"images/a/0.exr", "images/b/0.exr"})(d);
         EXPECT_NE(Read(d / "out/images/a/0.exr"), Read(d / "out/images/b/0.exr"));
       }},
  });
}

TEST_F(HostileInputTest, Meshes) {
  const std::string render = kRender;
  auto mesh = [](const std::string& contents) {
    return [contents](const fs::path& d) { Write(d / "mesh.obj", contents); };
  };
  RunCases({
      {"missing mesh",
       [](const fs::path& d) { fs::remove(d / "mesh.obj"); },
       render,
       false,
       {},
       "mesh.obj"},
      {"empty mesh", mesh(""), render, false, {}, "mesh.obj"},
      {"binary garbage",
       mesh(std::string("\x7f\x45\x4c\x46\x00\x01\xfe", 7)),
       render,
       false,
       {},
       "mesh.obj"},
      {"face index out of range",
       mesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
       render,
       false,
       {},
       "mesh.obj"},
      {"nan coordinate",
       mesh("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
       render,
       false,
       {},
       "mesh.obj"},
      {"vertices only", mesh("v 0 0 0\nv 1 0 0\nv 0 1 0\n"), render, false, {}, "mesh.obj"},
      {"zero-area faces only",
       mesh("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
       render,
       true,
       {"out/images/000.exr", "out/images/001.exr", "out/render.json"},
       "",
       RenderOutputs({"images/000.exr", "images/001.exr"}, /*black=*/true)},
      {"truncated PLY",
       [](const fs::path& d) {
         Write(d / "mesh.obj",
               "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\n"
               "property float y\nproperty float z\nelement face 10\nproperty list uchar int "
               "vertex_indices\nend_header\n\x01\x02");
         fs::rename(d / "mesh.obj", d / "mesh.ply");
       },
       "render --quiet --dataset {ds} --mesh {dir}/mesh.ply --spp 2 --out {out}",
       false,
       {},
       "mesh.ply"},
      {"OFF with negative counts",
       [](const fs::path& d) { Write(d / "m.off", "OFF\n-3 -1 0\n"); },
       "render --quiet --dataset {ds} --mesh {dir}/m.off --spp 2 --out {out}",
       false,
       {},
       "m.off"},
      {"unreferenced vertex at 1e23 (renders as without it)",
       [](const fs::path& d) {
         // Appended: a vertex put first would become OBJ index 1 and move every face onto it.
         std::string obj = Read(d / "mesh.obj");
         if (!obj.empty() && obj.back() != '\n') obj += '\n';
         Write(d / "mesh.obj", obj + "v 1e23 0 0\n");
       },
       render,
       true,
       {"out/images/000.exr", "out/images/001.exr", "out/render.json"},
       "",
       [](const fs::path& d) {
         RenderOutputs({"images/000.exr", "images/001.exr"})(d);
         SameAsBaseline(d);
       }},
      {"concave polygon that is not planar",
       mesh("v 0 0 0\nv 2 0 0\nv 2 2 1\nv 1 0.5 0\nv 0 2 0\nf 1 2 3 4 5\n"),
       render,
       false,
       {},
       "not planar"},
      {"self-intersecting quad",
       mesh("v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n"),
       render,
       false,
       {},
       "mesh.obj"},
      {"byte-order mark",
       [](const fs::path& d) { Write(d / "mesh.obj", "\xEF\xBB\xBF" + Read(d / "mesh.obj")); },
       render,
       true,
       {"out/images/000.exr", "out/images/001.exr", "out/render.json"},
       "",
       [](const fs::path& d) {
         RenderOutputs({"images/000.exr", "images/001.exr"})(d);
         SameAsBaseline(d);
       }},
      {"unknown extension",
       [](const fs::path& d) { Write(d / "m.stl", "solid x\n"); },
       "render --quiet --dataset {ds} --mesh {dir}/m.stl --spp 2 --out {out}",
       false,
       {},
       "m.stl"},
  });
}

TEST_F(HostileInputTest, Materials) {
  const std::string render = std::string(kRender) + " --material {material}";
  auto material = [](const std::string& contents) {
    return [contents](const fs::path& d) { Write(d / "material.json", contents); };
  };
  RunCases({
      {"malformed JSON", material("{\"albedo\": [0.5,"), render, false, {}, "material.json"},
      {"albedo above 1", material("{\"albedo\": [2, 0, 0]}"), render, false, {}, "albedo"},
      {"negative roughness", material("{\"roughness\": -1}"), render, false, {}, "roughness"},
      {"missing mesh-colors file",
       material("{\"mesh_colors\": \"nope.mc\"}"),
       render,
       false,
       {},
       "nope.mc"},
      {"texture on a mesh without UVs",
       material("{\"albedo_texture\": \"nope.png\"}"),
       render,
       false,
       {},
       "albedo_texture"},
      {"not an object", material("[1, 2, 3]"), render, false, {}, "material.json"},
      {"specular 1e20", material("{\"specular\": 1e20}"), render, false, {}, "specular"},
      {"specular NaN-like string",
       material("{\"specular\": \"nan\"}"),
       render,
       false,
       {},
       "specular"},
  });
}

TEST_F(HostileInputTest, OutputLocations) {
  RunCases({
      {"--out is the dataset",
       nullptr,
       "render --quiet --dataset {ds} --mesh {mesh} --spp 2 --out {ds}",
       false,
       {},
       "--out"},
      {"--out is ./ds/",
       nullptr,
       "render --quiet --dataset {ds} --mesh {mesh} --spp 2 --out {dir}/./ds/",
       false,
       {},
       "--out"},
      {"--out is a symlink to the dataset",
       [](const fs::path& d) { fs::create_directory_symlink(d / "ds", d / "link"); },
       "render --quiet --dataset {ds} --mesh {mesh} --spp 2 --out {dir}/link",
       false,
       {},
       "--out"},
      {"--out inside the dataset",
       nullptr,
       "render --quiet --dataset {ds} --mesh {mesh} --spp 2 --out {ds}/renders",
       false,
       {},
       "--out"},
      {"--out holds the dataset",
       nullptr,
       "render --quiet --dataset {ds} --mesh {mesh} --spp 2 --out {dir}",
       false,
       {},
       "--out"},
      {"--out holds the mesh",
       nullptr,
       "render --quiet --dataset {ds} --mesh {out}/../mesh.obj --spp 2 --out {dir}",
       false,
       {},
       "--out"},
      {"--out is an existing file",
       [](const fs::path& d) { Write(d / "out", "x"); },
       "render --quiet --dataset {ds} --mesh {mesh} --spp 2 --out {out}",
       false,
       {},
       "--out"},
      {"--out empty",
       nullptr,
       "render --quiet --dataset {ds} --mesh {mesh} --spp 2 --out ''",
       false,
       {},
       "--out"},
      {"synth --overwrite onto the mesh's folder",
       [](const fs::path& d) {
         fs::create_directories(d / "out");
         fs::copy_file(d / "mesh.obj", d / "out/in.obj");
       },
       "synth --quiet --mesh {out}/in.obj --out {out} --overwrite --cameras 1 --zooms 1 --res 8 "
       "--spp 1",
       false,
       {},
       "--out"},
      {"gradcheck --json onto the mesh",
       nullptr,
       "gradcheck --dataset {ds} --mesh {mesh} --param albedo --spp 1 --json {mesh}",
       false,
       {},
       "--json"},
      {"gradcheck --images into the dataset",
       nullptr,
       "gradcheck --dataset {ds} --mesh {mesh} --param albedo --spp 1 --images {ds}/img",
       false,
       {},
       "--images"},
      {"bench --json onto the mesh",
       nullptr,
       "bench render --mesh {mesh} --res 8 --spp 1 --json {mesh}",
       false,
       {},
       "--json"},
  });
}

TEST_F(HostileInputTest, Options) {
  const std::string base = "render --quiet --dataset {ds} --mesh {mesh} --out {out} ";
  RunCases({
      {"--spp 0", nullptr, base + "--spp 0", false, {}, "spp"},
      {"--spp -5", nullptr, base + "--spp -5", false, {}, "spp"},
      {"--spp abc", nullptr, base + "--spp abc", false, {}, "spp"},
      {"--bounces 100", nullptr, base + "--bounces 100", false, {}, "bounces"},
      {"--views 99", nullptr, base + "--views 99", false, {}, "views"},
      {"--views -1", nullptr, base + "--views -1", false, {}, "views"},
      {"--threads -3", nullptr, base + "--threads -3", false, {}, "threads"},
      {"--effects bogus", nullptr, base + "--effects bogus", false, {}, "effects"},
      {"--pass bogus", nullptr, base + "--pass bogus", false, {}, "--pass"},
      {"unknown flag", nullptr, base + "--sppp 3", false, {}, "sppp"},
      {"synth --res 0",
       nullptr,
       "synth --quiet --mesh {mesh} --out {out} --res 0",
       false,
       {},
       "res"},
      {"synth --cameras 0",
       nullptr,
       "synth --quiet --mesh {mesh} --out {out} --cameras 0",
       false,
       {},
       "cameras"},
      {"synth --light-offset nan",
       nullptr,
       "synth --quiet --mesh {mesh} --out {out} --light-offset nan,0,0",
       false,
       {},
       "light-offset"},
      {"synth --light-intensity -1",
       nullptr,
       "synth --quiet --mesh {mesh} --out {out} --light-intensity -1",
       false,
       {},
       "light-intensity"},
      {"reconstruct --steps 0",
       nullptr,
       "reconstruct --quiet --dataset {ds} --init {mesh} --out {out} --steps 0",
       false,
       {},
       "--steps"},
      {"reconstruct --out is the dataset",
       nullptr,
       "reconstruct --quiet --dataset {ds} --init {mesh} --out {ds}",
       false,
       {},
       "--out"},
      {"eval --json onto the mesh",
       nullptr,
       "eval --reference {mesh} --mesh {mesh} --samples 100 --json {mesh}",
       false,
       {},
       "--json"},
      {"synth --fov 200",
       nullptr,
       "synth --quiet --mesh {mesh} --out {out} --fov 200",
       false,
       {},
       "fov"},
      {"gradcheck --param bogus",
       nullptr,
       "gradcheck --dataset {ds} --mesh {mesh} --param bogus",
       false,
       {},
       "param"},
  });
}

}  // namespace
}  // namespace sft
