// File handling shared by the importers (`sft import colmap`, `video`, `nerf`, `idr`,
// `middlebury`; docs/import.md): decoding photographs as stored, storing them in the dataset
// (PNG and EXR byte for byte, other formats as lossless PNG), and building the output folder in
// OUT.partial/ so that a failed import leaves nothing behind.
#ifndef SFT_CAPTURE_IMPORT_FILES_H_
#define SFT_CAPTURE_IMPORT_FILES_H_

#include <functional>
#include <opencv2/core.hpp>
#include <string>

#include "src/core/file_util.h"
#include "src/core/status.h"

namespace sft {

// Decodes an image with OpenCV as stored (no EXIF rotation: calibrations describe the pixels as
// stored). Errors name the file ("file not found", "cannot decode image").
Status ReadImageAsStored(const std::string& path, int flags, cv::Mat* mat);

// Writes `mat` as PNG atomically.
Status WritePngMat(const std::string& path, const cv::Mat& mat);

// Stores image `source`, already decoded as stored (cv::IMREAD_UNCHANGED) into `mat`, as
// `root`/`out_name`: EXR and PNG are copied byte for byte, 8- and 16-bit images of other formats
// (JPEG, TIFF, ...) written as PNG of the same depth (lossless with respect to the decoded
// pixels). *encoding describes the source ("sRGB 8-bit JPEG converted to PNG", "linear EXR").
// Other depths (float TIFF, ...) are an error naming the file.
Status StoreImportedImage(const std::string& source, const cv::Mat& mat, const std::string& root,
                          const std::string& out_name, std::string* encoding);

// Reads the mask of image `name` (a path relative to the image folder) from folder `masks`:
// MASKS/NAME.png (COLMAP's convention, "a.jpg.png"), else MASKS/STEM.png ("a.png"); first channel,
// > 127 = object (docs/dataset.md). `binary` becomes 8-bit 0/255. Errors name the file: not found
// (naming both candidates), undecodable, or not `width` × `height`.
Status ReadMaskFile(const std::string& masks, const std::string& name, int width, int height,
                    cv::Mat* binary);

// `path` without its extension ("a/b.jpg" -> "a/b").
std::string WithoutExtension(const std::string& path);

// Builds the dataset folder `out`: refuses an `out` among `inputs` (CheckOutputDirectory, also for
// OUT.partial) and an existing non-empty `out` unless `overwrite`; then calls `fill` on a fresh
// OUT.partial/ and renames it to `out` when `fill` succeeds. On any failure OUT.partial/ is
// removed and `out` is untouched.
Status BuildDatasetFolder(const std::string& out, const RunInputs& inputs, bool overwrite,
                          const std::function<Status(const std::string& partial)>& fill);

}  // namespace sft

#endif  // SFT_CAPTURE_IMPORT_FILES_H_
