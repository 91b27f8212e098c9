// `sft eval` end to end: JSON on stdout (and in --json), exit codes, one-line errors naming the
// file or flag.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountLines;
using testing::RunSft;

using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string Sphere() { return testing::DataDir() + "/meshes/icosphere_r1_1280f.obj"; }

TEST(EvalCommandTest, PrintsJsonAndWritesIt) {
  testing::TempDir tmp;
  std::string out;
  ASSERT_EQ(RunSft("eval --reference " + Sphere() + " --mesh " + Sphere() +
                       " --samples 20000 --seed 3 --json " + tmp.Join("sub/eval.json"),
                   &out),
            0)
      << out;
  const nlohmann::json printed = nlohmann::json::parse(out);
  EXPECT_EQ(printed["mode"], "mesh");
  EXPECT_EQ(printed["f1"], 1.0);
  EXPECT_EQ(printed["precision"], 1.0);
  EXPECT_EQ(printed["recall"], 1.0);
  EXPECT_LT(printed["chamfer"].get<double>(), 1e-4);
  EXPECT_EQ(printed["samples"], 20000);
  EXPECT_EQ(printed["seed"], 3);
  EXPECT_EQ(printed["tolerance"], 0.01);
  for (const char* key : {"mean_mesh_to_reference", "mean_reference_to_mesh", "chamfer_definition",
                          "reference_diagonal", "reference", "mesh"}) {
    EXPECT_TRUE(printed.contains(key)) << key;
  }
  std::ifstream file(tmp.Join("sub/eval.json"));
  std::stringstream text;
  text << file.rdbuf();
  EXPECT_EQ(nlohmann::json::parse(text.str()), printed);
}

TEST(EvalCommandTest, DifferentMeshes) {
  testing::TempDir tmp;
  // The same sphere moved by 0.02 of its diagonal (2√3) along x: F1 well below 1.
  std::ifstream in(Sphere());
  std::ostringstream moved;
  std::string line;
  while (std::getline(in, line)) {
    double x, y, z;
    if (std::sscanf(line.c_str(), "v %lf %lf %lf", &x, &y, &z) == 3) {
      moved << "v " << x + 0.0692820323 << " " << y << " " << z << "\n";
    } else {
      moved << line << "\n";
    }
  }
  testing::WriteTestFile(tmp.Join("moved.obj"), moved.str());
  std::string out;
  ASSERT_EQ(RunSft("eval --reference " + Sphere() + " --mesh " + tmp.Join("moved.obj") +
                       " --samples 50000",
                   &out),
            0)
      << out;
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_NEAR(j["f1"].get<double>(), 0.5, 0.03);
  EXPECT_NEAR(j["chamfer"].get<double>(), 0.01, 0.001);
}

TEST(EvalCommandTest, ErrorsAreOneLineNamingTheFileOrFlag) {
  testing::TempDir tmp;
  testing::WriteTestFile(tmp.Join("bad.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
  testing::WriteTestFile(tmp.Join("nofaces.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  testing::WriteTestFile(tmp.Join("flat.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  const std::string ok = " --reference " + Sphere() + " --mesh " + Sphere();
  const struct {
    std::string args;
    std::string expected;
  } cases[] = {
      {"eval --reference " + tmp.Join("missing.ply") + " --mesh " + Sphere(), "missing.ply"},
      {"eval --reference " + Sphere() + " --mesh " + tmp.Join("bad.obj"), "bad.obj"},
      {"eval --reference " + Sphere() + " --mesh " + tmp.Join("nofaces.obj"), "nofaces.obj"},
      {"eval --reference " + Sphere() + " --mesh " + tmp.Join("flat.obj"), "flat.obj"},
      {"eval" + ok + " --tolerance 0", "--tolerance"},
      {"eval" + ok + " --tolerance -1", "--tolerance"},
      {"eval" + ok + " --tolerance nan", "--tolerance"},
      {"eval" + ok + " --samples 10", "--samples"},
      {"eval" + ok + " --samples 100000000", "--samples"},
      {"eval --reference " + Sphere(), "--mesh"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    std::string out;
    EXPECT_NE(RunSft(c.args, &out), 0);
    EXPECT_EQ(CountLines(out), 1) << out;
    EXPECT_THAT(out, StartsWith("sft eval: error: "));
    EXPECT_THAT(out, HasSubstr(c.expected));
  }
}

}  // namespace
}  // namespace sft
