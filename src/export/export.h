// `sft export`: a reconstruction's mesh and mesh-colors material as files other programs open
// (docs/export.md): OBJ + MTL + PNG textures, glTF 2.0 binary, PLY with vertex colours.
//
// Reads REC/mesh.ply and REC/material.json (+ its .meshcolors files; after a uv stage its PNG
// textures and mesh.obj's UVs, written as they are instead of re-baked), and the dataset —
// --dataset, else the one REC/state.json names — for its source frame and cameras; writes only into
// the output folder (fixed names, export_formats.h), each file atomically, plus export.json (what
// was written and the atlas's numbers).
//
// Frames. Positions are exported in the dataset's source frame (p_source = s·R·p + t,
// "source_from_world" of imported captures) when the dataset records one, else in sft's world
// frame; units are that frame's. glTF, which is Y-up by definition, additionally gets the frame
// turned so that its +Z becomes +Y: (x, y, z) ↦ (x, z, −y).
//
// Texture size: --texture-size when given; else from the dataset's finest pixel footprint (see
// TextureSizeFromFootprint, src/atlas/texture_size.h); else 1024.
#ifndef SFT_EXPORT_EXPORT_H_
#define SFT_EXPORT_EXPORT_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/atlas/uv_atlas.h"
#include "src/core/status.h"
#include "src/geometry/mesh.h"
#include "src/io/dataset.h"

namespace sft {

struct ExportOptions {
  std::string reconstruction;  // `sft reconstruct`'s output folder (read only).
  std::string out;             // output folder (created; nothing is written elsewhere).
  std::string dataset;         // the dataset; "" = the one REC/state.json names, if readable.
  std::string format = "all";  // obj, gltf, ply or all.
  int texture_size = 0;        // atlas side in texels, [64, 16384]; 0 = automatic (above).
  UvAtlasOptions atlas;        // gutters, stretch bound, charting (texture_size is set from above).

  bool Check(std::string* why) const;
};

// Runs the export; *summary is what export.json holds. Warnings (e.g. the dataset named by
// state.json cannot be read, so the world frame is used) are listed in summary["warnings"].
Status ExportReconstruction(const ExportOptions& options, nlohmann::json* summary);

// The folder inside a run's output where `sft reconstruct` writes its asset at the end.
constexpr char kRunExportDir[] = "export";

// What a finished `sft reconstruct` writes into RUN/export/ (kRunExportDir): the same files as
// `sft export --reconstruction RUN --format all` with the run's `dataset` and the automatic
// texture size. The caller has checked RUN as an output folder (this writes below it only).
Status ExportFinishedRun(const std::string& run, const Dataset& dataset, nlohmann::json* summary);

}  // namespace sft

#endif  // SFT_EXPORT_EXPORT_H_
