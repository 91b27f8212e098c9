// OUT/report.html of `sft sweep`: accuracy against wall time over the grid's cells. For each of
// Chamfer, F1 and the full, albedo and roughness PSNR (of the display images: clipped to [0, 1]
// and sRGB-encoded, `sft eval`'s psnr_srgb), every finished cell as a dot at its reconstruction's
// wall time, the Pareto front (src/sweep/pareto.h) as a line, and the default configuration (the
// cell that runs what the base configuration alone runs) as a ring. Then a table of every cell
// in the layout of the research report's Table 1: F1, then PSNR and SSIM of the full, diffuse
// (albedo) and roughness images, after the cell's settings, wall time and Chamfer.
#ifndef SFT_SWEEP_SWEEP_REPORT_H_
#define SFT_SWEEP_SWEEP_REPORT_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/sweep/sweep_grid.h"

namespace sft {

// One accuracy measure of a sweep line.
struct SweepMeasure {
  const char* name;       // "Chamfer", "full PSNR"...
  const char* pass;       // "" for mesh measures, else "full", "albedo" or "roughness".
  const char* key;        // "chamfer", "f1", "psnr_srgb".
  bool higher_is_better;  // F1 and PSNR; Chamfer is lower-better.
};
// The measures the report draws fronts for, in its order.
extern const SweepMeasure kSweepMeasures[5];

// The measure's value in a sweep line; NaN when absent (an error cell, no reference).
double SweepLineValue(const nlohmann::json& line, const SweepMeasure& measure);

// Writes out/report.html from the sweep's lines (cells not yet run are listed as such).
Status WriteSweepReport(const std::string& out, const SweepGrid& grid,
                        const std::vector<SweepCell>& cells,
                        const std::vector<nlohmann::json>& lines);

}  // namespace sft

#endif  // SFT_SWEEP_SWEEP_REPORT_H_
