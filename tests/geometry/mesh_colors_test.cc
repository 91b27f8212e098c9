// Mesh colors: the texel layout of the report's appendix, texel centres, and the file format.
#include "src/geometry/mesh_colors.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "src/core/rng.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

// The report's formula, written out independently of MeshColors.
int ReportIndex(int t, int r, int i, int j) {
  return (t * (r + 1) * (r + 2) + i * (2 * r - i + 3)) / 2 + j;
}

TEST(MeshColorsLayoutTest, CountsAndIndexFormula) {
  for (int r = 1; r <= 8; ++r) {
    SCOPED_TRACE(r);
    EXPECT_EQ(MeshColors::TexelsPerFace(r), (r + 1) * (r + 2) / 2);
    const MeshColors colors(5, r, 2);
    EXPECT_EQ(colors.num_texels(), 5 * (r + 1) * (r + 2) / 2);
    EXPECT_EQ(colors.values().size(), static_cast<size_t>(colors.num_texels()) * 2);
    // Rows i = 0..r of r − i + 1 texels enumerate the face's texels 0..T−1 in order.
    int expected_local = 0;
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; j <= r - i; ++j) {
        EXPECT_EQ(MeshColors::LocalIndex(r, i, j), expected_local++);
        for (int t : {0, 3, 4}) {
          const Eigen::Vector2d c = MeshColors::TexelCenter(r, i, j);
          EXPECT_EQ(colors.TexelIndex(t, c.x(), c.y()), ReportIndex(t, r, i, j))
              << "t " << t << " i " << i << " j " << j;
        }
      }
    }
    EXPECT_EQ(expected_local, MeshColors::TexelsPerFace(r));
  }
}

// Every texel of every face is hit by some point of the triangle: the area texels by interior
// points, the zero-area texels (i + j = r) at their lattice points (vertices and lattice points
// of the edge α + β = 1). Points are barycentric lattice points k/(4r) plus random points.
TEST(MeshColorsLayoutTest, EveryTexelReachable) {
  for (int r = 1; r <= 8; ++r) {
    SCOPED_TRACE(r);
    const int faces = 3;
    const MeshColors colors(faces, r, 1);
    std::set<int> hit;
    const int n = 4 * r;
    for (int t = 0; t < faces; ++t) {
      for (int a = 0; a <= n; ++a) {
        for (int b = 0; a + b <= n; ++b) {
          const int k =
              colors.TexelIndex(t, static_cast<double>(a) / n, static_cast<double>(b) / n);
          ASSERT_GE(k, t * MeshColors::TexelsPerFace(r));
          ASSERT_LT(k, (t + 1) * MeshColors::TexelsPerFace(r));
          hit.insert(k);
        }
      }
    }
    EXPECT_EQ(static_cast<int>(hit.size()), colors.num_texels());
    // Random interior points land on area texels only (i + j <= r − 1).
    Sampler sampler(7, r, 0, 0);
    for (int s = 0; s < 2000; ++s) {
      double a = sampler.Next1D(), b = sampler.Next1D();
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const int local = colors.TexelIndex(0, a, b);
      const int i = static_cast<int>(std::floor(r * a)), j = static_cast<int>(std::floor(r * b));
      EXPECT_EQ(local, MeshColors::LocalIndex(r, i, j));
      EXPECT_LE(i + j, r - 1);
    }
  }
}

// Points outside the triangle (rounding, or grazing hits) are clamped into it.
TEST(MeshColorsLayoutTest, OutsidePointsClamp) {
  const int r = 4;
  const MeshColors colors(2, r, 1);
  EXPECT_EQ(colors.TexelIndex(1, -0.1, -1e-12), ReportIndex(1, r, 0, 0));
  EXPECT_EQ(colors.TexelIndex(1, 1.5, 0.0), ReportIndex(1, r, r, 0));
  EXPECT_EQ(colors.TexelIndex(1, 0.0, 1.0 + 1e-12), ReportIndex(1, r, 0, r));
  // Beyond the edge α + β = 1: scaled back onto it, (0.6, 0.6) -> (0.5, 0.5) -> (2, 2).
  EXPECT_EQ(colors.TexelIndex(1, 0.6, 0.6), ReportIndex(1, r, 2, 2));
  EXPECT_EQ(colors.TexelIndex(1, std::nan(""), 0.3), ReportIndex(1, r, 0, 1));
}

// TexelCenter is the centroid of the region of the triangle that maps to the texel: checked
// against the mean of a fine midpoint grid (N² cells per unit of grid coordinates) of points that
// TexelIndex sends to the texel. The grid centroid of a square or a half square is exact up to
// the cells cut by the diagonal: error O(1/N) of a texel; N = 200 gives < 1e-2 of a texel, and
// we check to 2e-3/r in barycentric units (i.e. 2e-3 of a texel).
TEST(MeshColorsLayoutTest, TexelCenterIsCentroid) {
  for (int r : {1, 2, 3, 5}) {
    SCOPED_TRACE(r);
    const MeshColors colors(1, r, 1);
    const int n = 200 * r;
    std::vector<Eigen::Vector2d> sum(MeshColors::TexelsPerFace(r), Eigen::Vector2d::Zero());
    std::vector<int> count(MeshColors::TexelsPerFace(r), 0);
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        const double alpha = (a + 0.5) / n, beta = (b + 0.5) / n;
        if (alpha + beta > 1.0) continue;
        const int k = colors.TexelIndex(0, alpha, beta);
        sum[k] += Eigen::Vector2d(alpha, beta);
        ++count[k];
      }
    }
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; i + j <= r; ++j) {
        const int k = MeshColors::LocalIndex(r, i, j);
        const Eigen::Vector2d center = MeshColors::TexelCenter(r, i, j);
        if (i + j == r) {
          EXPECT_EQ(count[k], 0);  // Zero-area texel: its "centroid" is its lattice point.
          EXPECT_NEAR(center.x(), static_cast<double>(i) / r, 1e-15);
          EXPECT_NEAR(center.y(), static_cast<double>(j) / r, 1e-15);
          continue;
        }
        ASSERT_GT(count[k], 0);
        const Eigen::Vector2d mean = sum[k] / count[k];
        EXPECT_NEAR(mean.x(), center.x(), 2e-3 / r) << i << "," << j;
        EXPECT_NEAR(mean.y(), center.y(), 2e-3 / r) << i << "," << j;
      }
    }
  }
  EXPECT_EQ(MeshColors::TexelCenter(0, 0, 0), Eigen::Vector2d(1.0 / 3.0, 1.0 / 3.0));
}

MeshColors RandomColors(int faces, int r, int channels) {
  MeshColors colors(faces, r, channels);
  Sampler sampler(1, 2, 3, 4);
  // float-representable values, so that the float32 file round trip is exact.
  for (double& v : colors.values()) v = static_cast<float>(sampler.Next1D());
  return colors;
}

TEST(MeshColorsFileTest, RoundTrip) {
  testing::TempDir tmp;
  const MeshColors colors = RandomColors(7, 3, 3);
  const std::string path = tmp.Join("a.meshcolors");
  ASSERT_TRUE(WriteMeshColors(path, colors, {"r", "g", "b"}).ok());
  MeshColors read;
  std::vector<std::string> names;
  ASSERT_TRUE(ReadMeshColors(path, &read, &names).ok());
  EXPECT_EQ(read.num_faces(), 7);
  EXPECT_EQ(read.resolution(), 3);
  EXPECT_EQ(read.channels(), 3);
  EXPECT_EQ(read.values(), colors.values());
  EXPECT_EQ(names, (std::vector<std::string>{"r", "g", "b"}));

  // The documented layout: one JSON line, then little-endian float32 in texel order.
  std::ifstream in(path, std::ios::binary);
  std::string header;
  std::getline(in, header);
  const nlohmann::json json = nlohmann::json::parse(header);
  EXPECT_EQ(json["format"], "sft-mesh-colors/1");
  EXPECT_EQ(json["num_faces"], 7);
  EXPECT_EQ(json["resolution"], 3);
  EXPECT_EQ(json["channels"], 3);
  EXPECT_EQ(json["dtype"], "float32");
  EXPECT_EQ(json["byte_order"], "little");
  std::string payload((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(payload.size(), 4u * 7 * 10 * 3);
  const int k = ReportIndex(5, 3, 2, 1);  // texel (2, 1) of face 5, channel 2.
  float value;
  std::memcpy(&value, payload.data() + 4 * (3 * k + 2), 4);
  EXPECT_EQ(value, colors.texel(k)[2]);
}

TEST(MeshColorsFileTest, WrongNameCountFails) {
  testing::TempDir tmp;
  const Status status =
      WriteMeshColors(tmp.Join("a.meshcolors"), RandomColors(1, 1, 3), {"r", "g"});
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("channel names"));
}

TEST(MeshColorsFileTest, MalformedFilesNameFileAndField) {
  const std::string good_header =
      R"({"format":"sft-mesh-colors/1","num_faces":2,"resolution":1,"channels":1,)"
      R"("names":["x"],"dtype":"float32","byte_order":"little"})";
  const std::string payload(4 * 2 * 3, '\0');  // 2 faces × 3 texels × 1 channel, zeros.
  auto with = [&](const std::string& key, const std::string& value) {
    nlohmann::json json = nlohmann::json::parse(good_header);
    if (value.empty()) {
      json.erase(key);
    } else {
      json[key] = nlohmann::json::parse(value);
    }
    return json.dump() + "\n" + payload;
  };
  float nan = std::nanf("");
  std::string nan_payload = payload;
  std::memcpy(&nan_payload[8], &nan, 4);
  struct Case {
    std::string contents;
    std::string expected;
  } cases[] = {
      {good_header, "no one-line JSON header"},
      {"{not json\n" + payload, "not valid JSON"},
      {"[1, 2]\n" + payload, "not a JSON object"},
      {with("format", R"("sft-mesh-colors/2")"), "\"format\""},
      {with("num_faces", ""), "\"num_faces\": missing"},
      {with("num_faces", "-1"), "\"num_faces\""},
      {with("resolution", "1.5"), "\"resolution\""},
      {with("channels", "0"), "\"channels\""},
      {with("dtype", R"("float64")"), "\"dtype\""},
      {with("byte_order", R"("big")"), "\"byte_order\""},
      {with("names", R"(["x", "y"])"), "\"names\""},
      {with("names", "[3]"), "\"names\""},
      {good_header + "\n" + payload.substr(4), "payload has 20 bytes"},
      {good_header + "\n" + payload + "x", "payload has 25 bytes"},
      {good_header + "\n" + nan_payload, "non-finite value at texel 2"},
  };
  testing::TempDir tmp;
  int n = 0;
  for (const Case& c : cases) {
    const std::string path = tmp.Join("bad" + std::to_string(n++) + ".meshcolors");
    {
      std::ofstream out(path, std::ios::binary);
      out << c.contents;
    }
    SCOPED_TRACE(c.expected);
    MeshColors colors;
    const Status status = ReadMeshColors(path, &colors);
    ASSERT_FALSE(status.ok());
    EXPECT_THAT(status.message(), HasSubstr(path));
    EXPECT_THAT(status.message(), HasSubstr(c.expected));
  }
  // The good header itself reads.
  {
    std::ofstream out(tmp.Join("good.meshcolors"), std::ios::binary);
    out << good_header << "\n" << payload;
  }
  MeshColors colors;
  EXPECT_TRUE(ReadMeshColors(tmp.Join("good.meshcolors"), &colors).ok());
  const Status missing = ReadMeshColors(tmp.Join("missing.meshcolors"), &colors);
  ASSERT_FALSE(missing.ok());
  EXPECT_THAT(missing.message(), HasSubstr("missing.meshcolors"));
}

// ParseMeshColors (the fuzzed entry point) is ReadMeshColors without the file read.
TEST(MeshColorsFileTest, ParseMatchesRead) {
  testing::TempDir tmp;
  const MeshColors colors = RandomColors(3, 2, 1);
  const std::string path = tmp.Join("r.meshcolors");
  ASSERT_TRUE(WriteMeshColors(path, colors, {"roughness"}).ok());
  std::ifstream in(path, std::ios::binary);
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  MeshColors parsed;
  std::vector<std::string> names;
  ASSERT_TRUE(ParseMeshColors(data, "buffer.meshcolors", &parsed, &names).ok());
  EXPECT_EQ(parsed.values(), colors.values());
  EXPECT_EQ(names, std::vector<std::string>{"roughness"});
  const Status truncated =
      ParseMeshColors(data.substr(0, data.size() - 1), "buffer.meshcolors", &parsed);
  ASSERT_FALSE(truncated.ok());
  EXPECT_THAT(truncated.message(), ::testing::StartsWith("buffer.meshcolors: payload has"));
}

}  // namespace
}  // namespace sft
