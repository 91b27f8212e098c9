// ReadPlyPoints: point clouds (PLY without faces) for `sft init --points`.
#include <gtest/gtest.h>

#include <cstring>

#include "src/geometry/mesh.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

constexpr char kHeader[] =
    "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
    "property float z\nproperty uchar red\nend_header\n";

TEST(PlyPointsTest, ReadsAsciiAndBinaryPointClouds) {
  testing::TempDir tmp;
  testing::WriteTestFile(tmp.Join("a.ply"), std::string(kHeader) + "1 2 3 255\n-4 5.5 6 0\n");
  std::vector<Eigen::Vector3d> points;
  Status status = ReadPlyPoints(tmp.Join("a.ply"), &points);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0], Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(points[1], Eigen::Vector3d(-4, 5.5, 6));

  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\n"
      "property double y\nproperty double z\nend_header\n";
  const double xyz[3] = {0.25, -1.5, 1e-3};
  binary.append(reinterpret_cast<const char*>(xyz), sizeof(xyz));
  testing::WriteTestFile(tmp.Join("b.ply"), binary);
  status = ReadPlyPoints(tmp.Join("b.ply"), &points);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0], Eigen::Vector3d(0.25, -1.5, 1e-3));

  // Only PLY is read.
  status = ReadPlyPoints(testing::DataDir() + "/meshes/icosphere_r1_320f.obj", &points);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("must be PLY"), std::string::npos) << status.message();
}

TEST(PlyPointsTest, BadFilesAreOneLineErrorsNamingTheFile) {
  testing::TempDir tmp;
  struct Case {
    std::string name, contents, message;
  };
  const std::vector<Case> cases = {
      {"truncated.ply", std::string(kHeader) + "1 2 3 255\n-4 5.5\n", "truncated or malformed"},
      {"nan.ply", std::string(kHeader) + "1 2 3 255\nnan 5 6 0\n", "non-finite"},
      {"noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
       "lacks scalar x, y, z"},
      {"garbage.ply", "not a ply at all", "not a PLY file"},
      {"badface.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n3 0 1 2\n",
       "out of range"},
  };
  for (const Case& c : cases) {
    testing::WriteTestFile(tmp.Join(c.name), c.contents);
    std::vector<Eigen::Vector3d> points;
    const Status status = ReadPlyPoints(tmp.Join(c.name), &points);
    ASSERT_FALSE(status.ok()) << c.name;
    EXPECT_EQ(status.message().find(tmp.Join(c.name)), 0u) << status.message();
    EXPECT_NE(status.message().find(c.message), std::string::npos) << status.message();
    EXPECT_EQ(status.message().find('\n'), std::string::npos) << status.message();
  }
  std::vector<Eigen::Vector3d> points;
  EXPECT_FALSE(ReadPlyPoints(tmp.Join("missing.ply"), &points).ok());
}

}  // namespace
}  // namespace sft
