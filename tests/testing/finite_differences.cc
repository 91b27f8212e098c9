#include "tests/testing/finite_differences.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "src/render/scene.h"

namespace sft {
namespace testing {

std::vector<double> RowsTimes(const DerivativeOutput& out, const std::vector<double>& delta) {
  const size_t pixels = static_cast<size_t>(out.rows.width) * out.rows.height;
  std::vector<double> image(3 * pixels, 0.0);
  for (size_t p = 0; p < pixels; ++p) {
    for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
      const JacobianEntry& entry = out.rows.entries[e];
      EXPECT_EQ(out.layout.KindOf(entry.param), ParameterKind::kVertex);
      for (int c = 0; c < 3; ++c) image[3 * p + c] += entry.d[c] * delta[entry.param];
    }
  }
  return image;
}

std::vector<double> CentralDifference(const Triangles& g, const std::vector<double>& delta,
                                      double h, const Material& material, const ViewSetup& view,
                                      const RenderOptions& options) {
  Image image[2];
  for (int s = 0; s < 2; ++s) {
    std::vector<Eigen::Vector3d> positions = g.positions;
    const double t = s == 0 ? h : -h;
    for (size_t v = 0; v < positions.size(); ++v) {
      for (int k = 0; k < 3; ++k) positions[v][k] += t * delta[3 * v + k];
    }
    const RenderScene scene(positions, g.faces);
    RenderView(scene, material, view, options, &image[s]);
  }
  std::vector<double> fd(3 * static_cast<size_t>(image[0].width) * image[0].height);
  for (size_t p = 0; p < fd.size() / 3; ++p) {
    for (int c = 0; c < 3; ++c) {
      fd[3 * p + c] =
          (static_cast<double>(image[0].data[4 * p + c]) - image[1].data[4 * p + c]) / (2 * h);
    }
  }
  return fd;
}

std::vector<double> BlockSums(const std::vector<double>& image, int res, int block) {
  const int nb = (res + block - 1) / block;
  std::vector<double> sums(3 * nb * nb, 0.0);
  for (int y = 0; y < res; ++y) {
    for (int x = 0; x < res; ++x) {
      for (int c = 0; c < 3; ++c) {
        sums[3 * ((y / block) * nb + x / block) + c] += image[3 * (y * res + x) + c];
      }
    }
  }
  return sums;
}

double RelativeError(const std::vector<double>& a, const std::vector<double>& ref) {
  double err2 = 0.0, ref2 = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    err2 += (a[i] - ref[i]) * (a[i] - ref[i]);
    ref2 += ref[i] * ref[i];
  }
  return ref2 > 0.0 ? std::sqrt(err2 / ref2) : (err2 > 0.0 ? 1.0 : 0.0);
}

double Sum(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s;
}

Comparison CompareWithFiniteDifferences(const Triangles& g, const std::vector<double>& delta,
                                        double h, const Material& material, const ViewSetup& view,
                                        RenderOptions options, const char* name, int nodes) {
  options.sampling_material = &material;
  const int res = view.camera.width;
  Image weights(res, res, 3);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (float& w : weights.data) w = static_cast<float>(u(rng));
  DerivativeRequest request;
  request.params = ParameterSelection::Only(ParameterKind::kVertex);
  request.jacobian_rows = true;
  request.adjoint_weights = &weights;
  Comparison result;
  std::vector<double> analytic(3 * static_cast<size_t>(res) * res, 0.0);
  for (int j = 0; j < nodes; ++j) {
    RenderOptions node_options = options;
    std::vector<Eigen::Vector3d> positions = g.positions;
    if (nodes > 1) {
      node_options.spp = std::max(1, options.spp / nodes);
      node_options.seed = options.seed + 1 + j;
      const double t = -h + (j + 0.5) * 2.0 * h / nodes;
      for (size_t v = 0; v < positions.size(); ++v) {
        for (int k = 0; k < 3; ++k) positions[v][k] += t * delta[3 * v + k];
      }
    }
    const RenderScene scene(positions, g.faces);
    Image image;
    DerivativeOutput out;
    RenderViewWithDerivatives(scene, material, view, node_options, request, 1, &image, &out);
    const std::vector<double> node = RowsTimes(out, delta);
    double adjoint = 0.0, weighted = 0.0, weighted_abs = 0.0;
    for (size_t i = 0; i < out.gradient.size(); ++i) {
      result.finite &= std::isfinite(out.gradient[i]);
      if (i < delta.size()) adjoint += out.gradient[i] * delta[i];
    }
    for (size_t i = 0; i < node.size(); ++i) {
      result.finite &= std::isfinite(node[i]);
      weighted += weights.data[i] * node[i];
      weighted_abs += std::abs(weights.data[i] * node[i]);
      analytic[i] += node[i] / nodes;
    }
    result.adjoint_mismatch =
        std::max(result.adjoint_mismatch,
                 weighted_abs > 0.0 ? std::abs(adjoint - weighted) / weighted_abs : 0.0);
  }
  const std::vector<double> fd = CentralDifference(g, delta, h, material, view, options);
  result.block_error = RelativeError(BlockSums(analytic, res, 8), BlockSums(fd, res, 8));
  const double fd_sum = Sum(fd);
  result.sum_error = std::abs(Sum(analytic) - fd_sum) / std::max(std::abs(fd_sum), 1e-300);
  std::printf(
      "%s: block error %.4f, pixel error %.4f, sum error %.4f (fd sum %.5g), adjoint "
      "mismatch %.1e\n",
      name, result.block_error, RelativeError(analytic, fd), result.sum_error, fd_sum,
      result.adjoint_mismatch);
  return result;
}

}  // namespace testing
}  // namespace sft
