// `sft export` end to end: the files of every format exist and read back (OBJ with the same faces
// and UVs in [0, 1], GLB through TinyGLTF, PLY through ReadMesh), the source frame and glTF's Y-up,
// inputs untouched, and one-line errors for bad input.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "tests/testing/dataset_scenes.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::RunSft;

// A reconstruction folder: the 320-face icosphere as mesh.ply and a random mesh-colors material.
std::string MakeReconstruction(const testing::TempDir& tmp) {
  const std::string dir = tmp.Join("rec");
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &mesh).ok());
  EXPECT_TRUE(WriteMesh(dir + "/mesh.ply", mesh).ok());
  Material m = ConstantMaterial(static_cast<int>(mesh.n_faces()), Eigen::Vector3d::Constant(0.5),
                                0.4, 0.2, 2);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> value(0.05, 0.95);
  for (double& v : m.albedo.values()) v = value(rng);
  EXPECT_TRUE(SaveMaterial(dir + "/material.json", m).ok());
  return dir;
}

struct Obj {
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector2d> vt;
  int faces = 0;
  bool face_lines_have_uvs = true;
};
Obj ParseObj(const std::string& text) {
  Obj obj;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    double a, b, c;
    int i[6];
    if (std::sscanf(line.c_str(), "v %lf %lf %lf", &a, &b, &c) == 3) obj.v.emplace_back(a, b, c);
    if (std::sscanf(line.c_str(), "vt %lf %lf", &a, &b) == 2) obj.vt.emplace_back(a, b);
    if (line.rfind("f ", 0) == 0) {
      ++obj.faces;
      obj.face_lines_have_uvs &= std::sscanf(line.c_str(), "f %d/%d %d/%d %d/%d", &i[0], &i[1],
                                             &i[2], &i[3], &i[4], &i[5]) == 6;
    }
  }
  return obj;
}

TEST(ExportCommandTest, WritesEveryFormatInTheSourceFrame) {
  testing::TempDir tmp;
  const std::string rec = MakeReconstruction(tmp);
  // A dataset recording p_source = 2·R·p + t with R a quarter turn about z.
  nlohmann::json scene = testing::MinimalScene();
  scene["source_from_world"] = {{"scale", 2.0},
                                {"rotation", {std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)}},
                                {"translation", {1.0, 2.0, 3.0}}};
  testing::WriteJson(tmp.Join("data"), scene);
  const std::string mesh_before = testing::ReadTestFile(rec + "/mesh.ply");
  const std::string material_before = testing::ReadTestFile(rec + "/material.json");
  std::string output;
  ASSERT_EQ(RunSft("export --reconstruction " + rec + " --out " + tmp.Join("out") + " --dataset " +
                       tmp.Join("data") + " --texture-size 256",
                   &output),
            0)
      << output;
  EXPECT_EQ(testing::ReadTestFile(rec + "/mesh.ply"), mesh_before);
  EXPECT_EQ(testing::ReadTestFile(rec + "/material.json"), material_before);
  const nlohmann::json summary =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("out/export.json")));
  EXPECT_EQ(summary["frame"], "source");
  EXPECT_EQ(summary["atlas"]["texture_size"], 256);
  EXPECT_GE(summary["atlas"]["charts"].get<int>(), 2);

  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(rec + "/mesh.ply", &mesh).ok());
  const Obj obj = ParseObj(testing::ReadTestFile(tmp.Join("out/model.obj")));
  EXPECT_EQ(obj.faces, 320);
  EXPECT_TRUE(obj.face_lines_have_uvs);
  ASSERT_EQ(obj.v.size(), mesh.n_vertices());
  EXPECT_GT(obj.vt.size(), mesh.n_vertices());  // split at chart seams.
  for (const Eigen::Vector2d& uv : obj.vt) {
    EXPECT_GE(uv.minCoeff(), 0.0);
    EXPECT_LE(uv.maxCoeff(), 1.0);
  }
  // Vertex 0 in the source frame: 2·Rz(90°)·p + t.
  const OpenMesh::Vec3d p = mesh.point(mesh.vertex_handle(0));
  const Eigen::Vector3d expected(1.0 - 2.0 * p[1], 2.0 + 2.0 * p[0], 3.0 + 2.0 * p[2]);
  EXPECT_LT((obj.v[0] - expected).norm(), 1e-6);
  const std::string mtl = testing::ReadTestFile(tmp.Join("out/model.mtl"));
  EXPECT_NE(mtl.find("map_Kd model_albedo.png"), std::string::npos);
  EXPECT_NE(mtl.find("map_Pr model_roughness.png"), std::string::npos);
  ASSERT_TRUE(ReadMesh(tmp.Join("out/model.ply"), &mesh).ok());
  EXPECT_EQ(mesh.n_faces(), 320u);
  EXPECT_NE(testing::ReadTestFile(tmp.Join("out/model.ply")).find("property uchar red"),
            std::string::npos);

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, tmp.Join("out/model.glb"))) << err;
  ASSERT_EQ(model.meshes.size(), 1u);
  const tinygltf::Primitive& primitive = model.meshes[0].primitives[0];
  EXPECT_EQ(model.accessors[primitive.indices].count, 3u * 320u);
  ASSERT_EQ(model.materials.size(), 1u);
  const tinygltf::Material& material = model.materials[0];
  EXPECT_EQ(material.pbrMetallicRoughness.metallicFactor, 0.0);
  EXPECT_GE(material.pbrMetallicRoughness.baseColorTexture.index, 0);
  EXPECT_GE(material.pbrMetallicRoughness.metallicRoughnessTexture.index, 0);
  ASSERT_TRUE(material.extensions.count("KHR_materials_specular"));
  EXPECT_NEAR(material.extensions.at("KHR_materials_specular")
                  .Get("specularColorFactor")
                  .Get(0)
                  .GetNumberAsDouble(),
              0.2 / 0.04, 1e-9);
  ASSERT_EQ(model.images.size(), 2u);
  EXPECT_EQ(model.images[0].width, 256);
  // glTF is Y-up: (x, y, z) of the export frame is stored as (x, z, −y).
  const tinygltf::Accessor& positions = model.accessors[primitive.attributes.at("POSITION")];
  const tinygltf::BufferView& view = model.bufferViews[positions.bufferView];
  const unsigned char* data = model.buffers[view.buffer].data.data() + view.byteOffset;
  float first[3];
  std::memcpy(first, data, sizeof(first));
  bool found = false;
  for (const Eigen::Vector3d& v : obj.v) {
    found |= (Eigen::Vector3d(v.x(), v.z(), -v.y()) - Eigen::Vector3d(first[0], first[1], first[2]))
                 .norm() < 1e-5;
  }
  EXPECT_TRUE(found);
}

TEST(ExportCommandTest, WithoutADatasetTheWorldFrameWithAWarning) {
  testing::TempDir tmp;
  const std::string rec = MakeReconstruction(tmp);
  std::string output;
  ASSERT_EQ(RunSft("export --reconstruction " + rec + " --out " + tmp.Join("out") + " --format ply",
                   &output),
            0)
      << output;
  EXPECT_NE(output.find("warning: "), std::string::npos);
  EXPECT_TRUE(testing::ReadTestFile(tmp.Join("out/model.obj")).empty());
  EXPECT_FALSE(testing::ReadTestFile(tmp.Join("out/model.ply")).empty());
  const nlohmann::json summary =
      nlohmann::json::parse(testing::ReadTestFile(tmp.Join("out/export.json")));
  EXPECT_EQ(summary["frame"], "world");
}

TEST(ExportCommandTest, BadInputIsOneLineAndWritesNothing) {
  testing::TempDir tmp;
  const std::string rec = MakeReconstruction(tmp);
  std::filesystem::create_directories(tmp.Join("broken"));
  std::filesystem::create_directories(tmp.Join("nomaterial"));
  testing::WriteTestFile(tmp.Join("broken/mesh.ply"), "ply\nformat ascii 1.0\nend_header\n");
  testing::WriteTestFile(tmp.Join("nomaterial/mesh.ply"), testing::ReadTestFile(rec + "/mesh.ply"));
  const struct {
    std::string args;
    std::string expected;
  } cases[] = {
      {"--reconstruction " + tmp.Join("missing") + " --out " + tmp.Join("o1"), "mesh.ply"},
      {"--reconstruction " + tmp.Join("broken") + " --out " + tmp.Join("o2"), "mesh.ply"},
      {"--reconstruction " + tmp.Join("nomaterial") + " --out " + tmp.Join("o3"), "material.json"},
      {"--reconstruction " + rec + " --out " + tmp.Join("o4") + " --format fbx", "--format"},
      {"--reconstruction " + rec + " --out " + tmp.Join("o5") + " --texture-size 10",
       "texture-size"},
      {"--reconstruction " + rec + " --out " + rec + "/inside", "--out"},
      {"--reconstruction " + rec + " --out " + tmp.Join("o6") + " --dataset " + tmp.Join("nodata"),
       "nodata"},
  };
  for (const auto& c : cases) {
    std::string output;
    EXPECT_EQ(RunSft("export " + c.args, &output), 1) << c.args << "\n" << output;
    EXPECT_EQ(testing::CountLines(output), 1) << output;
    EXPECT_NE(output.find("sft export: error:"), std::string::npos) << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << c.args << "\n" << output;
  }
  for (const char* out : {"o1", "o2", "o3", "o4", "o5", "o6"}) {
    EXPECT_TRUE(testing::ReadTestFile(tmp.Join(out) + "/export.json").empty()) << out;
  }
  EXPECT_TRUE(testing::ReadTestFile(rec + "/inside/export.json").empty());
}

}  // namespace
}  // namespace sft
