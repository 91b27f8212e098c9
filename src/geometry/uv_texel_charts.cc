#include "src/geometry/uv_texel_charts.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

namespace sft {
namespace {

int Find(std::vector<int>* parent, int a) {
  while ((*parent)[a] != a) {
    (*parent)[a] = (*parent)[(*parent)[a]];
    a = (*parent)[a];
  }
  return a;
}

// Whether triangle p[0..2] meets the open square (cx − 1, cx + 1) × (cy − 1, cy + 1): no
// separating axis among x, y and the three edge normals.
bool TriangleMeetsSquare(const Eigen::Vector2d* p, double cx, double cy) {
  const Eigen::Vector2d c(cx, cy);
  for (int axis = 0; axis < 2; ++axis) {
    const double lo = std::min({p[0][axis], p[1][axis], p[2][axis]});
    const double hi = std::max({p[0][axis], p[1][axis], p[2][axis]});
    if (hi <= c[axis] - 1.0 || lo >= c[axis] + 1.0) return false;
  }
  for (int e = 0; e < 3; ++e) {
    const Eigen::Vector2d d = p[(e + 1) % 3] - p[e];
    const Eigen::Vector2d n(-d.y(), d.x());
    const double tri_a = n.dot(p[e]), tri_b = n.dot(p[(e + 2) % 3]);
    const double tri_lo = std::min(tri_a, tri_b), tri_hi = std::max(tri_a, tri_b);
    const double centre = n.dot(c), reach = std::abs(n.x()) + std::abs(n.y());
    if (tri_hi <= centre - reach || tri_lo >= centre + reach) return false;
  }
  return true;
}

// Charts: faces joined across edges whose two faces agree on both vertices' UVs.
void FaceCharts(const std::vector<Eigen::Vector3i>& faces,
                const std::vector<Eigen::Vector2d>& corner_uvs, UvTexelCharts* out) {
  const int num_faces = static_cast<int>(faces.size());
  std::vector<int> parent(num_faces);
  std::iota(parent.begin(), parent.end(), 0);
  // Edge (lo, hi) -> the first face corner pair seen on it.
  std::map<std::pair<int, int>, std::pair<int, int>> edges;  // -> (face, corner of edge start)
  for (int f = 0; f < num_faces; ++f) {
    for (int e = 0; e < 3; ++e) {
      const int a = faces[f][e], b = faces[f][(e + 1) % 3];
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      const auto it = edges.find(key);
      if (it == edges.end()) {
        edges.emplace(key, std::make_pair(f, e));
        continue;
      }
      const int g = it->second.first, ge = it->second.second;
      const int ga = faces[g][ge];
      // UV of vertex v in face h at corner k.
      const Eigen::Vector2d& ua = corner_uvs[3 * f + e];
      const Eigen::Vector2d& ub = corner_uvs[3 * f + (e + 1) % 3];
      const Eigen::Vector2d& va = corner_uvs[3 * g + (ga == a ? ge : (ge + 1) % 3)];
      const Eigen::Vector2d& vb = corner_uvs[3 * g + (ga == a ? (ge + 1) % 3 : ge)];
      if (ua == va && ub == vb) parent[Find(&parent, f)] = Find(&parent, g);
    }
  }
  std::vector<int> id(num_faces, -1);
  out->chart_of_face.assign(num_faces, -1);
  out->num_charts = 0;
  for (int f = 0; f < num_faces; ++f) {
    const int root = Find(&parent, f);
    if (id[root] < 0) id[root] = out->num_charts++;
    out->chart_of_face[f] = id[root];
  }
}

}  // namespace

UvTexelCharts ComputeUvTexelCharts(const std::vector<Eigen::Vector3i>& faces,
                                   const std::vector<Eigen::Vector2d>& corner_uvs, int width,
                                   int height) {
  UvTexelCharts out;
  out.width = width;
  out.height = height;
  out.chart_of_texel.assign(static_cast<size_t>(width) * height, -1);
  FaceCharts(faces, corner_uvs, &out);
  for (size_t f = 0; f < faces.size(); ++f) {
    Eigen::Vector2d p[3];
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector2d& uv = corner_uvs[3 * f + c];
      p[c] = Eigen::Vector2d(uv.x() * width - 0.5, (1.0 - uv.y()) * height - 0.5);
    }
    const double area2 =
        std::abs((p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x());
    if (!(area2 > 1e-9)) continue;
    const double lo_x = std::min({p[0].x(), p[1].x(), p[2].x()});
    const double hi_x = std::max({p[0].x(), p[1].x(), p[2].x()});
    const double lo_y = std::min({p[0].y(), p[1].y(), p[2].y()});
    const double hi_y = std::max({p[0].y(), p[1].y(), p[2].y()});
    const int x0 = std::max(0, static_cast<int>(std::floor(lo_x)));
    const int x1 = std::min(width - 1, static_cast<int>(std::ceil(hi_x)));
    const int y0 = std::max(0, static_cast<int>(std::floor(lo_y)));
    const int y1 = std::min(height - 1, static_cast<int>(std::ceil(hi_y)));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        int& chart = out.chart_of_texel[static_cast<size_t>(y) * width + x];
        if (chart >= 0 || !TriangleMeetsSquare(p, x, y)) continue;
        chart = out.chart_of_face[f];
        ++out.used_texels;
      }
    }
  }
  return out;
}

int DilateUnusedTexels(const UvTexelCharts& charts, int channels, std::vector<double>* values) {
  const int w = charts.width, h = charts.height;
  if (charts.used_texels == 0) return 0;
  std::vector<unsigned char> filled(static_cast<size_t>(w) * h, 0);
  for (size_t k = 0; k < filled.size(); ++k) filled[k] = charts.chart_of_texel[k] >= 0 ? 1 : 0;
  auto for_neighbours = [&](int k, auto&& visit) {
    const int x = k % w, y = k / w;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx, yy = y + dy;
        if ((dx != 0 || dy != 0) && xx >= 0 && yy >= 0 && xx < w && yy < h) visit(yy * w + xx);
      }
    }
  };
  std::vector<int> frontier;
  for (int k = 0; k < w * h; ++k) {
    if (filled[k]) continue;
    bool next_to = false;
    for_neighbours(k, [&](int n) { next_to = next_to || filled[n] == 1; });
    if (next_to) frontier.push_back(k);
  }
  int rings = 0;
  std::vector<double> sums;
  while (!frontier.empty()) {
    ++rings;
    sums.assign(frontier.size() * channels, 0.0);
    for (size_t i = 0; i < frontier.size(); ++i) {
      int count = 0;
      for_neighbours(frontier[i], [&](int n) {
        if (filled[n] != 1) return;
        for (int c = 0; c < channels; ++c) sums[i * channels + c] += (*values)[n * channels + c];
        ++count;
      });
      for (int c = 0; c < channels; ++c) {
        (*values)[static_cast<size_t>(frontier[i]) * channels + c] = sums[i * channels + c] / count;
      }
    }
    for (int k : frontier) filled[k] = 1;
    std::vector<int> next;
    for (int k : frontier) {
      for_neighbours(k, [&](int n) {
        if (filled[n] == 0) {
          filled[n] = 2;  // queued for the next ring.
          next.push_back(n);
        }
      });
    }
    for (int k : next) filled[k] = 0;
    frontier.swap(next);
  }
  return rings;
}

void DilateUvGutters(const std::vector<Eigen::Vector3i>& faces, UvMaterialMaps* maps) {
  for (UvTexture* texture : {&maps->albedo, &maps->roughness}) {
    if (texture->empty()) continue;
    const UvTexelCharts charts =
        ComputeUvTexelCharts(faces, maps->corner_uvs, texture->width(), texture->height());
    DilateUnusedTexels(charts, texture->channels(), &texture->values());
  }
}

}  // namespace sft
