#include "src/init/poisson_grid.h"

#include <CGAL/Eigen_solver_traits.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Poisson_reconstruction_function.h>
#include <CGAL/property_map.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <string>
#include <utility>

namespace sft {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalPoint = Kernel::Point_3;
using CgalVector = Kernel::Vector_3;
using PointWithNormal = std::pair<CgalPoint, CgalVector>;
using PoissonFunction = CGAL::Poisson_reconstruction_function<Kernel>;
using Triangulation = PoissonFunction::Triangulation;
using CellHandle = Triangulation::Cell_handle;
using Solver = CGAL::Eigen_solver_traits<
    Eigen::ConjugateGradient<CGAL::Eigen_sparse_symmetric_matrix<double>::EigenType>>;

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Eigen::Vector3d ToEigen(const CgalPoint& p) { return Eigen::Vector3d(p.x(), p.y(), p.z()); }

// CGAL's f at p: linear interpolation in the tetrahedron containing p; outside the convex hull
// of the triangulation's vertices (an infinite cell) the value of one of the cell's finite
// vertices, as Poisson_reconstruction_function::operator() does. *hint is the cell to start the
// walk from and receives the cell found.
double EvaluateAt(const Triangulation& tr, const Eigen::Vector3d& p, CellHandle* hint) {
  const CgalPoint q(p.x(), p.y(), p.z());
  const CellHandle cell = tr.locate(q, *hint);
  *hint = cell;
  if (tr.is_infinite(cell)) {
    const int i = cell->index(tr.infinite_vertex());
    return cell->vertex((i + 1) & 3)->f();
  }
  const Eigen::Vector3d p3 = ToEigen(cell->vertex(3)->point());
  Eigen::Matrix3d edges;
  for (int c = 0; c < 3; ++c) edges.col(c) = ToEigen(cell->vertex(c)->point()) - p3;
  const Eigen::Vector3d w = edges.partialPivLu().solve(p - p3);
  if (!w.allFinite()) return cell->vertex(0)->f();  // flat tetrahedron: any corner's value.
  return w[0] * cell->vertex(0)->f() + w[1] * cell->vertex(1)->f() + w[2] * cell->vertex(2)->f() +
         (1.0 - w.sum()) * cell->vertex(3)->f();
}

// Error unless the samples spread at least half a voxel across their flattest direction.
Status CheckSpansVolume(const std::vector<OrientedPoint>& samples, double voxel) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const OrientedPoint& s : samples) mean += s.position;
  mean /= static_cast<double>(samples.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const OrientedPoint& s : samples) {
    const Eigen::Vector3d d = s.position - mean;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(samples.size());
  const double thinnest = std::sqrt(
      std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues()[0]));
  if (!(thinnest >= 0.5 * voxel)) {
    return Status::Error("the samples are flat (standard deviation " + std::to_string(thinnest) +
                         " across them, voxel " + std::to_string(voxel) +
                         "): they enclose no volume to reconstruct");
  }
  return Status::Ok();
}

// Median over (up to ~2000 of) the samples of f's central difference along the normal, step h.
double MedianSlope(const Triangulation& tr, const std::vector<OrientedPoint>& samples, double h) {
  const size_t stride = std::max<size_t>(1, samples.size() / 2000);
  std::vector<double> slopes;
  CellHandle hint;
  for (size_t n = 0; n < samples.size(); n += stride) {
    const Eigen::Vector3d offset = 0.5 * h * samples[n].normal;
    const double outside = EvaluateAt(tr, samples[n].position + offset, &hint);
    const double inside = EvaluateAt(tr, samples[n].position - offset, &hint);
    slopes.push_back((outside - inside) / h);
  }
  std::nth_element(slopes.begin(), slopes.begin() + slopes.size() / 2, slopes.end());
  return slopes[slopes.size() / 2];
}

// CGAL's function of the samples (the triangulation of the samples; not solved yet).
std::unique_ptr<PoissonFunction> MakePoissonFunction(const std::vector<OrientedPoint>& samples) {
  std::vector<PointWithNormal> points;
  points.reserve(samples.size());
  for (const OrientedPoint& s : samples) {
    points.emplace_back(CgalPoint(s.position.x(), s.position.y(), s.position.z()),
                        CgalVector(s.normal.x(), s.normal.y(), s.normal.z()));
  }
  return std::make_unique<PoissonFunction>(points.begin(), points.end(),
                                           CGAL::First_of_pair_property_map<PointWithNormal>(),
                                           CGAL::Second_of_pair_property_map<PointWithNormal>());
}

}  // namespace

Status EvaluatePoissonGrid(const std::vector<OrientedPoint>& samples, const VoxelBox& box,
                           double band, std::vector<float>* field, PoissonGridReport* report) {
  *report = PoissonGridReport();
  if (static_cast<int>(samples.size()) < kMinPoissonSamples) {
    return Status::Error(
        "too few samples for the Poisson reconstruction: " + std::to_string(samples.size()) +
        " (at least " + std::to_string(kMinPoissonSamples) + ")");
  }
  SFT_RETURN_IF_ERROR(CheckSpansVolume(samples, box.voxel_size));
  try {
    auto start = std::chrono::steady_clock::now();
    const std::unique_ptr<PoissonFunction> function = MakePoissonFunction(samples);
    const bool solved =
        function->compute_implicit_function(Solver(), /*smoother_hole_filling=*/false);
    report->solve_seconds = SecondsSince(start);
    if (!solved) return Status::Error("the Poisson solve (CGAL) failed");
    const Triangulation& tr = function->tr();
    report->triangulation_vertices = static_cast<int>(tr.number_of_vertices());

    start = std::chrono::steady_clock::now();
    report->slope = MedianSlope(tr, samples, box.voxel_size);
    if (!(report->slope > 0) || !std::isfinite(report->slope)) {
      return Status::Error(
          "the Poisson field does not increase along the sample normals (median "
          "slope " +
          std::to_string(report->slope) + ")");
    }
    const double scale = 1.0 / report->slope;
    const Eigen::Vector3i& dims = box.dims;
    field->assign(static_cast<size_t>(box.NumVoxels()), 0.f);
    tbb::parallel_for(0, dims.z(), [&](int k) {
      CellHandle hint;
      for (int j = 0; j < dims.y(); ++j) {
        for (int i = 0; i < dims.x(); ++i) {
          const double value = scale * EvaluateAt(tr, box.Centre(i, j, k), &hint);
          (*field)[(static_cast<size_t>(k) * dims.y() + j) * dims.x() + i] =
              static_cast<float>(std::clamp(value, -band, band));
        }
      }
    });
    report->evaluate_seconds = SecondsSince(start);
  } catch (const std::exception& e) {
    return Status::Error(std::string("the Poisson reconstruction (CGAL) failed: ") + e.what());
  }
  return Status::Ok();
}

}  // namespace sft
