// `sft import idr`: an IDR / NeuS dataset (cameras.npz and an image folder, as the DTU and
// BlendedMVS releases of those papers lay them out; src/io/idr_cameras.h) becomes an
// sft-dataset/1 through the calibrated import pipeline (calibrated_import.h). As in IDR's own
// loader, the i-th image of the folder in sorted order (png, jpg, jpeg, exr, tif) belongs to
// world_mat_i, and a mask folder pairs the same way (DTU's masks are named 000.png while the
// images are 000000.png). The counts must agree. K's pixel centres sit at integer coordinates
// (OpenCV's convention, as IDR casts rays), so cx, cy + 0.5 in sft's convention. Without masks,
// scale_mat_0's sphere is the object's bound.
#ifndef SFT_CAPTURE_IDR_IMPORT_H_
#define SFT_CAPTURE_IDR_IMPORT_H_

#include <string>

#include "src/capture/calibrated_import.h"
#include "src/core/status.h"

namespace sft {

struct IdrImportOptions {
  std::string cameras;  // the cameras.npz file.
  std::string images;   // image folder; "" = CAMERAS_FOLDER/image (IDR's layout).
  // import.masks: a folder is paired by sorted order (not by name), as IDR does.
  CalibratedImportOptions import;

  bool Check(std::string* why) const;
};

struct IdrImportReport {
  int cameras = 0;  // world_mat entries.
  bool has_sphere = false;
  CalibratedImportReport import;
};

Status ImportIdr(const IdrImportOptions& options, IdrImportReport* report);

}  // namespace sft

#endif  // SFT_CAPTURE_IDR_IMPORT_H_
