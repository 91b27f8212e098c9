// OUT/report.html of `sft reconstruct`: the run's summary, the cost and mean-PSNR curves against
// wall time, F1 and Chamfer against wall time (when the outer records carry them: --reference),
// the stages with the mesh's normals after each, and target | render | |difference| for up to
// four views at the final state, the fitted lighting when the dataset's was unknown
// (lighting_report.h), the 3D view of the textured result (model_viewer.h), the held-out
// views, and up to two views relit by the studio lights (src/eval/studio_lights.h).
#ifndef SFT_EVAL_RECONSTRUCT_REPORT_H_
#define SFT_EVAL_RECONSTRUCT_REPORT_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/eval/model_viewer.h"
#include "src/io/dataset.h"
#include "src/optim/reconstruct.h"

namespace sft {

// The 3D view's inputs: `viewer.export_dir` empty = no 3D view, and `missing` says why.
struct ReportModel {
  ModelViewerOptions viewer;
  std::string missing;
};

Status WriteReconstructReport(const std::string& out, const Dataset& dataset,
                              const std::vector<IterationRecord>& records,
                              Reconstruction* reconstruction,
                              const nlohmann::json& outer_records = nlohmann::json::array(),
                              const nlohmann::json& stage_records = nlohmann::json::array(),
                              const ReportModel& model = ReportModel());

}  // namespace sft

#endif  // SFT_EVAL_RECONSTRUCT_REPORT_H_
