// The grid of `sft sweep` (docs/cli.md, "sft sweep"): base options shared by every cell, and axes
// whose product is the list of cells. One JSON object:
//
//   {"dataset": "ds", "init": "start.ply", "reference": "ds/gt/mesh.ply",
//    "material": "{...}" | "m.json", "config": "cfg.json" | {...},
//    "time_budget": 60, "outer_iterations": 3,
//    "eval": {"spp": 64, "bounces": 2, "f1_tolerance": 0.005, "mesh_samples": 200000},
//    "axes": {"spp": [4, 16], "image_scale": [0.5, 1], "bounces": [1, 2, "auto"],
//             "effects": ["all", "auto"], "solver": ["lm", "adam"], "views": [8, 16],
//             "steps": [2, 5], "phases": ["texture", {"name": "geometry", "material": "m.json"}],
//             "variant": [{"name": "local", "config": {"bounces": 1}}]}}
//
// Relative paths are relative to the grid file's folder. Axis values of the reconstruct keys
// (spp, image_scale, bounces, effects, solver, steps, phases) are passed to the reconstruction's
// configuration as they are ("effects": "auto" runs the effect planner): a value it rejects
// (such as "bounces": "auto") makes that cell an error recorded in sweep.jsonl, and the sweep goes
// on. `views` counts evenly spaced view indices; a `variant` sets several keys under one name.
// A `variant` or `phases` value given as an object may also give its cells their own start:
// "init" (a mesh file, or "reference": the grid's reference mesh) and "material" (a file, inline
// JSON, "ground_truth": the dataset's ground_truth.material, or "grey": the default start), so
// that a texture cell can start from the true shape and a geometry cell hold the true material.
// Cells are the product of the axes in the order of kSweepAxes, the first outermost. A structural
// error (unknown key, an axis that is not a non-empty array, a duplicate value, a bad variant) is
// one line naming the field.
#ifndef SFT_SWEEP_SWEEP_GRID_H_
#define SFT_SWEEP_SWEEP_GRID_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

// The axes a grid may have, in enumeration order (the first outermost).
extern const char* const kSweepAxes[9];

// How each cell is scored (`sft eval`'s code: src/eval/reconstruction_eval.h, mesh_metrics.h).
struct SweepEvalOptions {
  int spp = 64;                 // samples per pixel of the re-renders, [1, 65536].
  int bounces = 2;              // path segments of the colour re-render, [1, 16].
  double f1_tolerance = 0.005;  // F1 distance, fraction of the reference's diagonal, (0, 1].
  int mesh_samples = 200000;    // surface samples per mesh for F1 and Chamfer, [100, 2e7].

  bool Check(std::string* why) const;
};

// One value of an axis.
struct SweepAxisValue {
  std::string label;      // for ids, tables and charts ("16", "lm", "local+shadows").
  nlohmann::json value;   // as given (a number or string; a variant's name).
  nlohmann::json config;  // the reconstruct keys it sets; views: {} (resolved per dataset).
  int views = 0;          // the views axis: how many evenly spaced views; 0 otherwise.
  // The start of the value's cells (variant and phases objects); "" = the grid's. init: a mesh
  // file (resolved) or "reference"; material: a file (resolved), inline JSON, "ground_truth" or
  // "grey".
  std::string init;
  std::string material;
};

struct SweepAxis {
  std::string name;  // one of kSweepAxes.
  std::vector<SweepAxisValue> values;
};

struct SweepGrid {
  std::string dataset;    // dataset folder (required).
  std::string init;       // start mesh; "" = the dataset's initial_mesh, else a carved hull.
  std::string material;   // initial material (file or inline JSON); "" = grey, roughness 0.5.
  std::string reference;  // reference mesh for Chamfer and F1; "" = no mesh scores.
  // Base reconstruct configuration (flat keys, "schedule", "stages"; docs/reconstruct.md).
  nlohmann::json config = nlohmann::json::object();
  // Wall-time budget of each cell's reconstruction, seconds, (0, 1e6]; 0 = none. With a budget
  // and no outer_iterations (here or in the flat config) the last stage gets 10000 outer
  // iterations, so the budget ends the cell; earlier stages keep their own.
  double time_budget = 0.0;
  int outer_iterations = 0;  // flat outer_iterations of every cell, [1, 10000]; 0 = the config's.
  SweepEvalOptions eval;
  std::vector<SweepAxis> axes;  // in kSweepAxes order; none = one cell.

  bool Check(std::string* why) const;
};

// One cell: the product of one value per axis.
struct SweepCell {
  int index = 0;
  std::string id;  // "03_lm_scale0.5_spp16": index, then each axis' value; a folder name.
  nlohmann::json settings = nlohmann::json::object();  // axis name -> value as given.
  nlohmann::json config = nlohmann::json::object();    // reconstruct keys of the axes (no views).
  int views = 0;  // evenly spaced views to fit; 0 = the config's (all by default).
  // The cell's own start from its axis values (SweepAxisValue::init, material); "" = the grid's.
  std::string init;
  std::string material;
};

// Parses a grid object; `source` names the file in errors, relative paths are resolved against
// `base_dir` (config files are read and inlined).
Status ParseSweepGrid(const nlohmann::json& grid, const std::string& source,
                      const std::string& base_dir, SweepGrid* out);
Status ReadSweepGrid(const std::string& path, SweepGrid* out);

// Command-line values that replace the grid's; empty or 0 keeps the grid's. Paths are relative
// to the working directory. `config` is a reconstruct config file whose keys apply under the
// grid's own config keys (the grid's win, so a preset keeps its definition).
struct SweepOverrides {
  std::string dataset, init, material, reference, config;
  double time_budget = 0.0;  // seconds, (0, 1e6].
  int outer_iterations = 0;  // [1, 10000].
  int eval_spp = 0;          // [1, 65536].
  int eval_bounces = 0;      // [1, 16].
};
// Errors name the flag ("--time-budget: ...").
Status ApplySweepOverrides(const SweepOverrides& overrides, SweepGrid* grid);

// The built-in grid `name` ("ablations": docs/cli.md), without dataset, start and reference.
Status PresetSweepGrid(const std::string& name, SweepGrid* out);

// The grid as JSON (paths as resolved, config inlined): DIR/grid.json, which a resumed sweep must
// match.
nlohmann::json SweepGridJson(const SweepGrid& grid);

// The cells in enumeration order. Ids are unique: the index leads, and an axis' values differ
// after IdSafe (ParseSweepGrid checks).
std::vector<SweepCell> EnumerateCells(const SweepGrid& grid);

// `count` evenly spaced indices of `total` views: floor(i · total / count), i = 0 … count − 1.
// Errors: count outside [1, total].
Status EvenlySpacedViews(int count, int total, std::vector<int>* views);

}  // namespace sft

#endif  // SFT_SWEEP_SWEEP_GRID_H_
