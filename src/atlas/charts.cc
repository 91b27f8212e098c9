#include "src/atlas/charts.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <queue>
#include <unordered_map>
#include <utility>

namespace sft {
namespace {

bool VertexInChart(const MeshTopology& topology, const std::vector<int>& chart_of_face, int v,
                   int c) {
  for (int g : topology.VertexFaces(v)) {
    if (chart_of_face[g] == c) return true;
  }
  return false;
}

// Per-chart state of one GrowCharts call: ids from `first` on.
struct ChartStats {
  int first = 0;
  std::vector<Eigen::Vector3d> normal_sum;  // Σ area·normal.
  std::vector<int> size;

  void Add(const MeshTopology& t, int c, int f) {
    const size_t k = static_cast<size_t>(c - first);
    if (k >= size.size()) {
      size.resize(k + 1, 0);
      normal_sum.resize(k + 1, Eigen::Vector3d::Zero());
    }
    ++size[k];
    normal_sum[k] += t.area(f) * t.normal(f);
  }
  bool Within(const MeshTopology& t, int c, int f, double cos_angle) const {
    const Eigen::Vector3d& sum = normal_sum[c - first];
    const double norm = sum.norm();
    return norm > 0.0 && t.normal(f).dot(sum) >= cos_angle * norm;
  }
};

// Grows one chart with id c from `seed` (see charts.h); faces it looked at but did not take are
// appended to `rejected` (seeds for the next charts, so that charts follow each other).
void GrowOne(const MeshTopology& t, int seed, int c, double cos_angle, int max_faces,
             std::vector<int>* chart_of_face, ChartStats* stats, std::vector<int>* rejected) {
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  std::unordered_map<int, double> distance;
  auto push_neighbours = [&](int f, double d) {
    for (int e = 0; e < 3; ++e) {
      const int g = t.Neighbour(f, e);
      if (g < 0 || (*chart_of_face)[g] != -1) continue;
      const double dg = d + (t.centroid(g) - t.centroid(f)).norm();
      auto [it, inserted] = distance.emplace(g, dg);
      if (!inserted && dg >= it->second) {
        // Already queued closer; still queue again so that a face refused earlier gets another
        // chance now that the chart around it has changed.
        queue.emplace(it->second, g);
        continue;
      }
      it->second = dg;
      queue.emplace(dg, g);
    }
  };
  (*chart_of_face)[seed] = c;
  stats->Add(t, c, seed);
  int size = 1;
  push_neighbours(seed, 0.0);
  while (!queue.empty() && (max_faces <= 0 || size < max_faces)) {
    const auto [d, f] = queue.top();
    queue.pop();
    if ((*chart_of_face)[f] != -1) continue;
    if (!stats->Within(t, c, f, cos_angle) || !KeepsDisk(t, *chart_of_face, f, c) ||
        !KeepsBorderAnglesFlat(t, *chart_of_face, f, c)) {
      rejected->push_back(f);
      continue;
    }
    (*chart_of_face)[f] = c;
    stats->Add(t, c, f);
    ++size;
    push_neighbours(f, d);
  }
  while (!queue.empty()) {
    rejected->push_back(queue.top().second);
    queue.pop();
  }
}

// Grows charts until every face of `faces` has one.
void GrowPass(const MeshTopology& t, const std::vector<int>& faces, double cos_angle, int max_faces,
              std::vector<int>* chart_of_face, int* num_charts, ChartStats* stats) {
  std::vector<int> seeds;
  size_t scan = 0;
  while (true) {
    int seed = -1;
    while (!seeds.empty() && seed < 0) {
      if ((*chart_of_face)[seeds.back()] == -1) seed = seeds.back();
      seeds.pop_back();
    }
    while (seed < 0 && scan < faces.size()) {
      if ((*chart_of_face)[faces[scan]] == -1) seed = faces[scan];
      ++scan;
    }
    if (seed < 0) return;
    std::vector<int> rejected;
    GrowOne(t, seed, (*num_charts)++, cos_angle, max_faces, chart_of_face, stats, &rejected);
    // The nearest refused faces are tried first (the stack pops from the back).
    seeds.insert(seeds.end(), rejected.rbegin(), rejected.rend());
  }
}

// Dissolves the charts of `stats` smaller than `min_faces` and offers their faces to neighbouring
// charts of the same call (ids ≥ stats.first) under `cos_angle`, repeatedly; returns the faces
// left without a chart.
std::vector<int> DissolveSmallCharts(const MeshTopology& t, const std::vector<int>& faces,
                                     int min_faces, double cos_angle, int max_faces,
                                     std::vector<int>* chart_of_face, ChartStats* stats) {
  std::vector<int> loose;
  for (int f : faces) {
    const int c = (*chart_of_face)[f];
    if (c >= stats->first && stats->size[c - stats->first] < min_faces) loose.push_back(f);
  }
  for (int f : loose) {
    const int k = (*chart_of_face)[f] - stats->first;
    --stats->size[k];
    stats->normal_sum[k] -= t.area(f) * t.normal(f);
    (*chart_of_face)[f] = -1;
  }
  bool changed = true;
  while (changed && !loose.empty()) {
    changed = false;
    std::vector<int> still;
    for (int f : loose) {
      int best = -1;
      double best_dot = cos_angle;
      for (int e = 0; e < 3; ++e) {
        const int g = t.Neighbour(f, e);
        const int c = g < 0 ? -1 : (*chart_of_face)[g];
        if (c < stats->first) continue;
        const int k = c - stats->first;
        if (stats->size[k] == 0 || (max_faces > 0 && stats->size[k] >= max_faces)) continue;
        const double dot = t.normal(f).dot(stats->normal_sum[k].normalized());
        if (dot >= best_dot && KeepsDisk(t, *chart_of_face, f, c) &&
            KeepsBorderAnglesFlat(t, *chart_of_face, f, c)) {
          best = c;
          best_dot = dot;
        }
      }
      if (best < 0) {
        still.push_back(f);
        continue;
      }
      (*chart_of_face)[f] = best;
      stats->Add(t, best, f);
      changed = true;
    }
    loose.swap(still);
  }
  return loose;
}

}  // namespace

bool ChartingOptions::Check(std::string* why) const {
  if (!(max_normal_angle_degrees > 0.0 && max_normal_angle_degrees <= 90.0)) {
    *why = "max_normal_angle_degrees: expected (0, 90], got " +
           std::to_string(max_normal_angle_degrees);
    return false;
  }
  if (min_chart_faces < 1 || min_chart_faces > 1000) {
    *why = "min_chart_faces: expected [1, 1000], got " + std::to_string(min_chart_faces);
    return false;
  }
  if (max_chart_faces < 0) {
    *why = "max_chart_faces: expected >= 0, got " + std::to_string(max_chart_faces);
    return false;
  }
  return true;
}

bool KeepsDisk(const MeshTopology& t, const std::vector<int>& chart_of_face, int f, int c) {
  const Eigen::Vector3i& v = t.face(f);
  int shared = 0, free_edge = -1;
  for (int e = 0; e < 3; ++e) {
    const int g = t.Neighbour(f, e);
    if (g >= 0 && chart_of_face[g] == c) {
      ++shared;
    } else {
      free_edge = e;
    }
  }
  if (shared == 1) {
    // The corner opposite the shared edge must be new to the chart.
    for (int e = 0; e < 3; ++e) {
      const int g = t.Neighbour(f, e);
      if (g >= 0 && chart_of_face[g] == c) {
        return !VertexInChart(t, chart_of_face, v[(e + 2) % 3], c);
      }
    }
  }
  if (shared == 2) {
    // No chart face may already use the third edge (through a cut or non-manifold edge).
    const int a = v[free_edge], b = v[(free_edge + 1) % 3];
    for (int g : t.VertexFaces(a)) {
      if (g == f || chart_of_face[g] != c) continue;
      const Eigen::Vector3i& w = t.face(g);
      if (w[0] == b || w[1] == b || w[2] == b) return false;
    }
    return true;
  }
  return false;  // 0 shared edges: not adjacent; 3: would close the surface.
}

bool KeepsBorderAnglesFlat(const MeshTopology& t, const std::vector<int>& chart_of_face, int f,
                           int c) {
  constexpr double kMaxBorderAngle = 0.95 * 2.0 * M_PI;
  const Eigen::Vector3i& corners = t.face(f);
  for (int k = 0; k < 3; ++k) {
    const int v = corners[k];
    double sum = t.angle(f, k);
    size_t inside = 1;
    for (int g : t.VertexFaces(v)) {
      if (g == f || chart_of_face[g] != c) continue;
      const Eigen::Vector3i& w = t.face(g);
      sum += t.angle(g, w[0] == v ? 0 : (w[1] == v ? 1 : 2));
      ++inside;
    }
    // With every face around v in the chart, v is interior (or on the mesh's own border).
    if (inside < t.VertexFaces(v).size() && sum > kMaxBorderAngle) return false;
  }
  return true;
}

void GrowCharts(const MeshTopology& t, const std::vector<int>& subset,
                const ChartingOptions& options, std::vector<int>* chart_of_face, int* num_charts) {
  std::vector<int> faces;
  if (subset.empty()) {
    for (int f = 0; f < t.num_faces(); ++f) {
      if (!t.degenerate(f)) faces.push_back(f);
    }
  } else {
    for (int f : subset) {
      if (!t.degenerate(f)) faces.push_back(f);
    }
  }
  for (int f : faces) (*chart_of_face)[f] = -1;
  ChartStats stats;
  stats.first = *num_charts;
  const double kDegrees = M_PI / 180.0;
  const double cos_angle = std::cos(options.max_normal_angle_degrees * kDegrees);
  GrowPass(t, faces, cos_angle, options.max_chart_faces, chart_of_face, num_charts, &stats);
  if (options.min_chart_faces <= 1) return;
  // Small leftovers join a neighbour under a cone half as wide again (at most 90°).
  const double wide = std::cos(std::min(90.0, 1.5 * options.max_normal_angle_degrees) * kDegrees);
  const std::vector<int> loose = DissolveSmallCharts(
      t, faces, options.min_chart_faces, wide, options.max_chart_faces, chart_of_face, &stats);
  GrowPass(t, loose, wide, options.max_chart_faces, chart_of_face, num_charts, &stats);
}

}  // namespace sft

namespace sft {

void SplitChart(const MeshTopology& t, const std::vector<int>& faces,
                const ChartingOptions& options, std::vector<int>* chart_of_face, int* num_charts) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int f : faces) {
    mean += t.centroid(f) / static_cast<double>(faces.size());
    (*chart_of_face)[f] = -1;
  }
  auto farthest_from = [&](const Eigen::Vector3d& p) {
    int best = faces[0];
    for (int f : faces) {
      if ((t.centroid(f) - p).squaredNorm() > (t.centroid(best) - p).squaredNorm()) best = f;
    }
    return best;
  };
  const int seed_a = farthest_from(mean);
  const int seed_b = farthest_from(t.centroid(seed_a));
  struct Entry {
    double distance;
    int face, chart;
    bool operator>(const Entry& o) const { return distance > o.distance; }
  };
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  auto take = [&](int f, int c, double d) {
    (*chart_of_face)[f] = c;
    for (int e = 0; e < 3; ++e) {
      const int g = t.Neighbour(f, e);
      if (g >= 0 && (*chart_of_face)[g] == -1) {
        queue.push({d + (t.centroid(g) - t.centroid(f)).norm(), g, c});
      }
    }
  };
  const int a = (*num_charts)++;
  take(seed_a, a, 0.0);
  if (seed_b != seed_a) take(seed_b, (*num_charts)++, 0.0);
  while (!queue.empty()) {
    const Entry entry = queue.top();
    queue.pop();
    const int f = entry.face, c = entry.chart;
    if ((*chart_of_face)[f] != -1) continue;
    if (KeepsDisk(t, *chart_of_face, f, c) && KeepsBorderAnglesFlat(t, *chart_of_face, f, c)) {
      take(f, c, entry.distance);
    }
  }
  std::vector<int> left;
  for (int f : faces) {
    if ((*chart_of_face)[f] == -1) left.push_back(f);
  }
  if (!left.empty()) GrowCharts(t, left, options, chart_of_face, num_charts);
}

}  // namespace sft
