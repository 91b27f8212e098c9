// One chart's parameterisation for the UV atlas: least-squares conformal maps (Lévy et al. 2002)
// through CGAL 5.5's Surface_mesh_parameterization (LSCM_parameterizer_3, its default two-vertex
// border pinning and sparse LDLT solver), checked for flipped and overlapping triangles
// (is_one_to_one_mapping, exact predicates); where LSCM overlaps, mean-value coordinates with a
// circular border (Mean_value_coordinates_parameterizer_3). The result is scaled so that the
// chart's UV area equals its surface area, and measured for stretch.
//
// Stretch is Sander et al. 2001's L2 stretch of the UV → surface map over the chart,
//   L2 = sqrt(Σ_t A_t·(Γ_t² + γ_t²)/2 / Σ_t A_t),
// with Γ_t, γ_t the singular values of triangle t's Jacobian and A_t its surface area, after the
// area normalisation above: 1 for an isometry, larger for any distortion of lengths or areas.
#ifndef SFT_ATLAS_CHART_PARAMETERIZATION_H_
#define SFT_ATLAS_CHART_PARAMETERIZATION_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/atlas/mesh_topology.h"

namespace sft {

struct ChartUv {
  std::vector<int> faces;           // the chart's faces (input).
  std::vector<Eigen::Vector2d> uv;  // 3 per face in face corner order; surface units.
  double stretch = 0.0;             // L2 stretch (see above); ≥ 1.
  double area = 0.0;                // surface area = UV area; scene units².
  bool valid = false;               // parameterised, no flipped or overlapping triangle.
  std::string method;               // "lscm" or "mean_value" (the fallback, see the .cc).
  std::string failure;              // why not valid.
};

// Parameterises chart->faces (a topological disk of non-degenerate faces, charts.h) and fills the
// rest of *chart. Never throws: a CGAL failure or exception makes the chart invalid.
void ParameterizeChart(const MeshTopology& topology, ChartUv* chart);

// Sander's L2 stretch of the triangles `faces` with corner UVs `uv` (3 per face), normalised by
// the ratio of total surface area to total UV area; 0 when empty. A flipped or zero-area UV
// triangle gives infinity.
double L2Stretch(const MeshTopology& topology, const std::vector<int>& faces,
                 const std::vector<Eigen::Vector2d>& uv);

}  // namespace sft

#endif  // SFT_ATLAS_CHART_PARAMETERIZATION_H_
