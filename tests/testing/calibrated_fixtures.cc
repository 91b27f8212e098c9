#include "tests/testing/calibrated_fixtures.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "tests/testing/npz_writer.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace testing {
namespace fs = std::filesystem;

namespace {

std::string Stem(const std::string& image) { return fs::path(image).stem().string(); }

// 90° clockwise in the image plane: new pixel (x', y') = old (y', h − 1 − x').
Image RotateClockwise(const Image& in) {
  Image out(in.height, in.width, in.channels);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      for (int c = 0; c < in.channels; ++c) out.at(x, y, c) = in.at(y, in.height - 1 - x, c);
    }
  }
  return out;
}

}  // namespace

Eigen::Matrix3d IntrinsicsOf(const Camera& camera, double offset) {
  EXPECT_EQ(camera.model, CameraModel::kPinhole);
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = camera.Focal().x();
  k(1, 1) = camera.Focal().y();
  k(0, 2) = camera.Principal().x() + offset;
  k(1, 2) = camera.Principal().y() + offset;
  return k;
}

std::string WriteNerfTransforms(const Dataset& dataset) {
  nlohmann::json frames = nlohmann::json::array();
  for (const ViewSpec& view : dataset.views) {
    const Camera& camera = dataset.cameras[view.camera];
    const Rigid3d world_from_cam = view.cam_from_world.Inverse();
    // sft's camera axes to OpenGL's (y up, looking down −z).
    const Eigen::Matrix3d r =
        world_from_cam.rotation.toRotationMatrix() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    nlohmann::json m = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) {
      m.push_back({r(i, 0), r(i, 1), r(i, 2), world_from_cam.translation[i]});
    }
    m.push_back({0, 0, 0, 1});
    frames.push_back({{"file_path", Stem(view.image)},
                      {"fl_x", camera.Focal().x()},
                      {"fl_y", camera.Focal().y()},
                      {"cx", camera.Principal().x()},
                      {"cy", camera.Principal().y()},
                      {"w", camera.width},
                      {"h", camera.height},
                      {"transform_matrix", m}});
  }
  const std::string path = JoinPath(dataset.root, "images/transforms.json");
  WriteTestFile(path, nlohmann::json({{"frames", frames}}).dump(1));
  return path;
}

std::string WriteMiddleburyPar(const Dataset& dataset, int rotated_view) {
  std::ostringstream par;
  par << std::setprecision(17) << dataset.views.size() + 1 << "\n";
  for (int v = 0; v < static_cast<int>(dataset.views.size()); ++v) {
    const ViewSpec& view = dataset.views[v];
    Camera camera = dataset.cameras[view.camera];
    Eigen::Matrix3d r = view.cam_from_world.rotation.toRotationMatrix();
    Eigen::Vector3d t = view.cam_from_world.translation;
    std::string name = fs::path(view.image).filename().string();
    if (v == rotated_view) {
      Image image;
      EXPECT_TRUE(ReadImage(JoinPath(dataset.root, view.image), &image).ok());
      EXPECT_TRUE(
          WriteExr(JoinPath(dataset.root, "images/rotated.exr"), RotateClockwise(image)).ok());
      name = "rotated.exr";
      // u' = h − v, v' = u: fx' = fy, fy' = fx, cx' = h − cy, cy' = cx; p' = (−y, x, z).
      Eigen::Matrix3d rz;
      rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
      r = rz * r;
      t = rz * t;
      const Eigen::Vector2d f = camera.Focal(), c = camera.Principal();
      camera.params = {f.y(), f.x(), camera.height - c.y(), c.x()};
      std::swap(camera.width, camera.height);
    }
    const Eigen::Matrix3d k = IntrinsicsOf(camera, -0.5);
    par << name;
    for (int i = 0; i < 9; ++i) par << " " << k(i / 3, i % 3);
    for (int i = 0; i < 9; ++i) par << " " << r(i / 3, i % 3);
    for (int i = 0; i < 3; ++i) par << " " << t[i];
    par << "\n";
  }
  par << "missing.png 100 0 32 0 100 32 0 0 1 1 0 0 0 1 0 0 0 1 0 0 3\n";
  const std::string path = JoinPath(dataset.root, "images/par.txt");
  WriteTestFile(path, par.str());
  return path;
}

std::string WriteIdrFolder(const Dataset& dataset, double sphere_radius) {
  const std::string root = JoinPath(dataset.root, "idr");
  fs::create_directories(root + "/image");
  fs::create_directories(root + "/mask");
  std::map<std::string, std::string> members;
  for (size_t v = 0; v < dataset.views.size(); ++v) {
    const ViewSpec& view = dataset.views[v];
    char name[32];
    std::snprintf(name, sizeof(name), "%03zu", v);
    fs::copy_file(JoinPath(dataset.root, view.image), root + "/image/a" + name + ".exr");
    fs::copy_file(JoinPath(dataset.root, view.mask), root + "/mask/m" + name + ".png");
    const Eigen::Matrix3d k = IntrinsicsOf(dataset.cameras[view.camera], -0.5);
    Eigen::Matrix4d p = Eigen::Matrix4d::Identity();
    p.topLeftCorner<3, 3>() = k * view.cam_from_world.rotation.toRotationMatrix();
    p.topRightCorner<3, 1>() = k * view.cam_from_world.translation;
    p.topRows<3>() *= (v % 2 == 0 ? 1.0 : -0.01 * (v + 1));
    std::vector<double> values;
    for (int i = 0; i < 16; ++i) values.push_back(p(i / 4, i % 4));
    members["world_mat_" + std::to_string(v) + ".npy"] = NpyBytes({4, 4}, values);
  }
  const double s = sphere_radius;
  members["scale_mat_0.npy"] = NpyBytes({4, 4}, {s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, 0, 0, 0, 1});
  WriteZip(root + "/cameras.npz", members);
  return root;
}

}  // namespace testing
}  // namespace sft
