#include "src/capture/nerf_import.h"

#include <filesystem>

#include "src/core/file_util.h"
#include "src/io/nerf_transforms.h"

namespace sft {
namespace {
namespace fs = std::filesystem;

// The image file of `file_path` (relative to `folder`): as written, else with an image extension
// appended (returned in *appended). Empty when there is none.
std::string FindImage(const std::string& folder, const std::string& file_path,
                      std::string* appended) {
  const std::string path = JoinPath(folder, file_path);
  std::error_code ec;
  appended->clear();
  if (fs::is_regular_file(path, ec)) return path;
  for (const char* ext : {".png", ".jpg", ".jpeg", ".exr", ".PNG", ".JPG", ".JPEG"}) {
    *appended = ext;
    if (fs::is_regular_file(path + ext, ec)) return path + ext;
  }
  return "";
}

}  // namespace

bool NerfImportOptions::Check(std::string* why) const {
  if (transforms.empty()) {
    *why = "--transforms: required";
    return false;
  }
  return import.Check(why);
}

Status ImportNerf(const NerfImportOptions& opts, NerfImportReport* report) {
  *report = NerfImportReport();
  std::string why;
  if (!opts.Check(&why)) return Status::Error(why);
  if (!FileExists(opts.transforms)) {
    return Status::Error("--transforms: " + opts.transforms + ": file not found");
  }
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(opts.transforms, &text));
  std::vector<NerfFrame> frames;
  SFT_RETURN_IF_ERROR(ParseNerfTransforms(text, opts.transforms, &frames));
  report->frames = static_cast<int>(frames.size());
  std::string folder = fs::path(opts.transforms).parent_path().string();
  if (folder.empty()) folder = ".";
  std::vector<CalibratedView> views;
  for (size_t i = 0; i < frames.size(); ++i) {
    const NerfFrame& frame = frames[i];
    const std::string where = opts.transforms + ": frames[" + std::to_string(i) + "]";
    CalibratedView view;
    std::string appended;
    view.image = FindImage(folder, frame.file_path, &appended);
    if (view.image.empty()) {
      return Status::Error(where + ".file_path: " + JoinPath(folder, frame.file_path) +
                           ": no image file (also tried .png, .jpg, .jpeg, .exr)");
    }
    // The output name keeps the path below the JSON's folder ("./train/r_0" -> train/r_0.png).
    view.name = fs::path(frame.file_path).lexically_normal().generic_string() + appended;
    const NerfIntrinsics intrinsics = frame.intrinsics;
    view.make_camera = [intrinsics, where](int width, int height, Camera* camera) {
      return NerfCamera(intrinsics, width, height, where, camera);
    };
    view.cam_from_world = frame.cam_from_world;
    views.push_back(std::move(view));
  }
  CalibratedSource source;
  source.format = "nerf";
  source.provenance = {{"transforms", opts.transforms}, {"frames", report->frames}};
  source.inputs = {{folder}, {opts.transforms}};
  return ImportCalibratedViews(views, source, opts.import, &report->import);
}

}  // namespace sft
