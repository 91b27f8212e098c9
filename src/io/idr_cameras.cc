#include "src/io/idr_cameras.h"

#include <cmath>

namespace sft {
namespace {

// The largest index i with world_mat_i in `arrays` (−1 when none), or −1 via *bad for a key
// world_mat_X whose X is not a plain index.
int64_t MaxWorldMatIndex(const std::map<std::string, NpyArray>& arrays, std::string* bad) {
  const std::string prefix = "world_mat_";
  int64_t max_index = -1;
  for (const auto& [key, array] : arrays) {
    if (key.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = key.substr(prefix.size());
    if (digits.compare(0, 3, "inv") == 0) continue;  // world_mat_inv_i: not needed.
    if (digits.empty() || digits.size() > 7 ||
        digits.find_first_not_of("0123456789") != std::string::npos) {
      *bad = key;
      return -1;
    }
    max_index = std::max<int64_t>(max_index, std::stoll(digits));
  }
  return max_index;
}

// The top 3×4 block of a (4, 4) or (3, 4) array; false for other shapes.
bool TopRows(const NpyArray& array, Eigen::Matrix<double, 3, 4>* p) {
  const bool shape_ok = array.shape.size() == 2 && array.shape[1] == 4 &&
                        (array.shape[0] == 4 || array.shape[0] == 3);
  if (!shape_ok) return false;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) (*p)(r, c) = array.values[4 * r + c];
  }
  return true;
}

Status SphereFromScaleMat(const NpyArray& array, const std::string& where, IdrCameras* cameras) {
  if (array.shape != std::vector<int64_t>{4, 4}) {
    return Status::Error(where + ": shape " + NpyShapeText(array.shape) + ", expected (4, 4)");
  }
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = array.values[4 * r + c];
  }
  const double s = m(0, 0);
  const Eigen::Matrix4d expected = [&] {
    Eigen::Matrix4d e = Eigen::Matrix4d::Identity() * s;
    e(3, 3) = 1;
    e.topRightCorner<3, 1>() = m.topRightCorner<3, 1>();
    return e;
  }();
  if (!m.allFinite() || !(s > 0) || !((m - expected).cwiseAbs().maxCoeff() <= 1e-9 * s)) {
    return Status::Error(where +
                         ": expected a uniform scale and a translation ([s*I c; 0 0 0 1], s > 0)");
  }
  cameras->has_sphere = true;
  cameras->sphere_centre = m.topRightCorner<3, 1>();
  cameras->sphere_radius = s;
  return Status::Ok();
}

}  // namespace

Status IdrCamerasFromArrays(const std::map<std::string, NpyArray>& arrays, const std::string& file,
                            IdrCameras* cameras) {
  *cameras = IdrCameras();
  std::string bad;
  const int64_t max_index = MaxWorldMatIndex(arrays, &bad);
  if (!bad.empty()) {
    return Status::Error(file + ": " + bad + ": expected world_mat_<index>");
  }
  if (max_index < 0) return Status::Error(file + ": no world_mat_0 (no cameras)");
  for (int64_t i = 0; i <= max_index; ++i) {
    const std::string key = "world_mat_" + std::to_string(i);
    const auto it = arrays.find(key);
    if (it == arrays.end()) {
      return Status::Error(file + ": " + key + " missing (world_mat_0 to world_mat_" +
                           std::to_string(max_index) + " must all be present)");
    }
    Eigen::Matrix<double, 3, 4> p;
    if (!TopRows(it->second, &p)) {
      return Status::Error(file + ": " + key + ": shape " + NpyShapeText(it->second.shape) +
                           ", expected (4, 4) or (3, 4)");
    }
    PinholeCalibration calibration;
    std::string why;
    if (!DecomposeProjectionMatrix(p, &calibration, &why)) {
      return Status::Error(file + ": " + key + ": " + why);
    }
    cameras->views.push_back(calibration);
  }
  const auto scale = arrays.find("scale_mat_0");
  if (scale != arrays.end()) {
    SFT_RETURN_IF_ERROR(SphereFromScaleMat(scale->second, file + ": scale_mat_0", cameras));
  }
  return Status::Ok();
}

}  // namespace sft
