#include "src/eval/reference_score.h"

#include "src/eval/mesh_metrics.h"

namespace sft {

Status ScoreAgainstReference(const TriMesh& reference, double tolerance, const TriMesh& mesh,
                             const std::string& reference_name, nlohmann::json* out, int samples) {
  MeshMetricsOptions options;
  options.samples = samples;
  options.tolerance = tolerance;
  MeshMetrics m;
  SFT_RETURN_IF_ERROR(ComputeMeshMetrics(reference, mesh, options, &m, reference_name, "mesh"));
  *out = {{"chamfer", m.chamfer}, {"f1", m.f1}, {"f1_tolerance", tolerance}};
  return Status::Ok();
}

}  // namespace sft
