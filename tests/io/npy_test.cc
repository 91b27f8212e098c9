// .npy arrays and .npz archives (written here with libzip, tests/testing/npz_writer.h), and the
// IDR camera arrays read from them.
#include "src/io/npy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "src/io/idr_cameras.h"
#include "src/io/npz.h"
#include "tests/testing/npz_writer.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing::NpyBytes;

std::string NpyError(const std::string& bytes) {
  NpyArray array;
  const Status status = ParseNpy(bytes, "a.npy", &array);
  EXPECT_FALSE(status.ok());
  return status.message();
}

TEST(NpyTest, ReadsFloat64AndFloat32InCOrder) {
  NpyArray array;
  ASSERT_TRUE(ParseNpy(NpyBytes({2, 3}, {1, 2, 3, 4, 5, 6.5}), "a.npy", &array).ok());
  EXPECT_THAT(array.shape, ElementsAre(2, 3));
  EXPECT_THAT(array.values, ElementsAre(1, 2, 3, 4, 5, 6.5));
  ASSERT_TRUE(ParseNpy(NpyBytes({3}, {0.25, -1, 7}, "<f4"), "a.npy", &array).ok());
  EXPECT_THAT(array.shape, ElementsAre(3));
  EXPECT_THAT(array.values, ElementsAre(0.25, -1, 7));
  ASSERT_TRUE(ParseNpy(NpyBytes({}, {42}), "a.npy", &array).ok());  // a 0-d array.
  EXPECT_TRUE(array.shape.empty());
  EXPECT_THAT(array.values, ElementsAre(42));
}

TEST(NpyTest, RejectsWhatItDoesNotRead) {
  EXPECT_THAT(NpyError("PK\x03\x04 not npy"), HasSubstr("a.npy: not a .npy file"));
  EXPECT_THAT(NpyError(NpyBytes({2}, {1, 2}, ">f8")), HasSubstr("descr '>f8' is not supported"));
  EXPECT_THAT(NpyError(NpyBytes({2}, {1, 2}, "<i8")), HasSubstr("descr '<i8' is not supported"));
  EXPECT_THAT(NpyError(NpyBytes({2, 2}, {1, 2, 3, 4}, "<f8", true)),
              HasSubstr("fortran_order True is not supported"));
  const std::string ok = NpyBytes({4, 4}, std::vector<double>(16, 1.0));
  EXPECT_THAT(NpyError(ok.substr(0, ok.size() - 3)), HasSubstr("needs 128 data bytes"));
  std::string bad_header = ok;
  bad_header.replace(bad_header.find("'shape'"), 7, "'shope'");
  EXPECT_THAT(NpyError(bad_header), HasSubstr("unexpected key 'shope'"));
  std::string huge = NpyBytes({2}, {1, 2});
  huge.replace(huge.find("(2,)"), 4, "(99999999999,)");
  EXPECT_THAT(NpyError(huge), HasSubstr("header"));
}

TEST(NpzTest, ReadsStoredAndDeflatedMembers) {
  testing::TempDir tmp;
  for (bool compress : {false, true}) {
    const std::string path = tmp.Join(compress ? "c.npz" : "s.npz");
    testing::WriteZip(
        path,
        {{"a.npy", NpyBytes({2}, {1, 2})}, {"b.npy", NpyBytes({1}, {3})}, {"notes.txt", "ignored"}},
        compress);
    std::map<std::string, NpyArray> arrays;
    const Status status = ReadNpz(path, &arrays);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_EQ(arrays.size(), 2u);
    EXPECT_THAT(arrays["a"].values, ElementsAre(1, 2));
    EXPECT_THAT(arrays["b"].values, ElementsAre(3));
  }
}

TEST(NpzTest, ErrorsNameTheArchiveAndMember) {
  std::map<std::string, NpyArray> arrays;
  Status status = ParseNpz("not a zip at all", "cameras.npz", &arrays);
  EXPECT_THAT(status.message(), HasSubstr("cameras.npz: not a readable zip archive"));
  testing::TempDir tmp;
  testing::WriteZip(tmp.Join("x.npz"), {{"world_mat_0.npy", NpyBytes({2}, {1, 2}, ">f8")}});
  status = ReadNpz(tmp.Join("x.npz"), &arrays);
  EXPECT_THAT(status.message(), HasSubstr("x.npz: world_mat_0.npy: descr '>f8'"));
  status = ReadNpz(tmp.Join("missing.npz"), &arrays);
  EXPECT_THAT(status.message(), HasSubstr("missing.npz: file not found"));
}

// world_mat_i = [K [R|t]; 0 0 0 1] as IDR writes it.
std::string WorldMat(const Eigen::Matrix3d& k, const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
  p.topLeftCorner<3, 3>() = k * r;
  p.topRightCorner<3, 1>() = k * t;
  std::vector<double> values;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) values.push_back(p(i, j));
  }
  return NpyBytes({4, 4}, values);
}

std::map<std::string, NpyArray> Arrays(const std::map<std::string, std::string>& npy) {
  std::map<std::string, NpyArray> arrays;
  for (const auto& [name, bytes] : npy) EXPECT_TRUE(ParseNpy(bytes, name, &arrays[name]).ok());
  return arrays;
}

TEST(IdrCamerasTest, ConvertsWorldMatsAndTheSphere) {
  Eigen::Matrix3d k;
  k << 1000, 0, 400, 0, 1000, 300, 0, 0, 1;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d t(0.1, 0.2, 3);
  const auto arrays = Arrays(
      {{"world_mat_0", WorldMat(k, r, t)},
       {"world_mat_1", WorldMat(k, Eigen::Matrix3d::Identity(), t)},
       {"world_mat_inv_0", NpyBytes({2}, {0, 0})},
       {"scale_mat_0", NpyBytes({4, 4}, {2, 0, 0, 1, 0, 2, 0, -1, 0, 0, 2, 5, 0, 0, 0, 1})}});
  IdrCameras cameras;
  const Status status = IdrCamerasFromArrays(arrays, "cameras.npz", &cameras);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(cameras.views.size(), 2u);
  EXPECT_LT((cameras.views[0].rotation - r).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((cameras.views[0].translation - t).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((cameras.views[0].intrinsics - k).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_TRUE(cameras.has_sphere);
  EXPECT_EQ(cameras.sphere_radius, 2);
  EXPECT_EQ(cameras.sphere_centre, Eigen::Vector3d(1, -1, 5));
}

TEST(IdrCamerasTest, RejectsGapsShapesAndNonUniformScale) {
  const Eigen::Matrix3d k = Eigen::Vector3d(800, 800, 1).asDiagonal();
  const std::string good = WorldMat(k, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 2));
  auto error = [](const std::map<std::string, std::string>& npy) {
    IdrCameras cameras;
    const Status status = IdrCamerasFromArrays(Arrays(npy), "cameras.npz", &cameras);
    EXPECT_FALSE(status.ok());
    return status.message();
  };
  EXPECT_THAT(error({{"scale_mat_0", good}}), HasSubstr("cameras.npz: no world_mat_0"));
  EXPECT_THAT(error({{"world_mat_0", good}, {"world_mat_2", good}}),
              HasSubstr("world_mat_1 missing"));
  EXPECT_THAT(error({{"world_mat_0", NpyBytes({3, 3}, std::vector<double>(9, 1))}}),
              HasSubstr("world_mat_0: shape (3, 3), expected (4, 4) or (3, 4)"));
  EXPECT_THAT(error({{"world_mat_0", NpyBytes({4, 4}, std::vector<double>(16, 0))}}),
              HasSubstr("world_mat_0: the left 3x3 block of the projection matrix is singular"));
  EXPECT_THAT(
      error({{"world_mat_0", good},
             {"scale_mat_0", NpyBytes({4, 4}, {2, 0, 0, 0, 0, 3, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1})}}),
      HasSubstr("scale_mat_0: expected a uniform scale"));
  EXPECT_THAT(error({{"world_mat_x", good}}), HasSubstr("world_mat_x: expected world_mat_<index>"));
}

}  // namespace
}  // namespace sft
