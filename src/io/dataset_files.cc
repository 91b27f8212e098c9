// Opening a dataset's files: the view images, masks and probes that scene.json names, checked
// against their cameras' sizes (src/io/dataset.h).
#include <glog/logging.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/dataset_internal.h"

namespace sft {
namespace {

using dataset_internal::IndexPath;
using dataset_internal::kSceneFile;
using dataset_internal::SizeText;

Status CheckSize(const std::string& path, const char* what, const Image& image,
                 const Camera& camera) {
  if (image.width != camera.width || image.height != camera.height) {
    return Status::Error(path + ": " + what + " is " + SizeText(image.width, image.height) +
                         " but camera \"" + camera.id + "\" is " +
                         SizeText(camera.width, camera.height));
  }
  return Status::Ok();
}

const Camera& ViewCamera(const Dataset& dataset, int index) {
  CHECK_GE(index, 0);
  CHECK_LT(index, static_cast<int>(dataset.views.size()));
  const int camera = dataset.views[index].camera;
  CHECK_GE(camera, 0) << "view " << index << " has no resolved camera";
  CHECK_LT(camera, static_cast<int>(dataset.cameras.size()));
  return dataset.cameras[camera];
}

Status CheckViewFiles(const Dataset& dataset, int index) {
  const ViewSpec& view = dataset.views[index];
  const Camera& camera = ViewCamera(dataset, index);
  Image image;
  const std::string image_path = JoinPath(dataset.root, view.image);
  SFT_RETURN_IF_ERROR(ReadImage(image_path, &image));
  SFT_RETURN_IF_ERROR(CheckSize(image_path, "image", image, camera));
  if (!view.mask.empty()) {
    const std::string mask_path = JoinPath(dataset.root, view.mask);
    Image mask;
    SFT_RETURN_IF_ERROR(ReadMask(mask_path, &mask));
    SFT_RETURN_IF_ERROR(CheckSize(mask_path, "mask", mask, camera));
  }
  return Status::Ok();
}

}  // namespace

Status CheckDatasetFiles(const Dataset& dataset) {
  const int num_views = static_cast<int>(dataset.views.size());
  std::vector<Status> statuses(num_views);
  // Photographs can be large: decode them in parallel, report the first failure in view order.
  tbb::parallel_for(0, num_views, [&](int i) { statuses[i] = CheckViewFiles(dataset, i); });
  for (const Status& status : statuses) SFT_RETURN_IF_ERROR(status);
  for (int l = 0; l < static_cast<int>(dataset.lights.size()); ++l) {
    if (dataset.lights[l].type != LightType::kEnvironment) continue;
    Image probe;
    SFT_RETURN_IF_ERROR(LoadProbe(dataset, l, &probe));
  }
  return Status::Ok();
}

Status LoadViewImage(const Dataset& dataset, int index, Image* rgb) {
  const Camera& camera = ViewCamera(dataset, index);
  const std::string path = JoinPath(dataset.root, dataset.views[index].image);
  Image image;
  SFT_RETURN_IF_ERROR(ReadImage(path, &image));
  SFT_RETURN_IF_ERROR(CheckSize(path, "image", image, camera));
  *rgb = ToRgb(image);
  return Status::Ok();
}

Status LoadViewMask(const Dataset& dataset, int index, Image* mask) {
  const Camera& camera = ViewCamera(dataset, index);
  const ViewSpec& view = dataset.views[index];
  if (view.mask.empty()) {
    return Status::Error(JoinPath(dataset.root, kSceneFile) + ": " + IndexPath("views", index) +
                         ".mask: view has no mask");
  }
  const std::string path = JoinPath(dataset.root, view.mask);
  Image result;
  SFT_RETURN_IF_ERROR(ReadMask(path, &result));
  SFT_RETURN_IF_ERROR(CheckSize(path, "mask", result, camera));
  *mask = std::move(result);
  return Status::Ok();
}

Status LoadProbe(const Dataset& dataset, int light_index, Image* rgb) {
  CHECK_GE(light_index, 0);
  CHECK_LT(light_index, static_cast<int>(dataset.lights.size()));
  const LightSpec& light = dataset.lights[light_index];
  CHECK(light.type == LightType::kEnvironment) << "light " << light.id << " is not a probe";
  if (!light.pixels.empty()) {
    *rgb = ToRgb(light.pixels);
    return Status::Ok();
  }
  const std::string path = JoinPath(dataset.root, light.image);
  Image image;
  SFT_RETURN_IF_ERROR(ReadImage(path, &image));
  Image result = ToRgb(image);
  // Negative texels (ringing from HDR resampling) and non-finite ones would break importance
  // sampling; they carry no usable radiance.
  for (float& v : result.data) {
    if (!(v > 0.0f) || !std::isfinite(v)) v = 0.0f;
  }
  *rgb = std::move(result);
  return Status::Ok();
}

Status GroundTruthPath(const Dataset& dataset, const std::string& key, std::string* relative) {
  relative->clear();
  if (!dataset.ground_truth.is_object() || !dataset.ground_truth.contains(key)) return Status::Ok();
  const nlohmann::json& value = dataset.ground_truth[key];
  if (!value.is_string()) return Status::Ok();
  std::string why;
  if (!IsContainedRelativePath(value.get<std::string>(), &why)) {
    return Status::Error(JoinPath(dataset.root, kSceneFile) + ": ground_truth." + key + ": " + why);
  }
  *relative = value.get<std::string>();
  return Status::Ok();
}

}  // namespace sft
