// `sft import nerf`: a NeRF transforms.json (original NeRF Blender scenes, instant-ngp, nerfstudio;
// src/io/nerf_transforms.h) and its images become an sft-dataset/1 through the calibrated import
// pipeline (calibrated_import.h). A frame's file_path is relative to the JSON file's folder; when
// it names no file, the extensions .png, .jpg, .jpeg, .exr are tried in turn (the Blender scenes
// write "./train/r_0"). A frame without an image is an error.
#ifndef SFT_CAPTURE_NERF_IMPORT_H_
#define SFT_CAPTURE_NERF_IMPORT_H_

#include <string>

#include "src/capture/calibrated_import.h"
#include "src/core/status.h"

namespace sft {

struct NerfImportOptions {
  std::string transforms;          // the transforms.json file.
  CalibratedImportOptions import;  // output, masks, normalisation.

  bool Check(std::string* why) const;
};

struct NerfImportReport {
  int frames = 0;  // frames in the JSON file.
  CalibratedImportReport import;
};

Status ImportNerf(const NerfImportOptions& options, NerfImportReport* report);

}  // namespace sft

#endif  // SFT_CAPTURE_NERF_IMPORT_H_
