// Materials: constants, the JSON forms (inline and file), texture sampling into mesh colors as
// area averages, procedural patterns, save/load, and that every error names its field.
#include "src/geometry/material.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "src/core/image.h"
#include "src/image/image_io.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using ::testing::HasSubstr;

std::string MeshesDir() { return testing::DataDir() + "/meshes"; }
std::string SpotDir() { return testing::DataDir() + "/cycles/spot_textured_point/gt"; }

// data/meshes/quad_z0_2x2_2f.obj with per-vertex UVs: corner (x, y) of [-1, 1]² gets
// uv = lo + (hi − lo)·((x, y) + 1)/2.
TriMesh UvQuad(const testing::TempDir& tmp, double lo, double hi) {
  TriMesh quad;
  EXPECT_TRUE(ReadMesh(MeshesDir() + "/quad_z0_2x2_2f.obj", &quad).ok());
  std::string obj;
  for (TriMesh::VertexHandle vh : quad.vertices()) {
    const TriMesh::Point& p = quad.point(vh);
    obj += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) +
           "\n";
    obj += "vt " + std::to_string(lo + (hi - lo) * (p[0] + 1) / 2) + " " +
           std::to_string(lo + (hi - lo) * (p[1] + 1) / 2) + "\n";
  }
  obj += "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";  // The fixture's faces.
  const std::string path = tmp.Join("uv_quad.obj");
  testing::WriteTestFile(path, obj);
  TriMesh mesh;
  MeshReport report;
  EXPECT_TRUE(ReadMesh(path, &mesh, &report).ok());
  EXPECT_TRUE(report.has_texcoords);
  return mesh;
}

TriMesh ReadFixture(const std::string& name) {
  TriMesh mesh;
  EXPECT_TRUE(ReadMesh(MeshesDir() + "/" + name, &mesh).ok());
  return mesh;
}

TEST(MaterialTest, ConstantMaterial) {
  const Material m = ConstantMaterial(4, Eigen::Vector3d(0.1, 0.2, 0.3), 0.4, 0.5, 2);
  EXPECT_EQ(m.albedo.num_faces(), 4);
  EXPECT_EQ(m.albedo.resolution(), 2);
  EXPECT_EQ(m.albedo.channels(), 3);
  EXPECT_EQ(m.roughness.channels(), 1);
  EXPECT_EQ(m.roughness.resolution(), 2);
  for (int k = 0; k < m.albedo.num_texels(); ++k) {
    EXPECT_EQ(m.albedo.texel(k)[0], 0.1);
    EXPECT_EQ(m.albedo.texel(k)[1], 0.2);
    EXPECT_EQ(m.albedo.texel(k)[2], 0.3);
    EXPECT_EQ(m.roughness.texel(k)[0], 0.4);
  }
  EXPECT_EQ(m.specular, 0.5);
  EXPECT_EQ(m.fresnel, FresnelMode::kConstant);
}

TEST(MaterialTest, EmptySpecIsDefault) {
  const TriMesh mesh = ReadFixture("cube_2x2x2_12f.obj");
  Material m;
  ASSERT_TRUE(LoadMaterial("  ", mesh, &m).ok());
  EXPECT_EQ(m.albedo.num_faces(), 12);
  EXPECT_EQ(m.albedo.resolution(), 1);
  EXPECT_EQ(m.albedo.texel(5)[1], 0.7);
  EXPECT_EQ(m.roughness.texel(5)[0], 0.5);
  EXPECT_EQ(m.specular, 0.0);
}

TEST(MaterialTest, InlineAndFileJsonAgree) {
  const TriMesh mesh = ReadFixture("cube_2x2x2_12f.obj");
  const std::string json =
      R"({"albedo": [0.2, 0.4, 0.6], "roughness": 0.25, "specular": 0.5, "fresnel": "schlick",
          "resolution": 3})";
  testing::TempDir tmp;
  testing::WriteTestFile(tmp.Join("m.json"), json);
  Material inline_material, file_material;
  ASSERT_TRUE(LoadMaterial(json, mesh, &inline_material).ok());
  ASSERT_TRUE(LoadMaterial(tmp.Join("m.json"), mesh, &file_material).ok());
  for (const Material* m : {&inline_material, &file_material}) {
    EXPECT_EQ(m->albedo.resolution(), 3);
    EXPECT_EQ(m->albedo.num_faces(), 12);
    EXPECT_EQ(m->albedo.texel(7)[2], 0.6);
    EXPECT_EQ(m->roughness.resolution(), 3);
    EXPECT_EQ(m->roughness.texel(7)[0], 0.25);
    EXPECT_EQ(m->specular, 0.5);
    EXPECT_EQ(m->fresnel, FresnelMode::kSchlick);
  }
  EXPECT_EQ(inline_material.albedo.values(), file_material.albedo.values());
}

// SaveMaterial writes two mesh-colors files and a JSON naming them relative to itself; loading
// it from another working directory gives the same material (float32 storage).
TEST(MaterialTest, SaveLoadRoundTrip) {
  const TriMesh mesh = ReadFixture("cube_2x2x2_12f.obj");
  Material m = ConstantMaterial(12, Eigen::Vector3d(0.5, 0.5, 0.5), 0.3, 0.25, 2);
  for (int k = 0; k < m.albedo.num_texels(); ++k) {
    m.albedo.texel(k)[0] = static_cast<float>(k) / m.albedo.num_texels();
    m.roughness.texel(k)[0] =
        static_cast<float>(1.0 - static_cast<double>(k) / m.albedo.num_texels());
  }
  m.fresnel = FresnelMode::kSchlick;
  testing::TempDir tmp;
  const std::string json_path = tmp.Join("out/material.json");
  ASSERT_TRUE(SaveMaterial(json_path, m).ok());
  EXPECT_TRUE(std::filesystem::exists(tmp.Join("out/material_albedo.meshcolors")));
  EXPECT_TRUE(std::filesystem::exists(tmp.Join("out/material_roughness.meshcolors")));
  Material read;
  ASSERT_TRUE(LoadMaterial(json_path, mesh, &read).ok());
  EXPECT_EQ(read.albedo.values(), m.albedo.values());
  EXPECT_EQ(read.roughness.values(), m.roughness.values());
  EXPECT_EQ(read.specular, 0.25);
  EXPECT_EQ(read.fresnel, FresnelMode::kSchlick);
  // A mesh with another face count is refused, naming the field.
  const TriMesh quad = ReadFixture("quad_z0_2x2_2f.obj");
  const Status status = LoadMaterial(json_path, quad, &read);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("\"mesh_colors\""));
  EXPECT_THAT(status.message(), HasSubstr("12 faces, the mesh has 2"));
}

// Relative paths: against the JSON file's directory, or the working directory for inline JSON.
TEST(MaterialTest, RelativePaths) {
  const TriMesh mesh = ReadFixture("cube_2x2x2_12f.obj");
  testing::TempDir tmp;
  ASSERT_TRUE(SaveMaterial(tmp.Join("sub/material.json"),
                           ConstantMaterial(12, Eigen::Vector3d(0.1, 0.2, 0.3), 0.4, 0.0))
                  .ok());
  Material m;
  const std::string inline_json = R"({"mesh_colors": "sub/material_albedo.meshcolors"})";
  const Status from_elsewhere = LoadMaterial(inline_json, mesh, &m);
  EXPECT_FALSE(from_elsewhere.ok());
  EXPECT_THAT(from_elsewhere.message(), HasSubstr("sub/material_albedo.meshcolors"));
  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(tmp.path());
  const Status inline_status = LoadMaterial(inline_json, mesh, &m);
  // A relative JSON path: its files are found next to it.
  Material from_file;
  const Status file_status = LoadMaterial("sub/material.json", mesh, &from_file);
  std::filesystem::current_path(cwd);
  ASSERT_TRUE(inline_status.ok()) << inline_status.message();
  ASSERT_TRUE(file_status.ok()) << file_status.message();
  EXPECT_FLOAT_EQ(m.albedo.texel(3)[1], 0.2f);
  EXPECT_EQ(m.roughness.texel(3)[0], 0.5);  // Not given inline: the default.
  EXPECT_FLOAT_EQ(from_file.roughness.texel(3)[0], 0.4f);
}

// A texture whose pixel values are linear in the pixel index has a bilinear interpolant that is
// linear in (u, v) away from the wrap-around border, so the area average over each texel's
// region equals the texture at the region's centroid, the UV of TexelCenter. The UVs map the quad
// into [0.25, 0.75]² of an 8×8 texture: pixel coordinates 1.5..5.5, clear of the border.
// Tolerance 1e-6: pixel values are stored as float32 (relative error 6e-8) and the quadrature
// integrates linear functions exactly up to rounding.
TEST(MaterialTest, TextureLinearGradientIsExactAreaAverage) {
  testing::TempDir tmp;
  const TriMesh mesh = UvQuad(tmp, 0.25, 0.75);
  Image texture(8, 8, 3);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      texture.at(x, y, 0) = 0.1f + 0.1f * x;
      texture.at(x, y, 1) = 0.05f + 0.1f * y;
      texture.at(x, y, 2) = 0.5f;
    }
  }
  ASSERT_TRUE(WriteExr(tmp.Join("tex.exr"), texture).ok());
  Material m;
  ASSERT_TRUE(LoadMaterial(R"({"albedo_texture": ")" + tmp.Join("tex.exr") +
                               R"(", "resolution": 3, "roughness": 0.2})",
                           mesh, &m)
                  .ok());
  ASSERT_EQ(m.albedo.resolution(), 3);
  EXPECT_EQ(m.roughness.resolution(), 3);
  EXPECT_EQ(m.roughness.texel(0)[0], 0.2);
  const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
  const int r = 3;
  for (int f = 0; f < 2; ++f) {
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; i + j <= r; ++j) {
        const Eigen::Vector2d ab = MeshColors::TexelCenter(r, i, j);
        const Eigen::Vector2d uv =
            (1 - ab.x() - ab.y()) * uvs[3 * f] + ab.x() * uvs[3 * f + 1] + ab.y() * uvs[3 * f + 2];
        const double x = uv.x() * 8 - 0.5, y = (1 - uv.y()) * 8 - 0.5;  // v = 0 is the bottom.
        const double* texel =
            m.albedo.texel(f * MeshColors::TexelsPerFace(r) + MeshColors::LocalIndex(r, i, j));
        EXPECT_NEAR(texel[0], 0.1 + 0.1 * x, 1e-6) << f << " " << i << " " << j;
        EXPECT_NEAR(texel[1], 0.05 + 0.1 * y, 1e-6) << f << " " << i << " " << j;
        EXPECT_NEAR(texel[2], 0.5, 1e-6);
      }
    }
  }
}

// Bilinear lookup with repeat wrap, v flipped: the reference for the area-average test below,
// written independently of the implementation.
double Bilinear(const Image& image, double u, double v) {
  const double x = u * image.width - 0.5, y = (1 - v) * image.height - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int xi, int yi) {
    xi = ((xi % image.width) + image.width) % image.width;
    yi = ((yi % image.height) + image.height) % image.height;
    return static_cast<double>(image.at(xi, yi, 0));
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// A 2×2 checkerboard over the whole quad (UVs [0, 1]², so the repeat wrap matters everywhere):
// the bilinear interpolant is not linear, and each texel must hold its area average. The
// reference integrates with a midpoint grid of 800² cells per unit of barycentric coordinates
// (400 per texture pixel), whose texel boundaries fall on cell edges except the edge α + β = 1,
// where the half cells get half weight. The texture's kinks (pixel centres at u, v = 1/4, 3/4)
// fall on cell edges, where the midpoint rule is exact for bilinear pieces: the reference agrees
// with the (exact) implementation to 1e-14, measured at this n and 2n. Tolerance 1e-6, far below
// the 1e-2 error of the sampling quadrature this replaced. A point value at the texel centre misses
// by > 0.05 here (checked, so that the test can tell the two apart).
TEST(MaterialTest, TextureCheckerIsAreaAverage) {
  testing::TempDir tmp;
  const TriMesh mesh = UvQuad(tmp, 0.0, 1.0);
  Image texture(2, 2, 1);
  texture.at(0, 0) = 1.0f;
  texture.at(1, 1) = 1.0f;
  ASSERT_TRUE(WriteExr(tmp.Join("checker.exr"), texture).ok());
  const int r = 2;
  Material m;
  ASSERT_TRUE(
      LoadMaterial(R"({"albedo_texture": ")" + tmp.Join("checker.exr") + R"(", "resolution": 2})",
                   mesh, &m)
          .ok());
  const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
  const int n = 400 * r;
  double max_centre_error = 0.0;
  for (int f = 0; f < 2; ++f) {
    std::vector<double> sum(MeshColors::TexelsPerFace(r), 0.0);
    std::vector<int> count(MeshColors::TexelsPerFace(r), 0);
    const MeshColors one_face(1, r, 1);
    auto uv_at = [&](double a, double b) {
      return Eigen::Vector2d((1 - a - b) * uvs[3 * f] + a * uvs[3 * f + 1] + b * uvs[3 * f + 2]);
    };
    std::vector<double> weight(MeshColors::TexelsPerFace(r), 0.0);
    for (int a = 0; a < n; ++a) {
      for (int b = 0; a + b < n; ++b) {
        const double alpha = (a + 0.5) / n, beta = (b + 0.5) / n;
        const double w = a + b == n - 1 ? 0.5 : 1.0;  // Cells cut in half by α + β = 1.
        const Eigen::Vector2d uv = uv_at(alpha, beta);
        const int k = one_face.TexelIndex(0, alpha, beta);
        sum[k] += w * Bilinear(texture, uv.x(), uv.y());
        weight[k] += w;
        ++count[k];
      }
    }
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; i + j <= r; ++j) {
        const int local = MeshColors::LocalIndex(r, i, j);
        const Eigen::Vector2d centre = MeshColors::TexelCenter(r, i, j);
        const Eigen::Vector2d uv = uv_at(centre.x(), centre.y());
        const double at_centre = Bilinear(texture, uv.x(), uv.y());
        // Zero-area texels hold the texture at their lattice point.
        const double expected = count[local] > 0 ? sum[local] / weight[local] : at_centre;
        const double* texel = m.albedo.texel(f * MeshColors::TexelsPerFace(r) + local);
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(texel[c], expected, 1e-6) << "face " << f << " texel " << i << "," << j;
        }
        max_centre_error = std::max(max_centre_error, std::abs(at_centre - expected));
      }
    }
  }
  // The test can tell an area average from a point sample.
  EXPECT_GT(max_centre_error, 0.05);
}

// 8-bit PNGs are sRGB-decoded by default or with "srgb", kept as stored with "linear".
TEST(MaterialTest, TextureColorspace) {
  testing::TempDir tmp;
  const TriMesh mesh = UvQuad(tmp, 0.0, 1.0);
  Image texture(4, 4, 3, 128.0f / 255.0f);
  ASSERT_TRUE(WritePng(tmp.Join("grey.png"), texture, /*srgb=*/false).ok());
  const std::string tex = tmp.Join("grey.png");
  struct Case {
    std::string extra;
    double expected;
  } cases[] = {{"", 128.0 / 255.0},  // default: as stored, even for PNG (CLI contract).
               {R"(, "colorspace": "srgb")", SrgbToLinear(128.0f / 255.0f)},
               {R"(, "colorspace": "linear")", 128.0 / 255.0}};
  for (const Case& c : cases) {
    Material m;
    ASSERT_TRUE(
        LoadMaterial(R"({"albedo_texture": ")" + tex + "\"" + c.extra + "}", mesh, &m).ok());
    EXPECT_EQ(m.albedo.resolution(), 8);  // The default for textures.
    for (double v : m.albedo.values()) ASSERT_NEAR(v, c.expected, 1e-6) << c.extra;
  }
}

// Spot: the UV-area-weighted mean of the sampled texels equals the mean of the texture over the
// UV region the mesh uses. The reference marks texture pixels whose centre lies in some UV
// triangle; the two differ by pixels cut by island borders (half covered, and blended with the
// atlas background by bilinear lookup): measured 1.7e-4; tolerance 2e-3. To show that the test
// can fail, the region with v not flipped (the classic UV mistake) must have a mean more than
// 0.01 away (measured 0.03).
TEST(MaterialTest, SpotTextureMeanMatchesUvRegion) {
  TriMesh mesh;
  ASSERT_TRUE(ReadMesh(SpotDir() + "/mesh_uv.obj", &mesh).ok());
  Material m;
  ASSERT_TRUE(LoadMaterial(R"({"albedo_texture": ")" + SpotDir() +
                               R"(/texture.png", "colorspace": "linear"})",
                           mesh, &m)
                  .ok());
  const int r = m.albedo.resolution();
  ASSERT_EQ(r, 8);
  const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
  const int num_faces = static_cast<int>(mesh.n_faces());
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double total_area = 0.0;
  for (int f = 0; f < num_faces; ++f) {
    const Eigen::Vector2d e1 = uvs[3 * f + 1] - uvs[3 * f], e2 = uvs[3 * f + 2] - uvs[3 * f];
    const double area = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    total_area += area;
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; i + j <= r; ++j) {
        // Fraction of the face in the texel: a unit square (2/r²), a half square (1/r²) or 0.
        const double fraction = i + j <= r - 2 ? 2.0 / (r * r) : i + j == r - 1 ? 1.0 / (r * r) : 0;
        const double* t =
            m.albedo.texel(f * MeshColors::TexelsPerFace(r) + MeshColors::LocalIndex(r, i, j));
        weighted += area * fraction * Eigen::Vector3d(t[0], t[1], t[2]);
      }
    }
  }
  const Eigen::Vector3d sampled_mean = weighted / total_area;

  Image texture;
  ASSERT_TRUE(ReadImage(SpotDir() + "/texture.png", &texture, /*srgb=*/false).ok());
  auto region_mean = [&](bool flip_v) {
    std::vector<char> covered(static_cast<size_t>(texture.width) * texture.height, 0);
    for (int f = 0; f < num_faces; ++f) {
      Eigen::Vector2d p[3];
      for (int c = 0; c < 3; ++c) {
        const Eigen::Vector2d uv = uvs[3 * f + c];
        p[c] = Eigen::Vector2d(uv.x() * texture.width,
                               (flip_v ? 1 - uv.y() : uv.y()) * texture.height);
      }
      const Eigen::Vector2d lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]);
      const Eigen::Vector2d hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
      auto edge = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& q) {
        return (b.x() - a.x()) * (q.y() - a.y()) - (b.y() - a.y()) * (q.x() - a.x());
      };
      for (int y = std::max(0, static_cast<int>(lo.y()));
           y <= std::min(texture.height - 1, static_cast<int>(hi.y())); ++y) {
        for (int x = std::max(0, static_cast<int>(lo.x()));
             x <= std::min(texture.width - 1, static_cast<int>(hi.x())); ++x) {
          const Eigen::Vector2d q(x + 0.5, y + 0.5);
          const double d0 = edge(p[0], p[1], q), d1 = edge(p[1], p[2], q), d2 = edge(p[2], p[0], q);
          if ((d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0)) {
            covered[static_cast<size_t>(y) * texture.width + x] = 1;
          }
        }
      }
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (int y = 0; y < texture.height; ++y) {
      for (int x = 0; x < texture.width; ++x) {
        if (!covered[static_cast<size_t>(y) * texture.width + x]) continue;
        for (int c = 0; c < 3; ++c) sum[c] += texture.at(x, y, texture.channels >= 3 ? c : 0);
        ++count;
      }
    }
    return Eigen::Vector3d(sum / std::max(count, 1));
  };
  const Eigen::Vector3d reference = region_mean(/*flip_v=*/true);
  const Eigen::Vector3d unflipped = region_mean(/*flip_v=*/false);
  EXPECT_LT((sampled_mean - reference).cwiseAbs().maxCoeff(), 2e-3);
  EXPECT_GT((unflipped - reference).cwiseAbs().maxCoeff(), 0.01);
}

void ExpectInBox(const MeshColors& colors, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  for (int k = 0; k < colors.num_texels(); ++k) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_GE(colors.texel(k)[c], std::min(a[c], b[c]) - 1e-12);
      ASSERT_LE(colors.texel(k)[c], std::max(a[c], b[c]) + 1e-12);
    }
  }
}

double StdDev(const std::vector<double>& v, int stride, int offset) {
  double sum = 0, sum2 = 0;
  int n = 0;
  for (size_t k = offset; k < v.size(); k += stride, ++n) {
    sum += v[k];
    sum2 += v[k] * v[k];
  }
  const double mean = sum / n;
  return std::sqrt(std::max(0.0, sum2 / n - mean * mean));
}

// Procedural patterns are deterministic in the seed, stay between the two colours (and in the
// roughness range), and are not constant: the red channel's spread over texels is > 10% of the
// colour difference (a uniform mix would give ~29%, a constant 0).
TEST(MaterialTest, ProceduralDeterministicAndInRange) {
  const TriMesh mesh = ReadFixture("icosphere_r1_1280f.obj");
  const Eigen::Vector3d c0(0.8, 0.6, 0.4), c1(0.2, 0.1, 0.05);
  for (const char* kind : {"wood", "noise"}) {
    SCOPED_TRACE(kind);
    auto spec = [&](int seed) {
      return std::string(R"({"procedural": ")") + kind +
             R"(", "colors": [[0.8, 0.6, 0.4], [0.2, 0.1, 0.05]], "scale": 6,)"
             R"( "roughness_range": [0.2, 0.6], "resolution": 4, "seed": )" +
             std::to_string(seed) + "}";
    };
    Material a, b, c;
    ASSERT_TRUE(LoadMaterial(spec(3), mesh, &a).ok());
    ASSERT_TRUE(LoadMaterial(spec(3), mesh, &b).ok());
    ASSERT_TRUE(LoadMaterial(spec(4), mesh, &c).ok());
    EXPECT_EQ(a.albedo.resolution(), 4);
    EXPECT_EQ(a.albedo.values(), b.albedo.values());
    EXPECT_EQ(a.roughness.values(), b.roughness.values());
    EXPECT_NE(a.albedo.values(), c.albedo.values());
    ExpectInBox(a.albedo, c0, c1);
    for (double v : a.roughness.values()) {
      ASSERT_GE(v, 0.2 - 1e-12);
      ASSERT_LE(v, 0.6 + 1e-12);
    }
    EXPECT_GT(StdDev(a.albedo.values(), 3, 0), 0.1 * (c0[0] - c1[0]));
    EXPECT_GT(StdDev(a.roughness.values(), 1, 0), 0.1 * 0.4);
    // Without a range, roughness is the constant.
    Material d;
    ASSERT_TRUE(LoadMaterial(std::string(R"({"procedural": ")") + kind + R"(", "roughness": 0.3})",
                             mesh, &d)
                    .ok());
    EXPECT_EQ(d.albedo.resolution(), 8);
    for (double v : d.roughness.values()) ASSERT_EQ(v, 0.3);
  }
}

// A texture much finer than the texel regions is box-filtered to a mip level before sampling
// (memory: docs/design-notes.md 2026-11-24). A 1024² linear gradient on UVs [0.25, 0.75]² at
// resolution 2 is reduced 16× (texel regions 256 pixels across, kept at >= 16); box filtering
// keeps a linear function linear with its samples at the block centres, so each texel must still
// be the value at its region's centroid, which a half-pixel misalignment of the mip would break.
TEST(MaterialTest, ReducedTextureKeepsLinearGradientExact) {
  testing::TempDir tmp;
  const TriMesh mesh = UvQuad(tmp, 0.25, 0.75);
  const int n = 1024;
  Image texture(n, n, 3);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      texture.at(x, y, 0) = (x + 0.5f) / n;
      texture.at(x, y, 1) = (y + 0.5f) / n;
      texture.at(x, y, 2) = 0.5f;
    }
  }
  ASSERT_TRUE(WriteExr(tmp.Join("tex.exr"), texture).ok());
  Material m;
  ASSERT_TRUE(
      LoadMaterial(R"({"albedo_texture": ")" + tmp.Join("tex.exr") + R"(", "resolution": 2})", mesh,
                   &m)
          .ok());
  const std::vector<Eigen::Vector2d> uvs = FaceCornerUvs(mesh);
  const int r = 2;
  for (int f = 0; f < 2; ++f) {
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; i + j <= r; ++j) {
        const Eigen::Vector2d ab = MeshColors::TexelCenter(r, i, j);
        const Eigen::Vector2d uv =
            (1 - ab.x() - ab.y()) * uvs[3 * f] + ab.x() * uvs[3 * f + 1] + ab.y() * uvs[3 * f + 2];
        const double* texel =
            m.albedo.texel(f * MeshColors::TexelsPerFace(r) + MeshColors::LocalIndex(r, i, j));
        EXPECT_NEAR(texel[0], uv.x(), 1e-5) << f << " " << i << " " << j;
        EXPECT_NEAR(texel[1], 1 - uv.y(), 1e-5) << f << " " << i << " " << j;
        EXPECT_NEAR(texel[2], 0.5, 1e-6);
      }
    }
  }
}

// Texture values: non-finite ones are an error naming the pixel; values outside [0, 1] (HDR
// textures) are clamped (and reported in a warning), unlike constants, which are refused.
TEST(MaterialTest, TextureValuesCheckedAndClamped) {
  testing::TempDir tmp;
  const TriMesh mesh = UvQuad(tmp, 0.0, 1.0);
  Image texture(2, 2, 3, 0.5f);
  texture.at(1, 0, 2) = std::nanf("");
  ASSERT_TRUE(WriteExr(tmp.Join("nan.exr"), texture).ok());
  Material m;
  Status status = LoadMaterial(R"({"albedo_texture": ")" + tmp.Join("nan.exr") + R"("})", mesh, &m);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("\"albedo_texture\": " + tmp.Join("nan.exr") +
                                          ": pixel (1, 0) has a non-finite value"));
  ASSERT_TRUE(WriteExr(tmp.Join("hdr.exr"), Image(2, 2, 3, 7.0f)).ok());
  status = LoadMaterial(R"({"albedo_texture": ")" + tmp.Join("hdr.exr") + R"("})", mesh, &m);
  ASSERT_TRUE(status.ok()) << status.message();
  for (double v : m.albedo.values()) EXPECT_EQ(v, 1.0);
}

TEST(MaterialTest, ErrorsNameTheField) {
  testing::TempDir tmp;
  const TriMesh quad = ReadFixture("quad_z0_2x2_2f.obj");  // No UVs.
  const TriMesh uv_quad = UvQuad(tmp, 0.0, 1.0);
  ASSERT_TRUE(WriteExr(tmp.Join("t.exr"), Image(2, 2, 3, 0.5f)).ok());
  ASSERT_TRUE(
      WriteMeshColors(tmp.Join("three.meshcolors"), MeshColors(3, 1, 3, 0.5), {"r", "g", "b"})
          .ok());
  ASSERT_TRUE(WriteMeshColors(tmp.Join("grey.meshcolors"), MeshColors(2, 1, 1, 0.5), {"x"}).ok());
  ASSERT_TRUE(
      WriteMeshColors(tmp.Join("big.meshcolors"), MeshColors(2, 1, 3, 1.5), {"r", "g", "b"}).ok());
  const std::string tex = tmp.Join("t.exr");
  struct Case {
    std::string spec;
    std::vector<std::string> expected;
    bool uv_mesh = false;
  } cases[] = {
      {R"({"albedo": [0.5, 0.5]})", {"\"albedo\"", "3 numbers"}},
      {R"({"albedo": [0.5, 1.5, 0.5]})", {"\"albedo\"", "[0, 1]"}},
      {R"({"albedo": "red"})", {"\"albedo\""}},
      {R"({"roughness": 1.5})", {"\"roughness\"", "[0, 1]"}},
      {R"({"roughness": "x"})", {"\"roughness\""}},
      {R"({"specular": -0.1})", {"\"specular\""}},
      {R"({"specular": 1.5, "fresnel": "schlick"})", {"\"specular\"", "[0, 1]"}},
      {R"({"specular": 1e20})", {"\"specular\"", "[0, 1]", "1e+20"}},  // Gave inf pixels.
      {R"({"specular": 1.5})", {"\"specular\"", "[0, 1]", "1.5"}},
      {R"({"fresnel": "fresnel"})", {"\"fresnel\""}},
      {R"({"resolution": 0})", {"\"resolution\"", "[1, 64]"}},
      {R"({"resolution": 65})", {"\"resolution\""}},
      {R"({"resolution": 2.5})", {"\"resolution\""}},
      {R"({"albdo": [0.5, 0.5, 0.5]})", {"unknown key \"albdo\""}},
      {R"({"albedo": [0.5, 0.5, 0.5], "procedural": "wood"})", {"\"procedural\"", "\"albedo\""}},
      {R"({"albedo": [0.5, 0.5, 0.5], "colorspace": "srgb"})", {"\"colorspace\""}},
      {R"({"albedo": [0.5, 0.5, 0.5], "seed": 3})", {"\"seed\""}},
      {R"({"roughness": 0.5, "roughness_mesh_colors": "x"})", {"\"roughness\""}},
      {R"({"albedo_texture": "missing.png"})", {"\"albedo_texture\"", "missing.png"}, true},
      {R"({"albedo_texture": ")" + tex + R"("})", {"\"albedo_texture\"", "no texture coord"}},
      {R"({"albedo_texture": ")" + tex + R"(", "colorspace": "rgb"})", {"\"colorspace\""}, true},
      {R"({"albedo_texture": 3})", {"\"albedo_texture\""}, true},
      {R"({"mesh_colors": ")" + tmp.Join("three.meshcolors") + R"("})",
       {"\"mesh_colors\"", "3 faces, the mesh has 2"}},
      {R"({"mesh_colors": ")" + tmp.Join("grey.meshcolors") + R"("})",
       {"\"mesh_colors\"", "1 channels, expected 3"}},
      {R"({"mesh_colors": ")" + tmp.Join("big.meshcolors") + R"("})",
       {"\"mesh_colors\"", "outside [0, 1]"}},
      {R"({"mesh_colors": ")" + tmp.Join("nope.meshcolors") + R"("})",
       {"\"mesh_colors\"", "nope.meshcolors", "not found"}},
      {R"({"mesh_colors": ")" + tmp.Join("three.meshcolors") + R"(", "resolution": 2})",
       {"\"resolution\""}},
      {R"({"albedo": [0.5, 0.5, 0.5], "roughness_mesh_colors": ")" + tmp.Join("three.meshcolors") +
           R"("})",
       {"\"roughness_mesh_colors\""}},
      {R"({"procedural": "marble"})", {"\"procedural\"", "marble"}},
      {R"({"procedural": "wood", "colors": [[0.1, 0.1, 0.1]]})", {"\"colors\""}},
      {R"({"procedural": "wood", "colors": [[0.1, 0.1, 0.1], [2, 0, 0]]})", {"\"colors\""}},
      {R"({"procedural": "wood", "scale": 0})", {"\"scale\""}},
      {R"({"procedural": "noise", "seed": -1})", {"\"seed\""}},
      {R"({"procedural": "noise", "roughness_range": [0.6, 0.2]})", {"\"roughness_range\""}},
      {R"({"procedural": "noise", "roughness_range": [0.2, 1.2]})", {"\"roughness_range\""}},
      {R"({"albedo": [0.5, 0.5, 0.5], "roughness_range": [0.2, 0.3]})", {"\"roughness_range\""}},
      {R"({"albedo": })", {"material (inline JSON)", "invalid JSON"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.spec);
    Material m;
    const Status status = LoadMaterial(c.spec, c.uv_mesh ? uv_quad : quad, &m);
    ASSERT_FALSE(status.ok());
    for (const std::string& e : c.expected) EXPECT_THAT(status.message(), HasSubstr(e));
    EXPECT_EQ(status.message().find('\n'), std::string::npos);
  }
  // Errors in a JSON file name the file.
  testing::WriteTestFile(tmp.Join("bad.json"), R"({"roughness": 2})");
  Material m;
  Status status = LoadMaterial(tmp.Join("bad.json"), quad, &m);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(tmp.Join("bad.json") + ": \"roughness\""));
  testing::WriteTestFile(tmp.Join("array.json"), "[1, 2]");
  status = LoadMaterial(tmp.Join("array.json"), quad, &m);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("JSON object"));
  status = LoadMaterial(tmp.Join("absent.json"), quad, &m);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("absent.json"));
}

}  // namespace
}  // namespace sft
