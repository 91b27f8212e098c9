// The COLMAP model readers: the stored fixture (data/colmap/, written by COLMAP 3.8) reads the
// same from text and binary; hostile buffers give one error naming the file.
#include "src/io/colmap_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "src/core/file_util.h"
#include "src/io/point_cloud_ply.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

std::string FixtureDir(const std::string& format) {
  return testing::DataDir() + "/colmap/spot/sparse_" + format;
}

TEST(ColmapModelTest, TextAndBinaryFixturesAgree) {
  ColmapModel text, binary;
  std::string format;
  ASSERT_TRUE(ReadColmapModel(FixtureDir("txt"), &text, &format).ok());
  EXPECT_EQ(format, "text");
  ASSERT_TRUE(ReadColmapModel(FixtureDir("bin"), &binary, &format).ok());
  EXPECT_EQ(format, "binary");
  // model_converter writes images and points in hash-map order, which differs between formats.
  for (ColmapModel* m : {&text, &binary}) {
    std::sort(m->images.begin(), m->images.end(),
              [](const ColmapImage& a, const ColmapImage& b) { return a.id < b.id; });
    std::sort(m->points.begin(), m->points.end(),
              [](const ColmapPoint3D& a, const ColmapPoint3D& b) { return a.id < b.id; });
  }
  ASSERT_GE(text.images.size(), 10u);
  ASSERT_GE(text.points.size(), 100u);
  ASSERT_EQ(text.cameras.size(), binary.cameras.size());
  for (size_t i = 0; i < text.cameras.size(); ++i) {
    EXPECT_EQ(text.cameras[i].id, binary.cameras[i].id);
    EXPECT_EQ(text.cameras[i].model, binary.cameras[i].model);
    EXPECT_EQ(text.cameras[i].width, binary.cameras[i].width);
    EXPECT_EQ(text.cameras[i].height, binary.cameras[i].height);
    EXPECT_EQ(text.cameras[i].params, binary.cameras[i].params);
  }
  // COLMAP writes text with 17 significant digits (max_digits10): the values round-trip exactly.
  ASSERT_EQ(text.images.size(), binary.images.size());
  for (size_t i = 0; i < text.images.size(); ++i) {
    const ColmapImage& a = text.images[i];
    const ColmapImage& b = binary.images[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.camera_id, b.camera_id);
    EXPECT_EQ(a.cam_from_world_rotation.coeffs(), b.cam_from_world_rotation.coeffs());
    EXPECT_EQ(a.cam_from_world_translation, b.cam_from_world_translation);
    EXPECT_EQ(a.points2d, b.points2d);
    EXPECT_EQ(a.point3d_ids, b.point3d_ids);
  }
  ASSERT_EQ(text.points.size(), binary.points.size());
  for (size_t i = 0; i < text.points.size(); ++i) {
    const ColmapPoint3D& a = text.points[i];
    const ColmapPoint3D& b = binary.points[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.xyz, b.xyz);
    EXPECT_EQ(a.rgb, b.rgb);
    EXPECT_EQ(a.error, b.error);
    ASSERT_EQ(a.track.size(), b.track.size());
    for (size_t k = 0; k < a.track.size(); ++k) {
      EXPECT_EQ(a.track[k].image_id, b.track[k].image_id);
      EXPECT_EQ(a.track[k].point2d_index, b.track[k].point2d_index);
    }
  }
}

TEST(ColmapModelTest, ParsesTextRecords) {
  std::vector<ColmapCamera> cameras;
  ASSERT_TRUE(ParseColmapCamerasText("# comment\n\n1 PINHOLE 640 480 500 501 320 240\r\n"
                                     "2 FULL_OPENCV 10 10 1 1 5 5 0 0 0 0 0 0 0 0\n",
                                     "cameras.txt", &cameras)
                  .ok());
  ASSERT_EQ(cameras.size(), 2u);
  EXPECT_EQ(cameras[0].params, (std::vector<double>{500, 501, 320, 240}));
  EXPECT_EQ(cameras[1].model, "FULL_OPENCV");  // kept: the importer decides what sft supports.

  std::vector<ColmapImage> images;
  ASSERT_TRUE(ParseColmapImagesText("1 1 0 0 0 0.5 0 2 1 my frame.jpg\n10 20 -1 30 40 7\n"
                                    "2 0 1 0 0 0 0 0 1 b.png\n\n",
                                    "images.txt", &images)
                  .ok());
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[0].name, "my frame.jpg");
  EXPECT_EQ(images[0].point3d_ids, (std::vector<int64_t>{-1, 7}));
  EXPECT_TRUE(images[1].points2d.empty());

  std::vector<ColmapPoint3D> points;
  ASSERT_TRUE(
      ParseColmapPointsText("7 1 2 3 255 128 0 0.5 1 1 2 0\n", "points3D.txt", &points).ok());
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].track.size(), 2u);
  EXPECT_EQ(points[0].rgb[1], 128);
}

TEST(ColmapModelTest, HostileTextGivesOneLineNamingFileAndLine) {
  std::vector<ColmapCamera> cameras;
  Status s = ParseColmapCamerasText("1 PINHOLE 640 480 500 501 320\n", "c.txt", &cameras);
  EXPECT_THAT(s.message(), HasSubstr("c.txt: line 1: camera 1: PINHOLE needs 4 parameters"));
  s = ParseColmapCamerasText("\n1 WEIRD 6 4 1\n", "c.txt", &cameras);
  EXPECT_THAT(s.message(), HasSubstr("c.txt: line 2: camera 1: unknown camera model"));
  s = ParseColmapCamerasText("1 PINHOLE 640 480 nan 1 1 1\n", "c.txt", &cameras);
  EXPECT_THAT(s.message(), HasSubstr("c.txt: line 1"));
  s = ParseColmapCamerasText("1 PINHOLE 1 1 1 1 1 1\n1 PINHOLE 1 1 1 1 1 1\n", "c.txt", &cameras);
  EXPECT_THAT(s.message(), HasSubstr("duplicate camera id 1"));
  std::vector<ColmapImage> images;
  s = ParseColmapImagesText("1 0 0 0 0 0 0 0 1 a.png\n\n", "i.txt", &images);
  EXPECT_THAT(s.message(), HasSubstr("i.txt: line 1: image 1: rotation quaternion"));
  s = ParseColmapImagesText("1 1 0 0 0 0 0 0 1 a.png\n1 2\n", "i.txt", &images);
  EXPECT_THAT(s.message(), HasSubstr("i.txt: line 2"));
  std::vector<ColmapPoint3D> points;
  s = ParseColmapPointsText("\x01\xff garbage\n", "p.txt", &points);
  EXPECT_THAT(s.message(), HasSubstr("p.txt: line 1"));
  s = ParseColmapPointsText("1 0 0 0 300 0 0 0\n", "p.txt", &points);
  EXPECT_THAT(s.message(), HasSubstr("colour"));
  for (const Status& status : {s}) EXPECT_EQ(status.message().find('\n'), std::string::npos);
}

std::string Bytes(const void* p, size_t n) { return std::string(static_cast<const char*>(p), n); }

TEST(ColmapModelTest, HostileBinaryChecksCountsBeforeAllocating) {
  std::vector<ColmapCamera> cameras;
  const uint64_t huge = uint64_t{1} << 60;
  Status s = ParseColmapCamerasBinary(Bytes(&huge, 8), "c.bin", &cameras);
  EXPECT_THAT(s.message(), HasSubstr("c.bin: 1152921504606846976 cameras announced"));
  s = ParseColmapCamerasBinary("", "c.bin", &cameras);
  EXPECT_THAT(s.message(), HasSubstr("c.bin: truncated"));
  // One camera with model id 99.
  std::string record = Bytes("\x01\0\0\0\0\0\0\0", 8);
  const uint32_t id = 3;
  const int32_t model = 99;
  const uint64_t size = 10;
  record += Bytes(&id, 4) + Bytes(&model, 4) + Bytes(&size, 8) + Bytes(&size, 8);
  s = ParseColmapCamerasBinary(record, "c.bin", &cameras);
  EXPECT_THAT(s.message(), HasSubstr("c.bin: camera 3: unknown camera model id 99"));

  std::vector<ColmapImage> images;
  std::string image = Bytes("\x01\0\0\0\0\0\0\0", 8);
  const double q[7] = {1, 0, 0, 0, 0, 0, 0};
  image += Bytes(&id, 4) + Bytes(q, 56) + Bytes(&id, 4) + std::string("a.png", 6) + Bytes(&huge, 8);
  s = ParseColmapImagesBinary(image, "i.bin", &images);
  EXPECT_THAT(s.message(), HasSubstr("i.bin: 1152921504606846976 2D points announced"));

  std::vector<ColmapPoint3D> points;
  s = ParseColmapPointsBinary(Bytes(&huge, 8) + std::string(100, '\0'), "p.bin", &points);
  EXPECT_THAT(s.message(), HasSubstr("p.bin: 1152921504606846976 points announced"));
}

TEST(ColmapModelTest, EveryTruncationOfTheBinaryFixtureIsAnError) {
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    std::string data;
    ASSERT_TRUE(ReadTextFile(FixtureDir("bin") + "/" + name, &data).ok());
    // Cut at a spread of lengths (every length for the small cameras file).
    const size_t step = std::max<size_t>(1, data.size() / 300);
    for (size_t n = 0; n < data.size(); n += step) {
      const std::string cut = data.substr(0, n);
      Status s;
      if (name[0] == 'c') {
        std::vector<ColmapCamera> v;
        s = ParseColmapCamerasBinary(cut, name, &v);
      } else if (name[0] == 'i') {
        std::vector<ColmapImage> v;
        s = ParseColmapImagesBinary(cut, name, &v);
      } else {
        std::vector<ColmapPoint3D> v;
        s = ParseColmapPointsBinary(cut, name, &v);
      }
      ASSERT_FALSE(s.ok()) << name << " cut at " << n;
      EXPECT_THAT(s.message(), HasSubstr(name));
    }
  }
}

TEST(ColmapModelTest, CrossFileReferencesAreChecked) {
  ColmapModel model;
  ASSERT_TRUE(ReadColmapModel(FixtureDir("txt"), &model).ok());
  ColmapModel bad = model;
  bad.images[0].camera_id = 4242;
  EXPECT_THAT(CheckColmapModel(bad, "m").message(), HasSubstr("camera 4242"));
  bad = model;
  bad.points[0].track.push_back({99999, 0});
  EXPECT_THAT(CheckColmapModel(bad, "m").message(), HasSubstr("image 99999"));
  bad = model;
  bad.points[0].track[0].point2d_index = 1u << 30;
  EXPECT_THAT(CheckColmapModel(bad, "m").message(), HasSubstr("2D point"));
}

TEST(PointCloudPlyTest, RoundTripAndHostileHeaders) {
  testing::TempDir tmp;
  PointCloud cloud;
  cloud.positions = {{1, 2, 3}, {-0.25, 0.5, 1e-9}};
  cloud.colors = {{{1, 2, 3}}, {{250, 128, 0}}};
  ASSERT_TRUE(WritePointCloudPly(tmp.Join("p.ply"), cloud).ok());
  PointCloud back;
  ASSERT_TRUE(ReadPointCloudPly(tmp.Join("p.ply"), &back).ok());
  EXPECT_EQ(back.positions, cloud.positions);
  EXPECT_EQ(back.colors, cloud.colors);
  EXPECT_TRUE(back.normals.empty());

  ASSERT_TRUE(ParsePointCloudPly("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                 "property float y\nproperty float z\nproperty float nx\n"
                                 "property float ny\nproperty float nz\nelement face 0\n"
                                 "property list uchar int vertex_indices\nend_header\n"
                                 "1 2 3 0 0 1\n4 5 6 0 1 0\n",
                                 "a.ply", &back)
                  .ok());
  EXPECT_EQ(back.positions[1], Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(back.normals[1], Eigen::Vector3d(0, 1, 0));

  for (const std::string& bad :
       {std::string("garbage"), std::string("ply\nformat binary_big_endian 1.0\n"),
        std::string("ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
                    "property double x\nproperty double y\nproperty double z\nend_header\n"),
        std::string("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n"),
        std::string("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float "
                    "y\nproperty float z\nend_header\n1 2 3\n")}) {
    const Status s = ParsePointCloudPly(bad, "bad.ply", &back);
    EXPECT_FALSE(s.ok()) << bad;
    EXPECT_THAT(s.message(), HasSubstr("bad.ply: ")) << bad;
  }
}

}  // namespace
}  // namespace sft
