// The import pipeline shared by the calibrated formats (`sft import nerf`, `idr`, `middlebury`;
// docs/import.md "Calibrated formats"): each format's importer lists its views (image file,
// camera, pose in the capture's frame); this writes the sft-dataset/1.
//
// Per view, in order: the image is decoded as stored, its camera made for its size (so views
// rotated in the image plane, or of different sizes, get their own cameras), the mask made
// (--masks: a folder, `threshold` or `alpha`; see pixel_masks.h), and the image stored (PNG and
// EXR copied, other formats as PNG; import_files.h) with the mask as masks/STEM.png. A view whose
// mask has no object pixel (the object is outside the frame or too dark) is left out, and the
// import says how many. Cameras with equal model, size and parameters are shared ("c0", "c1",
// ...). Then the object's box is found (object_box.h) and the world normalised as for `sft import
// colmap`: centred on the box, box diagonal 1, p_capture = d·p_world + c recorded as
// source_from_world. Lighting is unknown (every view's `lights` is empty).
//
// The fill ratio: the object's box extent along x, y and z of the normalised world, as a fraction
// of the working box, the cube [-0.5, 0.5]³ that holds every box of diagonal 1 at the origin. With
// masks the box is the masks' visual hull; without, an estimate (see object_box.h).
//
// Everything is written to OUT.partial and renamed at the end (BuildDatasetFolder).
#ifndef SFT_CAPTURE_CALIBRATED_IMPORT_H_
#define SFT_CAPTURE_CALIBRATED_IMPORT_H_

#include <Eigen/Core>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "src/capture/object_box.h"
#include "src/capture/pixel_masks.h"
#include "src/core/file_util.h"
#include "src/core/status.h"
#include "src/render/camera.h"

namespace sft {

// One view as a format's importer found it.
struct CalibratedView {
  std::string image;  // the image file to import.
  // Output name below images/ (relative, no ".."; its extension is replaced), and the name a mask
  // folder is searched for (ReadMaskFile).
  std::string name;
  std::string mask_file;  // with a mask folder: this file, when the format pairs masks itself.
  // The camera for an image of width × height pixels (`camera->id` is set later); errors name
  // the view.
  std::function<Status(int width, int height, Camera* camera)> make_camera;
  Rigid3d cam_from_world;  // in the capture's frame.
};

struct CalibratedImportOptions {
  std::string out;  // output dataset folder.
  // "" (no masks), "threshold", "alpha", or a folder of masks (NAME.png or STEM.png per image).
  std::string masks;
  ThresholdMaskOptions threshold;  // for --masks threshold.
  ObjectBoxOptions box;            // how the object is found.
  bool overwrite = false;          // replace an existing, non-empty output folder.
  bool quiet = false;              // no progress lines.

  bool Check(std::string* why) const;
  // A mask folder was given (not empty, "threshold" or "alpha").
  bool HasMaskFolder() const;
};

// What the format importer adds: provenance and what the pipeline may not write over.
struct CalibratedSource {
  std::string format;                  // "nerf", "idr", "middlebury" (scene.json's import.from).
  nlohmann::json provenance;           // more keys of scene.json's "import" object.
  RunInputs inputs;                    // the folders and files the import reads.
  std::optional<ObjectSphere> sphere;  // the format's bounding sphere, if any.
};

struct CalibratedImportReport {
  int views = 0;                 // views written.
  int cameras = 0;               // distinct cameras written.
  int empty_masks = 0;           // views left out because their mask was empty.
  std::string first_empty_mask;  // the first of them (image name).
  std::string masks;             // "none", "folder", "threshold" or "alpha".
  ObjectBox box;                 // in the capture's frame.
  double diagonal = 0;           // the box's diagonal, capture units (source_from_world scale).
  Eigen::Vector3d fill = Eigen::Vector3d::Zero();  // fill ratio along x, y, z (file comment).
  std::string image_encoding;                      // as written to scene.json.
  double seconds = 0;                              // wall time.
};

// Imports `views` into options.out. Errors name the file or view; nothing is left behind.
Status ImportCalibratedViews(const std::vector<CalibratedView>& views,
                             const CalibratedSource& source, const CalibratedImportOptions& options,
                             CalibratedImportReport* report);

}  // namespace sft

#endif  // SFT_CAPTURE_CALIBRATED_IMPORT_H_
