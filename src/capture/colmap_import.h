// `sft import colmap`: a COLMAP sparse model (text or binary) and its images become an
// sft-dataset/1 (docs/dataset.md) with the optional import keys of docs/import.md
// (source_from_world, sparse_points, initial_mesh, dense_points, image_encoding, lighting).
//
// Decisions (docs/import.md): only registered images become views, in COLMAP image-id order; each
// COLMAP camera used by them becomes a camera "c<ID>" (models SIMPLE_PINHOLE, PINHOLE,
// SIMPLE_RADIAL, RADIAL, OPENCV; any other is an error). PNG and EXR images are copied byte for
// byte; other formats (JPEG, TIFF, ...) are decoded with OpenCV and written as PNG at their bit
// depth (8 or 16), which is lossless with respect to the decoded pixels. The scene is normalised
// like `sft synth`'s (import_normalization.h) and the similarity recorded as source_from_world.
// Everything is written to OUT.partial and renamed to OUT at the end; a failure removes
// OUT.partial.
#ifndef SFT_CAPTURE_COLMAP_IMPORT_H_
#define SFT_CAPTURE_COLMAP_IMPORT_H_

#include <string>

#include "src/capture/auto_masks.h"
#include "src/capture/import_normalization.h"
#include "src/capture/probe_alignment.h"
#include "src/core/status.h"

namespace sft {

struct ColmapImportOptions {
  std::string model;   // COLMAP sparse model folder (cameras/images/points3D .bin or .txt).
  std::string images;  // folder the model's image names are relative to.
  // optional mask folder: NAME.png (COLMAP's convention) or STEM.png; "auto" segments the
  // object in every view (auto_masks.h) after the normalisation.
  std::string masks;
  std::string probe;        // optional equirectangular probe: .exr/.hdr (linear) or 8-bit (sRGB).
  std::string out;          // output dataset folder.
  bool align_probe = true;  // align the probe (probe_alignment.h); else identity.
  ProbeAlignmentOptions alignment;     // how the probe is aligned.
  AutoMaskOptions auto_masks;          // how --masks auto segments.
  NormalizationOptions normalization;  // how the object is found among the sparse points.
  bool import_dense = true;            // import fused.ply / meshed-*.ply found beside the model.
  bool overwrite = false;              // replace an existing, non-empty output folder.
  bool quiet = false;                  // no progress line.

  bool Check(std::string* why) const;
  // A mask folder was given (not empty and not "auto").
  bool HasMaskFolder() const { return !masks.empty() && masks != "auto"; }
};

// What the import did, for the command's summary and for tests.
struct ColmapImportReport {
  std::string format;  // "binary" or "text".
  int cameras = 0;     // cameras written.
  int views = 0;       // registered images imported.
  NormalizationResult normalization;
  std::string dense_mesh;    // source file imported as init/mesh.ply, or "".
  std::string dense_points;  // source file imported as init/fused.ply, or "".
  int auto_masks = 0;        // masks made by --masks auto.
  bool probe_aligned = false;
  ProbeAlignmentResult alignment;  // when probe_aligned.
  // --probe-ground (SupportPlaneOptions::hides_probe): whether it was asked for with a probe, and
  // whether a support plane was found to hide the probe's lower part.
  bool probe_ground_requested = false;
  bool probe_ground = false;
  // The support disc's radius in the normalised world (object-box diagonals); 0 = an infinite
  // floor (no point on the plane to measure it by).
  double probe_ground_radius = 0;
  double seconds = 0;  // wall time.
};

Status ImportColmap(const ColmapImportOptions& options, ColmapImportReport* report);

}  // namespace sft

#endif  // SFT_CAPTURE_COLMAP_IMPORT_H_
