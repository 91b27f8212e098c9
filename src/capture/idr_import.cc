#include "src/capture/idr_import.h"

#include <algorithm>
#include <filesystem>

#include "src/core/file_util.h"
#include "src/io/idr_cameras.h"
#include "src/io/npz.h"

namespace sft {
namespace {
namespace fs = std::filesystem;

// The image files directly in `folder`, sorted by name (byte order, as Python's sorted()).
Status ListImages(const std::string& folder, const std::string& flag,
                  std::vector<std::string>* names) {
  names->clear();
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    return Status::Error(flag + ": " + folder + ": folder not found");
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string ext = FileExtension(entry.path().string());
    const bool image = ext == "png" || ext == "jpg" || ext == "jpeg" || ext == "exr" ||
                       ext == "tif" || ext == "tiff";
    if (image && entry.is_regular_file(ec)) names->push_back(entry.path().filename().string());
  }
  if (ec) return Status::Error(flag + ": " + folder + ": cannot list (" + ec.message() + ")");
  std::sort(names->begin(), names->end());
  return Status::Ok();
}

}  // namespace

bool IdrImportOptions::Check(std::string* why) const {
  if (cameras.empty()) {
    *why = "--cameras: required";
    return false;
  }
  return import.Check(why);
}

Status ImportIdr(const IdrImportOptions& opts, IdrImportReport* report) {
  *report = IdrImportReport();
  std::string why;
  if (!opts.Check(&why)) return Status::Error(why);
  if (!FileExists(opts.cameras)) {
    return Status::Error("--cameras: " + opts.cameras + ": file not found");
  }
  const std::string folder =
      opts.images.empty() ? (fs::path(opts.cameras).parent_path() / "image").string() : opts.images;
  std::vector<std::string> images, masks;
  SFT_RETURN_IF_ERROR(ListImages(folder, "--images", &images));
  if (opts.import.HasMaskFolder()) {
    SFT_RETURN_IF_ERROR(ListImages(opts.import.masks, "--masks", &masks));
  }
  std::map<std::string, NpyArray> arrays;
  SFT_RETURN_IF_ERROR(ReadNpz(opts.cameras, &arrays));
  IdrCameras cameras;
  SFT_RETURN_IF_ERROR(IdrCamerasFromArrays(arrays, opts.cameras, &cameras));
  report->cameras = static_cast<int>(cameras.views.size());
  report->has_sphere = cameras.has_sphere;
  if (images.size() != cameras.views.size()) {
    return Status::Error(folder + ": " + std::to_string(images.size()) + " images, but " +
                         opts.cameras + " has " + std::to_string(cameras.views.size()) +
                         " cameras (world_mat_i belongs to the i-th image in sorted order)");
  }
  if (opts.import.HasMaskFolder() && masks.size() != images.size()) {
    return Status::Error(opts.import.masks + ": " + std::to_string(masks.size()) +
                         " masks, but there are " + std::to_string(images.size()) +
                         " images (paired in sorted order)");
  }
  std::vector<CalibratedView> views;
  for (size_t i = 0; i < images.size(); ++i) {
    const PinholeCalibration& calibration = cameras.views[i];
    const std::string where =
        opts.cameras + ": world_mat_" + std::to_string(i) + " (" + images[i] + ")";
    CalibratedView view;
    view.image = JoinPath(folder, images[i]);
    view.name = images[i];
    if (!masks.empty()) view.mask_file = JoinPath(opts.import.masks, masks[i]);
    const Eigen::Matrix3d k = calibration.intrinsics;
    view.make_camera = [k, where](int width, int height, Camera* camera) {
      std::string why;
      if (!CameraFromIntrinsics(k, width, height, 0.5, camera, &why)) {
        return Status::Error(where + ": K: " + why);
      }
      return Status::Ok();
    };
    if (!RotationFromMatrix(calibration.rotation, &view.cam_from_world.rotation, &why)) {
      return Status::Error(where + ": R: " + why);
    }
    view.cam_from_world.translation = calibration.translation;
    views.push_back(std::move(view));
  }
  CalibratedSource source;
  source.format = "idr";
  source.provenance = {{"cameras", opts.cameras}, {"images", folder}};
  source.inputs = {{folder}, {opts.cameras}};
  if (cameras.has_sphere)
    source.sphere = ObjectSphere{cameras.sphere_centre, cameras.sphere_radius};
  return ImportCalibratedViews(views, source, opts.import, &report->import);
}

}  // namespace sft
