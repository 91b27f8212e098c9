// The 3D view of report.html (issue 21): the start mesh and the textured result side by side in
// WebGL, with orbit and zoom (the two views follow each other), a lighting switch, and the
// result's albedo and roughness maps.
//
// The viewer is three.js (Debian's libjs-three, r111): three.min.js, GLTFLoader and OrbitControls
// are copied into REPORT/report_files/three/, so the report folder stays self-contained and opens
// offline. The meshes are embedded in the page, not loaded from files, because Chromium refuses
// to load files over file://: the result as its export's model.glb (a base64 data string, parsed
// by GLTFLoader), the start mesh as base64 float32 positions and uint32 indices, in the GLB's
// frame (the export frame turned Y-up, src/export/export.h). When three.js is not installed the
// section says so and how to install it; the rest of the report is unaffected.
#ifndef SFT_EVAL_MODEL_VIEWER_H_
#define SFT_EVAL_MODEL_VIEWER_H_

#include <string>

#include "src/core/status.h"
#include "src/eval/report.h"
#include "src/io/dataset.h"

namespace sft {

// Where Debian's libjs-three installs three.js.
constexpr char kThreeJsDir[] = "/usr/share/javascript/three";

struct ModelViewerOptions {
  // An export folder (model.glb, model_albedo.png, model_roughness.png) inside the report's
  // folder; its path relative to the report folder, e.g. "export".
  std::string export_dir;
  // The start mesh (any format ReadMesh reads) in sft's world frame; "" = no start view.
  std::string start_mesh;
  // three.js's folder (three.min.js, examples/js/loaders/GLTFLoader.js,
  // examples/js/controls/OrbitControls.js).
  std::string three_dir = kThreeJsDir;
  // Canvas size of each of the two views, CSS pixels, [64, 4096].
  int width = 480;
  int height = 400;

  bool Check(std::string* why) const;
};

// Base64 (RFC 4648, with '=' padding) of `bytes`.
std::string Base64Encode(const std::string& bytes);

// Adds the section to `html` (whose folder holds options.export_dir) and copies three.js beside
// it. `dataset` gives the export frame (its source_from_world, as the export used). Errors: bad
// options; an unreadable model.glb or start mesh; a failed copy.
Status AddModelViewer(const ModelViewerOptions& options, const Dataset& dataset, HtmlReport* html);

}  // namespace sft

#endif  // SFT_EVAL_MODEL_VIEWER_H_
