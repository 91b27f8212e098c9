#include "tests/testing/light_finite_differences.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

#include "tests/testing/finite_differences.h"

namespace sft {
namespace testing {
namespace {

// The directional derivative image Σ_θ J_θ·δ_θ (RGB per pixel) from the rows, any kind.
std::vector<double> AllRowsTimes(const DerivativeOutput& out, const std::vector<double>& delta) {
  std::vector<double> image(3 * static_cast<size_t>(out.rows.width) * out.rows.height, 0.0);
  for (size_t p = 0; p + 1 < out.rows.offsets.size(); ++p) {
    for (uint64_t e = out.rows.offsets[p]; e < out.rows.offsets[p + 1]; ++e) {
      const JacobianEntry& entry = out.rows.entries[e];
      for (int k = 0; k < 3; ++k) image[3 * p + k] += entry.d[k] * delta[entry.param];
    }
  }
  return image;
}

}  // namespace

LightDerivativeCheck::LightDerivativeCheck(const RenderScene& scene, const Material& material,
                                           const RenderOptions& options,
                                           std::function<ViewSetup(const Eigen::Vector3d&)> view_at,
                                           const Eigen::Vector3d& x0, const Eigen::Vector3d& delta,
                                           double h, ParameterKind kind)
    : scene_(scene),
      material_(material),
      options_(options),
      view_at_(std::move(view_at)),
      x0_(x0),
      kind_(kind),
      layout_(MakeParameterLayout(scene, material, 1)) {
  layout_.light_positions = kind == ParameterKind::kLightPosition;
  layout_.light_directions = kind == ParameterKind::kLightDirection;
  layout_.environment_rotations = kind == ParameterKind::kEnvironmentRotation;
  const int offset = layout_.light_positions    ? layout_.LightPositionOffset()
                     : layout_.light_directions ? layout_.LightDirectionOffset()
                                                : layout_.EnvironmentRotationOffset();
  direction_.assign(layout_.size(), 0.0);
  for (int k = 0; k < 3; ++k) direction_[offset + k] = delta[k];
  Image plus, minus;
  RenderView(scene_, material_, view_at_(x0 + h * delta), options_, &plus);
  RenderView(scene_, material_, view_at_(x0 - h * delta), options_, &minus);
  width_ = plus.width;
  fd_.resize(3 * static_cast<size_t>(plus.width) * plus.height);
  for (size_t p = 0; p < fd_.size() / 3; ++p) {
    for (int k = 0; k < 3; ++k) {
      fd_[3 * p + k] =
          (static_cast<double>(plus.data[4 * p + k]) - minus.data[4 * p + k]) / (2.0 * h);
    }
  }
}

LightComparison LightDerivativeCheck::Compare(double shadow_edge_ratio,
                                              double secondary_edge_samples) const {
  Image weights(width_, width_, 3);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (float& w : weights.data) w = static_cast<float>(u(rng));
  DerivativeRequest request;
  request.params = ParameterSelection::Only(kind_);
  request.jacobian_rows = true;
  request.adjoint_weights = &weights;
  request.shadow_edge_ratio = shadow_edge_ratio;
  request.secondary_edge_samples = secondary_edge_samples;
  const ViewSetup view = view_at_(x0_);
  Image image, reference;
  DerivativeOutput out;
  RenderViewWithDerivatives(scene_, material_, view, options_, request, layout_, &image, &out);
  RenderView(scene_, material_, view, options_, &reference);
  LightComparison c;
  c.image_unchanged = image.data == reference.data;
  for (const JacobianEntry& entry : out.rows.entries) {
    c.rows_of_kind = c.rows_of_kind && layout_.KindOf(entry.param) == kind_;
  }
  const std::vector<double> analytic = AllRowsTimes(out, direction_);
  for (int i = 0; i < layout_.size(); ++i) c.adjoint += out.gradient[i] * direction_[i];
  for (size_t i = 0; i < analytic.size(); ++i) {
    c.weighted += weights.data[i] * analytic[i];
    c.weighted_abs += std::abs(weights.data[i] * analytic[i]);
  }
  c.pixel_error = RelativeError(analytic, fd_);
  c.block_error = RelativeError(BlockSums(analytic, width_, 8), BlockSums(fd_, width_, 8));
  c.fd_sum = Sum(fd_);
  c.sum_error = std::abs(Sum(analytic) - c.fd_sum) / std::abs(c.fd_sum);
  return c;
}

void LightDerivativeCheck::ExpectMatches(const char* name, double pixel_tolerance,
                                         double block_tolerance, double sum_tolerance, bool shadows,
                                         int bounces) const {
  const DerivativeRequest defaults;
  const LightComparison r = Compare(defaults.shadow_edge_ratio, defaults.secondary_edge_samples);
  EXPECT_TRUE(r.image_unchanged) << name << ": the derivative pass changed the image";
  EXPECT_TRUE(r.rows_of_kind) << name;
  std::printf("%s: pixel error %.2e, block error %.4f, sum error %.4f (fd sum %.5g)\n", name,
              r.pixel_error, r.block_error, r.sum_error, r.fd_sum);
  ASSERT_GT(std::abs(r.fd_sum), 0.0) << name << ": the perturbation does not change the image";
  if (pixel_tolerance > 0) {
    EXPECT_LT(r.pixel_error, pixel_tolerance) << name;
  }
  if (block_tolerance > 0) {
    EXPECT_LT(r.block_error, block_tolerance) << name;
  }
  if (sum_tolerance > 0) {
    EXPECT_LT(r.sum_error, sum_tolerance) << name;
  }
  EXPECT_NEAR(r.adjoint, r.weighted, 1e-5 * r.weighted_abs + 1e-12) << name;
  if (!shadows) return;
  for (const bool secondary : {false, true}) {
    if (secondary && bounces == 1) continue;
    const LightComparison without = secondary ? Compare(defaults.shadow_edge_ratio, 0.0)
                                              : Compare(0.0, defaults.secondary_edge_samples);
    std::printf("%s without %s: block error %.4f, sum error %.4f\n", name,
                secondary ? "secondary edges" : "shadow edges", without.block_error,
                without.sum_error);
    if (!secondary) {
      EXPECT_GT(without.block_error, 2.0 * r.block_error) << name;
    }
  }
}

}  // namespace testing
}  // namespace sft
