#include "src/atlas/chart_parameterization.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Mean_value_coordinates_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <array>
#include <cmath>
#include <exception>
#include <limits>
#include <unordered_map>

namespace sft {
namespace {

// Exact predicates: the overlap test (is_one_to_one_mapping) meets touching and nearly collinear
// triangles, where inexact predicates report intersections that are not there.
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using ChartMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VertexIndex = ChartMesh::Vertex_index;
namespace SMP = CGAL::Surface_mesh_parameterization;
namespace PMP = CGAL::Polygon_mesh_processing;

double SignedArea(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a, ac = c - a;
  return 0.5 * (ab.x() * ac.y() - ab.y() * ac.x());
}

// Parameterises the chart (LSCM, else mean-value coordinates); false with *why on failure. uv gets
// 3 entries per face; *method names the parameterisation used.
bool RunLscm(const MeshTopology& t, const std::vector<int>& faces, std::vector<Eigen::Vector2d>* uv,
             std::string* method, std::string* why) {
  // Built from a soup (CGAL orders the faces itself; adding them one by one in an arbitrary order
  // can meet a temporarily pinched vertex).
  std::unordered_map<int, size_t> local;
  std::vector<Kernel::Point_3> points;
  std::vector<std::array<size_t, 3>> polygons(faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const int v = t.face(faces[i])[c];
      auto it = local.find(v);
      if (it == local.end()) {
        const Eigen::Vector3d& p = t.positions()[v];
        it = local.emplace(v, points.size()).first;
        points.emplace_back(p.x(), p.y(), p.z());
      }
      polygons[i][c] = it->second;
    }
  }
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    *why = "not a manifold disk";
    return false;
  }
  ChartMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  // Surface_mesh numbers the soup's points in order; checked, since the UVs are read back by it.
  if (mesh.number_of_vertices() != points.size() || mesh.number_of_faces() != faces.size()) {
    *why = "not a manifold disk";
    return false;
  }
  for (size_t k = 0; k < points.size(); ++k) {
    if (mesh.point(VertexIndex(static_cast<ChartMesh::size_type>(k))) != points[k]) {
      *why = "vertex order changed";
      return false;
    }
  }
  std::vector<ChartMesh::Halfedge_index> cycles;
  PMP::extract_boundary_cycles(mesh, std::back_inserter(cycles));
  if (cycles.size() != 1) {
    *why = std::to_string(cycles.size()) + " boundary loops";
    return false;
  }
  auto uvmap = mesh.add_property_map<VertexIndex, Kernel::Point_2>("v:uv").first;
  // LSCM first (free border, conformal). Where it overlaps itself — a boundary vertex whose faces
  // span more than 2π, as on saddles, cannot be laid out flat conformally — mean-value coordinates
  // with the border on a circle (arc-length spacing; bijective for a convex border, Floater 2003)
  // take over, at the cost of more stretch, which the caller measures.
  SMP::LSCM_parameterizer_3<ChartMesh> lscm;
  SMP::Error_code code = SMP::parameterize(mesh, lscm, cycles[0], uvmap);
  *method = "lscm";
  if (code != SMP::OK || !lscm.is_one_to_one_mapping(mesh, cycles[0], uvmap)) {
    SMP::Mean_value_coordinates_parameterizer_3<ChartMesh> mvc;
    code = SMP::parameterize(mesh, mvc, cycles[0], uvmap);
    *method = "mean_value";
    if (code != SMP::OK) {
      *why = std::string("mean-value coordinates: ") + SMP::get_error_message(code);
      return false;
    }
    if (!lscm.is_one_to_one_mapping(mesh, cycles[0],
                                    uvmap)) {  // the same test (MVC's is not const).

      *why = "overlapping triangles";
      return false;
    }
  }
  uv->resize(3 * faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const Kernel::Point_2& q =
          uvmap[VertexIndex(static_cast<ChartMesh::size_type>(polygons[i][c]))];
      (*uv)[3 * i + c] = Eigen::Vector2d(q.x(), q.y());
    }
  }
  return true;
}

}  // namespace

double L2Stretch(const MeshTopology& t, const std::vector<int>& faces,
                 const std::vector<Eigen::Vector2d>& uv) {
  double surface_area = 0.0, uv_area = 0.0, weighted = 0.0;
  for (size_t i = 0; i < faces.size(); ++i) {
    const Eigen::Vector3i& v = t.face(faces[i]);
    const Eigen::Vector3d& q1 = t.positions()[v[0]];
    const Eigen::Vector3d& q2 = t.positions()[v[1]];
    const Eigen::Vector3d& q3 = t.positions()[v[2]];
    const Eigen::Vector2d& p1 = uv[3 * i];
    const Eigen::Vector2d& p2 = uv[3 * i + 1];
    const Eigen::Vector2d& p3 = uv[3 * i + 2];
    const double a = SignedArea(p1, p2, p3);
    if (!(a > 0.0)) return std::numeric_limits<double>::infinity();
    // Partial derivatives of the surface point along u (s) and v (t), Sander et al. eq. (2).
    const Eigen::Vector3d ds =
        (q1 * (p2.y() - p3.y()) + q2 * (p3.y() - p1.y()) + q3 * (p1.y() - p2.y())) / (2.0 * a);
    const Eigen::Vector3d dt =
        (q1 * (p3.x() - p2.x()) + q2 * (p1.x() - p3.x()) + q3 * (p2.x() - p1.x())) / (2.0 * a);
    const double area = t.area(faces[i]);
    weighted += area * 0.5 * (ds.squaredNorm() + dt.squaredNorm());
    surface_area += area;
    uv_area += a;
  }
  if (surface_area <= 0.0) return 0.0;
  // Scaling UV by k divides the Jacobian by k; k² = surface_area / uv_area equalises the areas.
  return std::sqrt(weighted / surface_area * uv_area / surface_area);
}

void ParameterizeChart(const MeshTopology& t, ChartUv* chart) {
  chart->valid = false;
  chart->uv.clear();
  chart->area = 0.0;
  for (int f : chart->faces) chart->area += t.area(f);
  try {
    if (!RunLscm(t, chart->faces, &chart->uv, &chart->method, &chart->failure)) return;
  } catch (const std::exception& e) {
    chart->failure = std::string("CGAL: ") + e.what();
    return;
  }
  double uv_area = 0.0;
  for (size_t i = 0; i < chart->faces.size(); ++i) {
    uv_area += SignedArea(chart->uv[3 * i], chart->uv[3 * i + 1], chart->uv[3 * i + 2]);
  }
  // LSCM keeps the mesh's orientation up to a reflection of the whole chart; undo a reflection.
  if (uv_area < 0.0) {
    for (Eigen::Vector2d& p : chart->uv) p.x() = -p.x();
    uv_area = -uv_area;
  }
  if (!(uv_area > 0.0) || !std::isfinite(uv_area)) {
    chart->failure = "zero UV area";
    return;
  }
  const double scale = std::sqrt(chart->area / uv_area);
  for (Eigen::Vector2d& p : chart->uv) p *= scale;
  chart->stretch = L2Stretch(t, chart->faces, chart->uv);
  if (!std::isfinite(chart->stretch)) {
    chart->failure = "flipped or zero-area UV triangle";
    return;
  }
  chart->valid = true;
}

}  // namespace sft
