#include "src/atlas/uv_atlas.h"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "src/atlas/atlas_packing.h"
#include "src/atlas/chart_parameterization.h"
#include "src/atlas/mesh_topology.h"

namespace sft {
namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The faces of each chart id in [first, end).
std::vector<std::vector<int>> FacesOfCharts(const std::vector<int>& chart_of_face,
                                            const std::vector<int>& faces, int first, int end) {
  std::vector<std::vector<int>> charts(end - first);
  for (int f : faces) {
    const int c = chart_of_face[f];
    if (c >= first && c < end) charts[c - first].push_back(f);
  }
  charts.erase(std::remove_if(charts.begin(), charts.end(),
                              [](const std::vector<int>& c) { return c.empty(); }),
               charts.end());
  return charts;
}

// A single triangle laid out with its true edge lengths (stretch 1).
void LayOutTriangle(const MeshTopology& t, ChartUv* chart) {
  const Eigen::Vector3i& v = t.face(chart->faces[0]);
  const Eigen::Vector3d e1 = t.positions()[v[1]] - t.positions()[v[0]];
  const Eigen::Vector3d e2 = t.positions()[v[2]] - t.positions()[v[0]];
  const Eigen::Vector3d d = e1.normalized();
  chart->uv = {Eigen::Vector2d::Zero(), Eigen::Vector2d(e1.norm(), 0.0),
               Eigen::Vector2d(e2.dot(d), e2.cross(d).norm())};
  chart->area = t.area(chart->faces[0]);
  chart->stretch = 1.0;
  chart->valid = true;
}

// Parameterises `pending` charts, splitting failures until every chart passes; passing charts are
// appended to `done`.
void ParameterizeAll(const MeshTopology& t, const UvAtlasOptions& options,
                     std::vector<std::vector<int>> pending, std::vector<int>* chart_of_face,
                     int* next_id, std::vector<ChartUv>* done, UvAtlasReport* report) {
  while (!pending.empty()) {
    std::vector<ChartUv> charts(pending.size());
    tbb::parallel_for(size_t{0}, pending.size(), [&](size_t i) {
      charts[i].faces = std::move(pending[i]);
      if (charts[i].faces.size() == 1) {
        LayOutTriangle(t, &charts[i]);
      } else {
        ParameterizeChart(t, &charts[i]);
      }
    });
    pending.clear();
    for (ChartUv& chart : charts) {
      if (chart.valid && chart.stretch <= options.max_stretch) {
        done->push_back(std::move(chart));
        continue;
      }
      ++report->splits;
      if (!chart.valid) ++report->failed_parameterizations;
      const int first = *next_id;
      SplitChart(t, chart.faces, options.charting, chart_of_face, next_id);
      for (std::vector<int>& piece : FacesOfCharts(*chart_of_face, chart.faces, first, *next_id)) {
        pending.push_back(std::move(piece));
      }
    }
  }
}

}  // namespace

bool UvAtlasOptions::Check(std::string* why) const {
  if (texture_size < 64 || texture_size > 16384) {
    *why = "texture_size: expected [64, 16384], got " + std::to_string(texture_size);
    return false;
  }
  if (gutter_texels < 1 || gutter_texels > 64) {
    *why = "gutter_texels: expected [1, 64], got " + std::to_string(gutter_texels);
    return false;
  }
  if (!(max_stretch >= 1.01 && max_stretch <= 100.0)) {
    *why = "max_stretch: expected [1.01, 100], got " + std::to_string(max_stretch);
    return false;
  }
  return charting.Check(why);
}

Status BuildUvAtlas(const std::vector<Eigen::Vector3d>& positions,
                    const std::vector<Eigen::Vector3i>& faces, const UvAtlasOptions& options,
                    UvAtlas* atlas, UvAtlasReport* report) {
  std::string why;
  if (!options.Check(&why)) return Status::Error("atlas options: " + why);
  const auto start = std::chrono::steady_clock::now();
  *report = UvAtlasReport();
  report->faces = static_cast<int>(faces.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int c = 0; c < 3; ++c) {
      if (faces[f][c] < 0 || faces[f][c] >= static_cast<int>(positions.size())) {
        return Status::Error("face " + std::to_string(f) + " has vertex index " +
                             std::to_string(faces[f][c]) + " out of range");
      }
    }
  }
  const MeshTopology topology(positions, faces);
  report->degenerate_faces = topology.num_degenerate_faces();
  report->nonmanifold_edges = topology.num_nonmanifold_edges();
  report->inconsistent_edges = topology.num_inconsistent_edges();
  if (topology.num_degenerate_faces() == topology.num_faces()) {
    return Status::Error("the mesh has no face with non-zero area");
  }
  std::vector<int> chart_of_face(faces.size(), -1);
  int next_id = 0;
  GrowCharts(topology, {}, options.charting, &chart_of_face, &next_id);
  std::vector<int> all_faces;
  for (int f = 0; f < topology.num_faces(); ++f) {
    if (!topology.degenerate(f)) all_faces.push_back(f);
  }
  report->chart_seconds = Seconds(start);

  const auto parameterize_start = std::chrono::steady_clock::now();
  std::vector<ChartUv> charts;
  ParameterizeAll(topology, options, FacesOfCharts(chart_of_face, all_faces, 0, next_id),
                  &chart_of_face, &next_id, &charts, report);
  report->parameterize_seconds = Seconds(parameterize_start);

  const auto pack_start = std::chrono::steady_clock::now();
  std::vector<ChartCorners> corners(charts.size());
  for (size_t c = 0; c < charts.size(); ++c) corners[c] = charts[c].uv;
  SFT_RETURN_IF_ERROR(
      PackCharts(options.texture_size, options.gutter_texels, &corners, &report->texels_per_unit));
  report->pack_seconds = Seconds(pack_start);

  atlas->texture_size = options.texture_size;
  atlas->num_charts = static_cast<int>(charts.size());
  // Degenerate faces: the centre of the top-left texel (in the gutter).
  const double corner = 0.5 / options.texture_size;
  atlas->corner_uv.assign(3 * faces.size(), Eigen::Vector2d(corner, 1.0 - corner));
  atlas->chart_of_face.assign(faces.size(), -1);
  double area = 0.0, weighted_stretch = 0.0;
  for (size_t c = 0; c < charts.size(); ++c) {
    for (size_t i = 0; i < charts[c].faces.size(); ++i) {
      const int f = charts[c].faces[i];
      atlas->chart_of_face[f] = static_cast<int>(c);
      for (int k = 0; k < 3; ++k) atlas->corner_uv[3 * f + k] = corners[c][3 * i + k];
    }
    area += charts[c].area;
    weighted_stretch += charts[c].area * charts[c].stretch;
    report->max_stretch = std::max(report->max_stretch, charts[c].stretch);
  }
  report->charts = atlas->num_charts;
  report->mean_stretch = area > 0.0 ? weighted_stretch / area : 0.0;
  const double s = report->texels_per_unit;
  report->utilization =
      area * s * s / (static_cast<double>(options.texture_size) * options.texture_size);
  report->seconds = Seconds(start);
  return Status::Ok();
}

}  // namespace sft
