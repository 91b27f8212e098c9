// `sft import colmap` end to end on the stored COLMAP fixture (data/colmap/spot): the dataset
// loads, the cameras map back onto COLMAP's through source_from_world, the normalisation finds
// the object with and without masks; hostile inputs fail with one line and write nothing outside
// --out.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/colmap_model.h"
#include "src/io/dataset.h"
#include "src/io/point_cloud_ply.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::RunSft;

std::string Fixture() { return testing::DataDir() + "/colmap/spot"; }

// The similarity the fixture's script applied (scripts/make_colmap_fixture.py).
constexpr double kTrueScale = 3.7;
const Eigen::Vector3d kTrueTranslation(1.5, -2.0, 0.75);

Eigen::Vector3d Centre(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation) {
  return -(rotation.conjugate() * translation);
}

// Imports the fixture and checks the cameras against COLMAP's model.
void ImportAndCheck(const std::string& format, bool masks, const std::string& probe) {
  testing::TempDir tmp;
  const std::string out = tmp.Join("ds");
  std::string args = "import colmap --quiet --model " + Fixture() + "/sparse_" + format +
                     " --images " + Fixture() + "/images --out " + out;
  if (masks) args += " --masks " + Fixture() + "/masks";
  if (!probe.empty()) args += " --probe " + probe;
  std::string output;
  ASSERT_EQ(RunSft(args, &output), 0) << output;
  EXPECT_EQ(output, "");

  Dataset dataset;
  ASSERT_TRUE(ReadDataset(out, &dataset).ok());
  ASSERT_TRUE(CheckDatasetFiles(dataset).ok());
  ColmapModel model;
  ASSERT_TRUE(ReadColmapModel(Fixture() + "/sparse_" + format, &model).ok());
  ASSERT_EQ(dataset.views.size(), model.images.size());
  ASSERT_EQ(dataset.cameras.size(), 1u);
  EXPECT_EQ(dataset.cameras[0].params, model.cameras[0].params);
  ASSERT_TRUE(dataset.has_source_from_world);
  const Similarity3d& s = dataset.source_from_world;
  std::map<std::string, const ColmapImage*> by_png;
  for (const ColmapImage& image : model.images) {
    by_png["images/" + image.name.substr(0, image.name.size() - 4) + ".png"] = &image;
  }
  for (const ViewSpec& view : dataset.views) {
    ASSERT_EQ(by_png.count(view.image), 1u) << view.image;
    const ColmapImage& image = *by_png[view.image];
    const Eigen::Vector3d colmap_centre =
        Centre(image.cam_from_world_rotation, image.cam_from_world_translation);
    const Eigen::Vector3d mapped =
        s * Centre(view.cam_from_world.rotation, view.cam_from_world.translation);
    EXPECT_LT((mapped - colmap_centre).norm(), 1e-9 * colmap_centre.norm()) << view.image;
    EXPECT_LT(view.cam_from_world.rotation.angularDistance(image.cam_from_world_rotation), 1e-12);
    EXPECT_EQ(view.mask.empty(), !masks);
    EXPECT_EQ(view.lights.size(), probe.empty() ? 0u : 1u);
  }
  // The object is spot: its box centre sits at the script's translation, and its diagonal is
  // spot's (1 in synth's units, ×3.7) up to the rotation of the box's axes (within ×1.5).
  EXPECT_LT((s.translation - kTrueTranslation).norm(), 0.1 * kTrueScale) << s.translation;
  EXPECT_GT(s.scale, 0.7 * kTrueScale);
  EXPECT_LT(s.scale, 1.5 * kTrueScale);
  EXPECT_EQ(dataset.extra["import"]["normalization"]["method"], masks ? "masks" : "optical_axes");

  PointCloud sparse;
  ASSERT_TRUE(ReadPointCloudPly(JoinPath(out, dataset.sparse_points), &sparse).ok());
  ASSERT_EQ(sparse.positions.size(), model.points.size());
  for (size_t i = 0; i < model.points.size(); ++i) {
    EXPECT_LT((s * sparse.positions[i] - model.points[i].xyz).norm(), 1e-9 * kTrueScale);
  }
  EXPECT_EQ(dataset.image_encoding, "sRGB 8-bit JPEG converted to PNG; sRGB 8-bit PNG");
  if (probe.empty()) {
    EXPECT_EQ(dataset.lighting, "unknown");
  } else {
    // The probe was aligned (probe_alignment_test.cc checks the rotation in detail): synth's world
    // is the probe's env frame, and the fixture rotated it into COLMAP's frame by a known R.
    EXPECT_THAT(dataset.lighting, HasSubstr("probe aligned"));
    const double s = std::sin(0.4);
    const Eigen::Matrix3d truth =
        Eigen::Quaterniond(std::cos(0.4), s * 0.48, s * 0.6, s * 0.64).toRotationMatrix();
    const Eigen::Matrix3d error = truth.transpose() * dataset.lights[0].world_from_env;
    EXPECT_LT(Eigen::AngleAxisd(error).angle() * 180.0 / M_PI, 2.0);
  }
  EXPECT_EQ(dataset.background, probe.empty() ? Background::kBlack : Background::kEnvironment);
  // The PNG is a byte copy; a JPEG's pixels are the decoded JPEG's.
  std::string a, b;
  ASSERT_TRUE(ReadTextFile(Fixture() + "/images/023.png", &a).ok());
  ASSERT_TRUE(ReadTextFile(out + "/images/023.png", &b).ok());
  EXPECT_TRUE(a == b);
}

TEST(ImportColmapTest, BinaryWithMasks) { ImportAndCheck("bin", true, ""); }

TEST(ImportColmapTest, TextWithoutMasksWithProbe) {
  ImportAndCheck("txt", false, testing::DataDir() + "/cycles/sphere_env_studio/probes/studio.exr");
}

// --probe-ground on a model without a support plane (the fixture's points surround the object):
// one summary line says so, the import records it, and the probe is not hidden. (A found plane
// is checked against the truth's floor in tests/apps/video_reconstruct_long_test.cc.)
TEST(ImportColmapTest, ProbeGroundWithoutASupportPlaneLeavesTheProbeWhole) {
  testing::TempDir tmp;
  std::string output;
  ASSERT_EQ(RunSft("import colmap --model " + Fixture() + "/sparse_txt --images " + Fixture() +
                       "/images --probe " + testing::DataDir() +
                       "/cycles/sphere_env_studio/probes/studio.exr --probe-ground --out " +
                       tmp.Join("ds"),
                   &output),
            0)
      << output;
  EXPECT_THAT(output, HasSubstr("probe ground: no support plane found, the probe is not hidden"));
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  ASSERT_EQ(dataset.lights.size(), 1u);
  EXPECT_TRUE(dataset.lights[0].ground_normal.isZero());
  EXPECT_FALSE(dataset.has_support_plane);
  EXPECT_EQ(dataset.extra["import"]["normalization"]["probe_ground"], false);
}

TEST(ImportColmapTest, UnknownLightingIsReadableButNotRenderable) {
  testing::TempDir tmp;
  std::string output;
  ASSERT_EQ(RunSft("import colmap --quiet --model " + Fixture() + "/sparse_bin --images " +
                       Fixture() + "/images --out " + tmp.Join("ds"),
                   &output),
            0)
      << output;
  const int code =
      RunSft("render --quiet --dataset " + tmp.Join("ds") + " --mesh " + testing::DataDir() +
                 "/meshes/icosphere_r1_320f.obj --out " + tmp.Join("r"),
             &output);
  EXPECT_EQ(code, 1);
  EXPECT_THAT(output, HasSubstr("views[0].lights: empty (unknown lighting"));
  EXPECT_EQ(testing::CountLines(output), 1);
}

TEST(ImportColmapTest, DenseMeshBesideTheModelBecomesTheInitialMesh) {
  testing::TempDir tmp;
  // COLMAP's layout: PROJECT/sparse (the model) and PROJECT/dense/meshed-poisson.ply.
  fs::create_directories(tmp.Join("project/dense"));
  fs::copy(Fixture() + "/sparse_txt", tmp.Join("project/sparse"), fs::copy_options::recursive);
  // A quad in COLMAP's frame at the script's object centre.
  const Eigen::Vector3d c = kTrueTranslation;
  std::ostringstream ply;
  ply.precision(17);
  ply << "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
         "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      << c.x() << " " << c.y() << " " << c.z() << "\n"
      << c.x() + 1 << " " << c.y() << " " << c.z() << "\n"
      << c.x() << " " << c.y() + 1 << " " << c.z() << "\n3 0 1 2\n";
  testing::WriteTestFile(tmp.Join("project/dense/meshed-poisson.ply"), ply.str());
  testing::WriteTestFile(tmp.Join("project/dense/fused.ply"),
                         "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty "
                         "float y\nproperty float z\nend_header\n1.5 -2 0.75\n");
  std::string output;
  ASSERT_EQ(RunSft("import colmap --quiet --model " + tmp.Join("project/sparse") + " --images " +
                       Fixture() + "/images --out " + tmp.Join("ds"),
                   &output),
            0)
      << output;
  Dataset dataset;
  ASSERT_TRUE(ReadDataset(tmp.Join("ds"), &dataset).ok());
  EXPECT_EQ(dataset.initial_mesh, "init/mesh.ply");
  EXPECT_EQ(dataset.dense_points, "init/fused.ply");
  PointCloud mesh_vertices, fused;
  ASSERT_TRUE(ReadPointCloudPly(tmp.Join("ds/init/mesh.ply"), &mesh_vertices).ok());
  ASSERT_TRUE(ReadPointCloudPly(tmp.Join("ds/init/fused.ply"), &fused).ok());
  ASSERT_EQ(mesh_vertices.positions.size(), 3u);
  const Similarity3d& s = dataset.source_from_world;
  // WriteMesh (OpenMesh) stores float coordinates.
  EXPECT_LT((s * mesh_vertices.positions[1] - (c + Eigen::Vector3d(1, 0, 0))).norm(), 1e-6);
  EXPECT_LT((s * fused.positions[0] - c).norm(), 1e-6);  // fused.ply was float.
}

// ---- hostile inputs ----

std::map<std::string, std::string> Snapshot(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string rel = fs::relative(entry.path(), root).string();
    if (rel == "out" || rel.rfind("out/", 0) == 0) continue;
    std::string contents;
    if (entry.is_regular_file()) {
      EXPECT_TRUE(ReadTextFile(entry.path().string(), &contents).ok());
    }
    files[rel] = contents;
  }
  return files;
}

struct Case {
  std::string name;
  std::function<void(const fs::path& dir)> prepare;
  std::string error_mentions;
  std::string out = "{dir}/out";
  std::string model = "{dir}/model";
};

void Replace(std::string* s, const std::string& key, const std::string& value) {
  for (size_t at = s->find(key); at != std::string::npos; at = s->find(key, at + value.size())) {
    s->replace(at, key.size(), value);
  }
}

std::string ReadFile(const fs::path& p) {
  std::string s;
  EXPECT_TRUE(ReadTextFile(p.string(), &s).ok());
  return s;
}

TEST(ImportColmapTest, HostileInputsFailWithOneLineAndWriteNothingOutsideOut) {
  const std::vector<Case> cases = {
      {"truncated cameras.bin",
       [](const fs::path& d) {
         const std::string s = ReadFile(d / "model/cameras.bin");
         testing::WriteTestFile((d / "model/cameras.bin").string(), s.substr(0, s.size() - 5));
       },
       "cameras.bin: truncated"},
      {"garbage points3D.txt",
       [](const fs::path& d) {
         fs::remove(d / "model/cameras.bin");  // falls back to the text model.
         testing::WriteTestFile((d / "model/points3D.txt").string(), "1 2 3 \x01\xfe\n");
       },
       "points3D.txt: line 1"},
      {"unsupported camera model",
       [](const fs::path& d) {
         fs::remove(d / "model/cameras.bin");
         testing::WriteTestFile((d / "model/cameras.txt").string(),
                                "1 FULL_OPENCV 320 320 439 439 160 160 0 0 0 0 0 0 0 0\n");
       },
       "camera 1: camera model FULL_OPENCV is not supported"},
      {"image size mismatch",
       [](const fs::path& d) {
         fs::remove(d / "model/cameras.bin");
         testing::WriteTestFile((d / "model/cameras.txt").string(),
                                "1 PINHOLE 321 320 439 439 160 160\n");
       },
       "000.jpg: image is 320x320 but its camera c1 is 321x320"},
      {"missing image", [](const fs::path& d) { fs::remove(d / "images/005.jpg"); },
       "005.jpg: file not found"},
      {"missing mask", [](const fs::path& d) { fs::remove(d / "masks/007.jpg.png"); },
       "mask of image 007.jpg not found"},
      {"out is the model folder", nullptr, "--out", "{dir}/model"},
      {"no model", nullptr, "no COLMAP sparse model", "{dir}/out", "{dir}/images"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    testing::TempDir tmp;
    const fs::path dir(tmp.path());
    fs::copy(Fixture() + "/sparse_bin", dir / "model");
    for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
      fs::copy(Fixture() + "/sparse_txt/" + name, dir / "model" / name);
    }
    fs::copy(Fixture() + "/images", dir / "images");
    fs::copy(Fixture() + "/masks", dir / "masks");
    if (c.prepare) c.prepare(dir);
    const auto before = Snapshot(dir);
    std::string args = "import colmap --model " + c.model +
                       " --images {dir}/images --masks {dir}/masks --out " + c.out;
    Replace(&args, "{dir}", dir.string());
    std::string output;
    const int code = RunSft(args, &output);
    EXPECT_EQ(code, 1) << output;
    // One error line, the last of the output (a progress line of the image copy may precede it).
    const size_t at = output.rfind("sft import colmap: error:");
    ASSERT_NE(at, std::string::npos) << output;
    const std::string last = output.substr(at);
    EXPECT_EQ(testing::CountLines(last), 1) << output;
    EXPECT_THAT(last, HasSubstr(c.error_mentions));
    EXPECT_TRUE(before == Snapshot(dir)) << "files outside out/ changed";
    EXPECT_FALSE(fs::exists(dir / "out")) << "out/ written on failure";
    EXPECT_FALSE(fs::exists(dir / "out.partial")) << "temporary folder left behind";
  }
}

}  // namespace
}  // namespace sft
