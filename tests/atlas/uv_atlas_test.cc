// The UV atlas: charts are disks and more than one face each, no two UV triangles overlap (a
// supersampled coverage count), charts keep their gutters, stretch is bounded, utilisation is
// honest, and non-manifold, mis-oriented and degenerate input is handled.
#include "src/atlas/uv_atlas.h"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <utility>

#include "src/atlas/bake.h"
#include "tests/testing/meshes.h"

namespace sft {
namespace {

using testing::Triangles;

// Faces of each chart.
std::vector<std::vector<int>> Charts(const UvAtlas& atlas) {
  std::vector<std::vector<int>> charts(atlas.num_charts);
  for (size_t f = 0; f < atlas.chart_of_face.size(); ++f) {
    if (atlas.chart_of_face[f] >= 0) charts[atlas.chart_of_face[f]].push_back(static_cast<int>(f));
  }
  return charts;
}

// True when the faces form a topological disk: connected through shared edges, V − E + F = 1,
// every edge used once or twice, and the border edges one closed loop through distinct vertices.
bool IsDisk(const std::vector<Eigen::Vector3i>& faces, const std::vector<int>& chart) {
  std::map<std::pair<int, int>, int> edge_uses;
  std::set<int> vertices;
  for (int f : chart) {
    for (int c = 0; c < 3; ++c) {
      const int a = faces[f][c], b = faces[f][(c + 1) % 3];
      ++edge_uses[{std::min(a, b), std::max(a, b)}];
      vertices.insert(a);
    }
  }
  std::map<int, std::vector<int>> border;  // vertex → border neighbours.
  for (const auto& [edge, uses] : edge_uses) {
    if (uses > 2) return false;
    if (uses == 1) {
      border[edge.first].push_back(edge.second);
      border[edge.second].push_back(edge.first);
    }
  }
  const long euler = static_cast<long>(vertices.size()) - static_cast<long>(edge_uses.size()) +
                     static_cast<long>(chart.size());
  if (euler != 1 || border.empty()) return false;
  for (const auto& [v, next] : border) {
    if (next.size() != 2) return false;  // a pinched border vertex.
  }
  // Walk the loop from one border vertex: it must visit every border vertex.
  int previous = -1, current = border.begin()->first;
  size_t steps = 0;
  do {
    const std::vector<int>& next = border[current];
    const int go = next[0] != previous ? next[0] : next[1];
    previous = current;
    current = go;
    ++steps;
  } while (current != border.begin()->first && steps <= border.size());
  return steps == border.size();
}

// Texel-level checks of the packed atlas at 4×4 samples per texel: no sample strictly inside two
// UV triangles, and no texel covered by one chart within `gutter` − 1 texels of another chart.
struct Coverage {
  int overlapping_samples = 0;
  int gutter_violations = 0;
};
Coverage CheckCoverage(const UvAtlas& atlas, int gutter) {
  const int n = atlas.texture_size, sub = 4, m = n * sub;
  std::vector<int> owner(static_cast<size_t>(m) * m, -1);
  std::vector<int> texel_chart(static_cast<size_t>(n) * n, -1);
  Coverage result;
  for (size_t f = 0; f < atlas.chart_of_face.size(); ++f) {
    if (atlas.chart_of_face[f] < 0) continue;
    Eigen::Vector2d p[3];
    for (int c = 0; c < 3; ++c) p[c] = UvToTexel(atlas.corner_uv[3 * f + c], n) * sub;
    const double det =
        (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    const Eigen::Vector2d lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]);
    const Eigen::Vector2d hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
    for (int y = std::max(0, static_cast<int>(lo.y()));
         y <= std::min(m - 1, static_cast<int>(hi.y())); ++y) {
      for (int x = std::max(0, static_cast<int>(lo.x()));
           x <= std::min(m - 1, static_cast<int>(hi.x())); ++x) {
        const Eigen::Vector2d q(x + 0.5, y + 0.5);
        double w[3];
        for (int e = 0; e < 3; ++e) {
          const Eigen::Vector2d a = p[(e + 1) % 3] - q, b = p[(e + 2) % 3] - q;
          w[e] = (a.x() * b.y() - a.y() * b.x()) / det;
        }
        if (w[0] <= 1e-9 || w[1] <= 1e-9 || w[2] <= 1e-9) continue;
        int& o = owner[static_cast<size_t>(y) * m + x];
        if (o >= 0) ++result.overlapping_samples;
        o = static_cast<int>(f);
        texel_chart[static_cast<size_t>(y / sub) * n + x / sub] = atlas.chart_of_face[f];
      }
    }
  }
  const int reach = gutter - 1;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const int c = texel_chart[static_cast<size_t>(y) * n + x];
      if (c < 0) continue;
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= n || yy >= n) continue;
          const int d = texel_chart[static_cast<size_t>(yy) * n + xx];
          if (d >= 0 && d != c) ++result.gutter_violations;
        }
      }
    }
  }
  return result;
}

void ExpectValidAtlas(const Triangles& mesh, const UvAtlasOptions& options, const UvAtlas& atlas,
                      const UvAtlasReport& report) {
  ASSERT_EQ(atlas.corner_uv.size(), 3 * mesh.faces.size());
  for (const Eigen::Vector2d& uv : atlas.corner_uv) {
    EXPECT_GE(uv.minCoeff(), 0.0);
    EXPECT_LE(uv.maxCoeff(), 1.0);
  }
  int disks = 0;
  for (const std::vector<int>& chart : Charts(atlas)) disks += IsDisk(mesh.faces, chart) ? 1 : 0;
  EXPECT_EQ(disks, atlas.num_charts);
  const Coverage coverage = CheckCoverage(atlas, options.gutter_texels);
  EXPECT_EQ(coverage.overlapping_samples, 0);
  EXPECT_EQ(coverage.gutter_violations, 0);
  EXPECT_GE(report.max_stretch, 1.0 - 1e-9);
  EXPECT_LE(report.max_stretch, options.max_stretch);
  EXPECT_EQ(report.charts, atlas.num_charts);
}

TEST(UvAtlasTest, SphereChartsAreDisksWithoutOverlaps) {
  const Triangles sphere = testing::ReadTestMesh("icosphere_r1_1280f.obj");
  UvAtlasOptions options;
  options.texture_size = 512;
  UvAtlas atlas;
  UvAtlasReport report;
  ASSERT_TRUE(BuildUvAtlas(sphere.positions, sphere.faces, options, &atlas, &report).ok());
  ExpectValidAtlas(sphere, options, atlas, report);
  // Charts, not one island per triangle: a closed sphere needs a few, 1280 faces are far more.
  EXPECT_GE(atlas.num_charts, 2);
  EXPECT_LE(atlas.num_charts, 64);
  EXPECT_GT(report.utilization, 0.4);
  EXPECT_LT(report.utilization, 1.0);
  EXPECT_EQ(report.degenerate_faces, 0);
  EXPECT_EQ(report.nonmanifold_edges, 0);
  printf("sphere: %d charts, utilisation %.3f, max stretch %.3f, %.3f s\n", report.charts,
         report.utilization, report.max_stretch, report.seconds);
}

TEST(UvAtlasTest, BunnyStretchIsBoundedAndSplitsHonourTheBound) {
  const Triangles bunny = testing::ReadTestMesh("bunny_watertight_5k.obj");
  UvAtlasOptions options;
  options.texture_size = 1024;
  options.max_stretch = 1.1;
  UvAtlas atlas;
  UvAtlasReport report;
  ASSERT_TRUE(BuildUvAtlas(bunny.positions, bunny.faces, options, &atlas, &report).ok());
  ExpectValidAtlas(bunny, options, atlas, report);
  EXPECT_LT(atlas.num_charts, static_cast<int>(bunny.faces.size()) / 10);
  EXPECT_GT(report.utilization, 0.3);
  printf("bunny: %d charts, %d splits, utilisation %.3f, max stretch %.3f, %.3f s\n", report.charts,
         report.splits, report.utilization, report.max_stretch, report.seconds);
}

// A 4×4 grid of quads with a fin (a third face on an interior edge), a face that disagrees with
// its neighbour about orientation, and a face with a repeated vertex.
TEST(UvAtlasTest, NonManifoldMisorientedAndDegenerateFaces) {
  Triangles mesh;
  const int n = 4;
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) mesh.positions.emplace_back(x, y, 0.0);
  }
  auto id = [&](int x, int y) { return y * (n + 1) + x; };
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      mesh.faces.emplace_back(id(x, y), id(x + 1, y), id(x + 1, y + 1));
      mesh.faces.emplace_back(id(x, y), id(x + 1, y + 1), id(x, y + 1));
    }
  }
  // Fin on the interior edge (1,1)–(2,2), standing up in z.
  mesh.positions.emplace_back(1.5, 1.5, 1.0);
  const int apex = static_cast<int>(mesh.positions.size()) - 1;
  mesh.faces.emplace_back(id(1, 1), id(2, 2), apex);
  // A separate flipped pair: (3..4 shifted) two faces sharing an edge in the same direction.
  const int base = static_cast<int>(mesh.positions.size());
  mesh.positions.emplace_back(10, 0, 0);
  mesh.positions.emplace_back(11, 0, 0);
  mesh.positions.emplace_back(10, 1, 0);
  mesh.positions.emplace_back(11, 1, 0);
  mesh.faces.emplace_back(base, base + 1, base + 2);
  mesh.faces.emplace_back(base + 1, base + 2, base + 3);  // runs base+1 → base+2 as well.
  mesh.faces.emplace_back(base, base, base + 3);          // repeated vertex.
  UvAtlasOptions options;
  options.texture_size = 256;
  UvAtlas atlas;
  UvAtlasReport report;
  ASSERT_TRUE(BuildUvAtlas(mesh.positions, mesh.faces, options, &atlas, &report).ok());
  EXPECT_EQ(report.nonmanifold_edges, 1);
  EXPECT_EQ(report.inconsistent_edges, 1);
  EXPECT_EQ(report.degenerate_faces, 1);
  EXPECT_EQ(atlas.chart_of_face.back(), -1);
  for (size_t f = 0; f + 1 < mesh.faces.size(); ++f) EXPECT_GE(atlas.chart_of_face[f], 0) << f;
  ExpectValidAtlas(mesh, options, atlas, report);
  // The three faces on the non-manifold edge cannot all be in one chart.
  const int fin = static_cast<int>(mesh.faces.size()) - 4;
  std::set<int> around = {atlas.chart_of_face[fin], atlas.chart_of_face[2 * (1 * n + 1)]};
  EXPECT_EQ(around.size(), 2u);
}

TEST(UvAtlasTest, ErrorsAndOptions) {
  const Triangles sphere = testing::ReadTestMesh("icosphere_r1_320f.obj");
  UvAtlas atlas;
  UvAtlasReport report;
  UvAtlasOptions options;
  options.texture_size = 32;
  Status status = BuildUvAtlas(sphere.positions, sphere.faces, options, &atlas, &report);
  EXPECT_NE(status.message().find("texture_size"), std::string::npos) << status.message();
  options = UvAtlasOptions();
  options.max_stretch = 1.0;
  EXPECT_FALSE(BuildUvAtlas(sphere.positions, sphere.faces, options, &atlas, &report).ok());
  std::vector<Eigen::Vector3i> bad = sphere.faces;
  bad[3][1] = 100000;
  status = BuildUvAtlas(sphere.positions, bad, UvAtlasOptions(), &atlas, &report);
  EXPECT_NE(status.message().find("face 3"), std::string::npos) << status.message();
  // 64² texels cannot hold 320 one-face charts with 4-texel gutters.
  options = UvAtlasOptions();
  options.texture_size = 64;
  options.charting.max_normal_angle_degrees = 1.0;
  options.charting.min_chart_faces = 1;
  status = BuildUvAtlas(sphere.positions, sphere.faces, options, &atlas, &report);
  EXPECT_NE(status.message().find("raise --texture-size"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace sft
