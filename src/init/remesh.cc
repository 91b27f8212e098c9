#include "src/init/remesh.h"

#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>

#include <OpenMesh/Tools/Subdivider/Uniform/LongestEdgeT.hh>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <vector>

#include "src/init/cgal_surface_mesh.h"
#include "src/init/surface_cleanup.h"

namespace sft {
namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

// Area of an equilateral triangle of unit edge: √3/4.
constexpr double kEquilateralArea = 0.43301270189221932;
constexpr int kMinFaces = 4;  // a tetrahedron.
constexpr int kMaxFacesLimit = 20000000;

DecimationGuards GuardsOf(const RemeshOptions& options) {
  DecimationGuards guards;
  guards.max_normal_deviation_degrees = options.max_normal_deviation_degrees;
  guards.max_aspect_ratio = options.max_aspect_ratio;
  return guards;
}

// CGAL isotropic remeshing of the whole surface; border edges (of an open input) are remeshed
// too but not flipped.
Status RemeshIsotropic(double edge_length, int iterations, SurfaceMesh* mesh) {
  try {
    PMP::isotropic_remeshing(faces(*mesh), edge_length, *mesh,
                             PMP::parameters::number_of_iterations(iterations));
    mesh->collect_garbage();
  } catch (const std::exception& e) {
    return Status::Error(std::string("CGAL isotropic_remeshing failed: ") + e.what());
  }
  return Status::Ok();
}

// Removes faces with collinear corners by edge flips and collapses (CGAL 5.5
// PMP::remove_degenerate_faces, present but not part of 5.5's documented API; the documented
// alternative is still experimental): their zero normals would make the decimation's
// normal-flipping guard refuse every collapse near them. Returns how many faces went.
Status RemoveDegenerateFaces(SurfaceMesh* mesh, int* removed) {
  const int before = static_cast<int>(mesh->number_of_faces());
  try {
    PMP::remove_degenerate_faces(*mesh);
    mesh->collect_garbage();
  } catch (const std::exception& e) {
    return Status::Error(std::string("CGAL remove_degenerate_faces failed: ") + e.what());
  }
  *removed = before - static_cast<int>(mesh->number_of_faces());
  return Status::Ok();
}

// Longest-edge bisection down to `max_edge_length`, then quadric decimation to `target_faces`.
void RemeshAdaptive(double max_edge_length, int target_faces, const RemeshOptions& options,
                    TriMesh* mesh, RemeshReport* report) {
  OpenMesh::Subdivider::Uniform::LongestEdgeT<TriMesh, double> bisection;
  bisection.set_max_edge_length(max_edge_length);
  bisection(*mesh, 1);  // splits until no edge is longer (the step count is not used).
  report->faces_subdivided = static_cast<int>(mesh->n_faces());
  DecimateMesh(target_faces, mesh, GuardsOf(options));
}

void FillEdgeStats(const TriMesh& mesh, RemeshReport* report) {
  double sum = 0.0, lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (TriMesh::EdgeHandle e : mesh.edges()) {
    const double length = mesh.calc_edge_length(e);
    sum += length;
    lo = std::min(lo, length);
    hi = std::max(hi, length);
  }
  const size_t n = mesh.n_edges();
  report->mean_edge_length_after = n > 0 ? sum / n : 0.0;
  report->min_edge_length_after = n > 0 ? lo : 0.0;
  report->max_edge_length_after = hi;
  report->faces_after = static_cast<int>(mesh.n_faces());
  report->vertices_after = static_cast<int>(mesh.n_vertices());
}

}  // namespace

const char* RemeshMethodName(RemeshMethod method) {
  switch (method) {
    case RemeshMethod::kAdaptive:
      return "adaptive";
    case RemeshMethod::kIsotropic:
      return "isotropic";
  }
  return "unknown";
}

bool RemeshMethodFromName(const std::string& name, RemeshMethod* method) {
  for (RemeshMethod m : {RemeshMethod::kAdaptive, RemeshMethod::kIsotropic}) {
    if (name == RemeshMethodName(m)) {
      *method = m;
      return true;
    }
  }
  return false;
}

bool RemeshOptions::Check(std::string* why) const {
  if (method != RemeshMethod::kAdaptive && method != RemeshMethod::kIsotropic) {
    *why = "method is not a RemeshMethod";
    return false;
  }
  if (!(target_edge_length > 0.0 && std::isfinite(target_edge_length))) {
    *why = "target_edge_length must be finite and > 0, got " + std::to_string(target_edge_length);
    return false;
  }
  if (max_faces < kMinFaces || max_faces > kMaxFacesLimit) {
    *why = "max_faces must be in [" + std::to_string(kMinFaces) + ", " +
           std::to_string(kMaxFacesLimit) + "], got " + std::to_string(max_faces);
    return false;
  }
  if (iterations < 1 || iterations > 100) {
    *why = "iterations must be in [1, 100], got " + std::to_string(iterations);
    return false;
  }
  if (!(subdivision_ratio >= 0.25 && subdivision_ratio <= 1.0)) {
    *why = "subdivision_ratio must be in [0.25, 1], got " + std::to_string(subdivision_ratio);
    return false;
  }
  return GuardsOf(*this).Check(why);
}

Status Remesh(const TriMesh& mesh, const RemeshOptions& options, TriMesh* out,
              RemeshReport* report) {
  const auto start = std::chrono::steady_clock::now();
  RemeshReport local_report;
  if (report == nullptr) report = &local_report;
  *report = RemeshReport();
  report->faces_before = static_cast<int>(mesh.n_faces());
  std::string why;
  if (!options.Check(&why)) return Status::Error("remesh options: " + why);
  if (out == &mesh) return Status::Error("remesh: the output may not alias the input");
  if (mesh.n_faces() == 0) return Status::Error("remesh: the mesh has no faces");

  SurfaceMesh surface;
  SoupRepairReport repair;
  SFT_RETURN_IF_ERROR(TriMeshToSurfaceMesh(mesh, &surface, &repair).Prefixed("remesh"));
  report->non_manifold_vertices_split = repair.duplicated_points;
  report->merged_vertices = repair.merged_points;
  report->dropped_faces = repair.degenerate_faces + repair.duplicate_faces;
  int degenerate = 0;
  SFT_RETURN_IF_ERROR(RemoveDegenerateFaces(&surface, &degenerate).Prefixed("remesh"));
  report->dropped_faces += degenerate;
  if (surface.number_of_faces() == 0) {
    return Status::Error("remesh: every face is degenerate (zero area)");
  }
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  SurfaceMeshToArrays(surface, &positions, &faces);
  const double area = SurfaceArea(positions, faces);
  if (!(area > 0.0 && std::isfinite(area))) {
    return Status::Error("remesh: the surface area is " + std::to_string(area));
  }
  // The used edge length: the target, or longer where the target would exceed max_faces.
  const double edge_length = std::max(options.target_edge_length,
                                      std::sqrt(area / (kEquilateralArea * options.max_faces)));
  report->edge_length_used = edge_length;
  const double implied_faces = area / (kEquilateralArea * edge_length * edge_length);
  report->target_faces =
      static_cast<int>(std::clamp(std::round(implied_faces), static_cast<double>(kMinFaces),
                                  static_cast<double>(options.max_faces)));

  if (options.method == RemeshMethod::kIsotropic) {
    SFT_RETURN_IF_ERROR(
        RemeshIsotropic(edge_length, options.iterations, &surface).Prefixed("remesh"));
    SurfaceMeshToArrays(surface, &positions, &faces);
    SFT_RETURN_IF_ERROR(ArraysToTriMesh(positions, faces, out).Prefixed("remesh (isotropic)"));
    // Rounding of the split/collapse thresholds can leave slightly more faces than the cap.
    DecimateMesh(options.max_faces, out, GuardsOf(options));
  } else {
    SFT_RETURN_IF_ERROR(ArraysToTriMesh(positions, faces, out).Prefixed("remesh (adaptive)"));
    RemeshAdaptive(options.subdivision_ratio * edge_length, report->target_faces, options, out,
                   report);
  }
  if (repair.closed && !IsClosedManifold(*out, &why)) {
    return Status::Error(std::string("remesh (") + RemeshMethodName(options.method) +
                         "): the input is closed but the output is not: " + why);
  }
  FillEdgeStats(*out, report);
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace sft
