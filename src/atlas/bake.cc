#include "src/atlas/bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace sft {
namespace {

// Barycentric weights of q in triangle (a, b, c); the triangle must have non-zero area.
Eigen::Vector3d Barycentric(const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a, ac = c - a, aq = q - a;
  const double det = ab.x() * ac.y() - ab.y() * ac.x();
  const double wb = (aq.x() * ac.y() - aq.y() * ac.x()) / det;
  const double wc = (ab.x() * aq.y() - ab.y() * aq.x()) / det;
  return Eigen::Vector3d(1.0 - wb - wc, wb, wc);
}

// The closest point of triangle p[0..2] to q as barycentric weights; *distance its distance.
Eigen::Vector3d ClosestPoint(const Eigen::Vector2d& q, const Eigen::Vector2d* p, double* distance) {
  const Eigen::Vector3d w = Barycentric(q, p[0], p[1], p[2]);
  if (w.minCoeff() >= 0.0) {
    *distance = 0.0;
    return w;
  }
  Eigen::Vector3d best = w;
  *distance = std::numeric_limits<double>::infinity();
  for (int e = 0; e < 3; ++e) {
    const Eigen::Vector2d& a = p[e];
    const Eigen::Vector2d& b = p[(e + 1) % 3];
    const Eigen::Vector2d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double s = len2 > 0.0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const double d = (a + s * ab - q).norm();
    if (d < *distance) {
      *distance = d;
      best = Eigen::Vector3d::Zero();
      best[e] = 1.0 - s;
      best[(e + 1) % 3] = s;
    }
  }
  return best;
}

// Fills every texel with mask 0 ring by ring from the filled ones; returns the number of rings.
int Dilate(std::vector<unsigned char>* filled, Image* albedo, Image* roughness, int* dilated) {
  const int n = albedo->width;
  std::vector<int> frontier;
  auto empty_next_to_filled = [&](int x, int y) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx, yy = y + dy;
        if (xx >= 0 && yy >= 0 && xx < n && yy < n && (*filled)[yy * n + xx]) return true;
      }
    }
    return false;
  };
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      if (!(*filled)[y * n + x] && empty_next_to_filled(x, y)) frontier.push_back(y * n + x);
    }
  }
  int rings = 0;
  std::vector<float> values;
  while (!frontier.empty()) {
    ++rings;
    values.assign(4 * frontier.size(), 0.0f);
    for (size_t i = 0; i < frontier.size(); ++i) {
      const int x = frontier[i] % n, y = frontier[i] / n;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= n || yy >= n || !(*filled)[yy * n + xx]) continue;
          for (int c = 0; c < 3; ++c) values[4 * i + c] += albedo->at(xx, yy, c);
          values[4 * i + 3] += roughness->at(xx, yy);
          ++count;
        }
      }
      for (int c = 0; c < 4; ++c) values[4 * i + c] /= static_cast<float>(count);
    }
    std::vector<int> next;
    for (size_t i = 0; i < frontier.size(); ++i) {
      const int x = frontier[i] % n, y = frontier[i] / n;
      for (int c = 0; c < 3; ++c) albedo->at(x, y, c) = values[4 * i + c];
      roughness->at(x, y) = values[4 * i + 3];
      (*filled)[frontier[i]] = 2;  // filled in this ring: not a source until the ring is done.
    }
    for (int k : frontier) {
      (*filled)[k] = 1;
      ++*dilated;
      const int x = k % n, y = k / n;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= n || yy >= n || (*filled)[yy * n + xx]) continue;
          (*filled)[yy * n + xx] = 3;  // queued.
          next.push_back(yy * n + xx);
        }
      }
    }
    for (int k : next) (*filled)[k] = 0;
    frontier.swap(next);
  }
  return rings;
}

}  // namespace

Status BakeMaterial(const UvAtlas& atlas, const Material& material, BakedMaterial* baked,
                    BakeReport* report) {
  const auto start = std::chrono::steady_clock::now();
  const int num_faces = static_cast<int>(atlas.chart_of_face.size());
  if (material.albedo.num_faces() != num_faces || material.roughness.num_faces() != num_faces) {
    return Status::Error("the material has " + std::to_string(material.albedo.num_faces()) +
                         " faces, the mesh " + std::to_string(num_faces));
  }
  *report = BakeReport();
  const int n = atlas.texture_size;
  baked->albedo = Image(n, n, 3, 0.0f);
  baked->roughness = Image(n, n, 1, 0.0f);
  baked->coverage = Image(n, n, 1, 0.0f);
  std::vector<float> best(static_cast<size_t>(n) * n, std::numeric_limits<float>::infinity());
  constexpr double kReach = 1.0;  // texels outside a face that still take its value.
  for (int f = 0; f < num_faces; ++f) {
    if (atlas.chart_of_face[f] < 0) continue;
    Eigen::Vector2d p[3];
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
    for (int c = 0; c < 3; ++c) {
      p[c] = UvToTexel(atlas.corner_uv[3 * f + c], n);
      lo = lo.cwiseMin(p[c]);
      hi = hi.cwiseMax(p[c]);
    }
    const int x0 = std::max(0, static_cast<int>(std::floor(lo.x() - kReach)));
    const int y0 = std::max(0, static_cast<int>(std::floor(lo.y() - kReach)));
    const int x1 = std::min(n - 1, static_cast<int>(std::ceil(hi.x() + kReach)));
    const int y1 = std::min(n - 1, static_cast<int>(std::ceil(hi.y() + kReach)));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        double d = 0.0;
        const Eigen::Vector3d w = ClosestPoint(Eigen::Vector2d(x + 0.5, y + 0.5), p, &d);
        const size_t k = static_cast<size_t>(y) * n + x;
        if (!(d <= kReach) || !(d < best[k])) continue;
        best[k] = static_cast<float>(d);
        const double* a = material.albedo.texel(material.albedo.TexelIndex(f, w[1], w[2]));
        const double* r = material.roughness.texel(material.roughness.TexelIndex(f, w[1], w[2]));
        for (int c = 0; c < 3; ++c) baked->albedo.at(x, y, c) = static_cast<float>(a[c]);
        baked->roughness.at(x, y) = static_cast<float>(r[0]);
        baked->coverage.at(x, y) = d == 0.0 ? 1.0f : 0.0f;
      }
    }
  }
  std::vector<unsigned char> filled(static_cast<size_t>(n) * n, 0);
  for (size_t k = 0; k < filled.size(); ++k) {
    if (std::isfinite(best[k])) {
      filled[k] = 1;
      if (best[k] == 0.0f) {
        ++report->covered_texels;
      } else {
        ++report->edge_texels;
      }
    }
  }
  report->dilation_rings =
      Dilate(&filled, &baked->albedo, &baked->roughness, &report->dilated_texels);
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace sft
