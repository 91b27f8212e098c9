// The report's "Fitted lighting" section (OUT/report.html of a run whose lighting was unknown):
// the fitted environment map as an image (equirectangular, at its fitted scale, its own
// exposure), and one line per light the run estimated beside it (--estimate-lights,
// --find-lamp): where it started and where the fit put it, and its intensity. Nothing for a run
// whose dataset lists its lights.
#ifndef SFT_EVAL_LIGHTING_REPORT_H_
#define SFT_EVAL_LIGHTING_REPORT_H_

#include <string>

#include "src/core/status.h"
#include "src/eval/report.h"
#include "src/io/dataset.h"

namespace sft {

// Adds the section for run folder `out` to `html`: `dataset` is the run's, with its estimated
// lights and its fitted environment (PrepareUnknownLighting); the fitted values come from
// OUT/lights.json and OUT/environment.exr, the starts from OUT/estimated_lights.json. Writes
// report_files/environment.png. Errors name the file.
Status AddFittedLighting(const std::string& out, const Dataset& dataset, HtmlReport* html);

}  // namespace sft

#endif  // SFT_EVAL_LIGHTING_REPORT_H_
