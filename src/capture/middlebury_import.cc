#include "src/capture/middlebury_import.h"

#include <filesystem>

#include "src/core/file_util.h"
#include "src/io/middlebury_par.h"

namespace sft {
namespace fs = std::filesystem;

bool MiddleburyImportOptions::Check(std::string* why) const {
  if (par.empty()) {
    *why = "--par: required";
    return false;
  }
  return import.Check(why);
}

Status ImportMiddlebury(const MiddleburyImportOptions& opts, MiddleburyImportReport* report) {
  *report = MiddleburyImportReport();
  std::string why;
  if (!opts.Check(&why)) return Status::Error(why);
  if (!FileExists(opts.par)) return Status::Error("--par: " + opts.par + ": file not found");
  const std::string folder =
      opts.images.empty() ? fs::path(opts.par).parent_path().string() : opts.images;
  std::error_code ec;
  if (!opts.images.empty() && !fs::is_directory(folder, ec)) {
    return Status::Error("--images: " + folder + ": folder not found");
  }
  std::string text;
  SFT_RETURN_IF_ERROR(ReadTextFile(opts.par, &text));
  std::vector<MiddleburyEntry> entries;
  SFT_RETURN_IF_ERROR(ParseMiddleburyPar(text, opts.par, &entries));
  report->entries = static_cast<int>(entries.size());
  std::vector<CalibratedView> views;
  for (const MiddleburyEntry& entry : entries) {
    const std::string image = JoinPath(folder.empty() ? "." : folder, entry.image);
    if (!FileExists(image)) {
      if (report->missing_images++ == 0) report->first_missing = entry.image;
      continue;
    }
    CalibratedView view;
    view.image = image;
    view.name = entry.image;
    const std::string par = opts.par;
    view.make_camera = [entry, par](int width, int height, Camera* camera) {
      return MiddleburyCamera(entry, par, width, height, camera);
    };
    SFT_RETURN_IF_ERROR(MiddleburyPose(entry, opts.par, &view.cam_from_world));
    views.push_back(std::move(view));
  }
  if (views.empty()) {
    return Status::Error(opts.par + ": none of the " + std::to_string(entries.size()) +
                         " images exists in " + (folder.empty() ? "." : folder) +
                         " (first: " + entries[0].image + ")");
  }
  CalibratedSource source;
  source.format = "middlebury";
  source.provenance = {{"par", opts.par},
                       {"entries", report->entries},
                       {"entries_without_image", report->missing_images}};
  source.inputs = {{folder.empty() ? "." : folder}, {opts.par}};
  return ImportCalibratedViews(views, source, opts.import, &report->import);
}

}  // namespace sft
