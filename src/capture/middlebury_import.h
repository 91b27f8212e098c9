// `sft import middlebury`: a Middlebury multi-view stereo set (X_par.txt and its PNG images;
// src/io/middlebury_par.h) becomes an sft-dataset/1 through the calibrated import pipeline
// (calibrated_import.h). Entries whose image file is missing are skipped (the sets' _par.txt
// files list every view of the full hemisphere while a download may hold a subset); the report
// counts them for one warning line. Each image's camera is PINHOLE at the image's own size.
#ifndef SFT_CAPTURE_MIDDLEBURY_IMPORT_H_
#define SFT_CAPTURE_MIDDLEBURY_IMPORT_H_

#include <string>

#include "src/capture/calibrated_import.h"
#include "src/core/status.h"

namespace sft {

struct MiddleburyImportOptions {
  std::string par;     // the X_par.txt file.
  std::string images;  // folder the image names are relative to; "" = the par file's folder.
  CalibratedImportOptions import;  // output, masks, normalisation.

  bool Check(std::string* why) const;
};

struct MiddleburyImportReport {
  int entries = 0;            // entries in the par file.
  int missing_images = 0;     // entries skipped because their image file does not exist.
  std::string first_missing;  // the first of them (as written in the file).
  CalibratedImportReport import;
};

Status ImportMiddlebury(const MiddleburyImportOptions& options, MiddleburyImportReport* report);

}  // namespace sft

#endif  // SFT_CAPTURE_MIDDLEBURY_IMPORT_H_
