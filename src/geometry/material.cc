#include "src/geometry/material.h"

#include <glog/logging.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "src/core/file_util.h"
#include "src/core/image.h"
#include "src/core/rng.h"
#include "src/io/image_io.h"

namespace sft {
namespace {

using Json = nlohmann::json;

constexpr double kDefaultAlbedo = 0.7;
constexpr double kDefaultRoughness = 0.5;
constexpr int kDefaultSampledResolution = 8;  // albedo_texture and procedural.
constexpr int kMaxResolution = 64;
// Default procedural frequencies, in features across the bounding-box diagonal.
constexpr double kDefaultWoodScale = 10.0;
constexpr double kDefaultNoiseScale = 4.0;

// Where errors point: the JSON file's path or "material (inline JSON)".
class Context {
 public:
  explicit Context(std::string where) : where_(std::move(where)) {}
  Status Error(const std::string& field, const std::string& what) const {
    return Status::Error(where_ + ": \"" + field + "\": " + what);
  }
  Status Error(const std::string& what) const { return Status::Error(where_ + ": " + what); }

 private:
  std::string where_;
};

std::string FormatNumber(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", v);
  return buffer;
}

Status ReadNumber(const Context& ctx, const Json& json, const std::string& field, double lo,
                  double hi, double* value) {
  const Json& v = json.at(field);
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo ||
      v.get<double>() > hi) {
    std::string range =
        "[" + FormatNumber(lo) + ", " + (std::isinf(hi) ? "inf)" : FormatNumber(hi) + "]");
    return ctx.Error(field, "expected a number in " + range + ", got " + v.dump());
  }
  *value = v.get<double>();
  return Status::Ok();
}

Status ParseColor(const Context& ctx, const std::string& field, const Json& v,
                  Eigen::Vector3d* color) {
  if (!v.is_array() || v.size() != 3) {
    return ctx.Error(field, "expected 3 numbers in [0, 1], got " + v.dump());
  }
  for (int c = 0; c < 3; ++c) {
    if (!v[c].is_number() || !(v[c].get<double>() >= 0.0 && v[c].get<double>() <= 1.0)) {
      return ctx.Error(field, "expected 3 numbers in [0, 1], got " + v.dump());
    }
    (*color)[c] = v[c].get<double>();
  }
  return Status::Ok();
}

Status ReadString(const Context& ctx, const Json& json, const std::string& field,
                  std::string* value) {
  const Json& v = json.at(field);
  if (!v.is_string() || v.get<std::string>().empty()) {
    return ctx.Error(field, "expected a non-empty string, got " + v.dump());
  }
  *value = v.get<std::string>();
  return Status::Ok();
}

void FillConstant(int num_faces, int resolution, const double* value, int channels,
                  MeshColors* colors) {
  *colors = MeshColors(num_faces, resolution, channels);
  for (int k = 0; k < colors->num_texels(); ++k) {
    for (int c = 0; c < channels; ++c) colors->texel(k)[c] = value[c];
  }
}

// ---- Texture sampling ---------------------------------------------------------------------------

// A linear RGB texture with repeat-wrapped bilinear lookup in OBJ/Blender UV convention: u to the
// right, v up (v = 0 is the bottom row of the image), pixel centres at half-integers. Works in
// "pixel-centre coordinates" (x, y) = (u·W − 1/2, (1 − v)·H − 1/2), in which pixel (px, py) sits at
// the integer point (px, py) and the bilinear interpolant is bilinear on each unit cell.
class Texture {
 public:
  // `image` holds linear values (see PrepareTexture); it is kept as is (floats, no per-pixel
  // copy: an 8192² texture is 0.8–1 GB already).
  explicit Texture(Image image)
      : width_(image.width), height_(image.height), image_(std::move(image)) {}

  Eigen::Vector2d ToPixel(const Eigen::Vector2d& uv) const {
    return Eigen::Vector2d(uv.x() * width_ - 0.5, (1.0 - uv.y()) * height_ - 0.5);
  }

  // The interpolant at pixel-centre coordinates `p`.
  Eigen::Vector3d Sample(const Eigen::Vector2d& p) const {
    const double x0 = std::floor(p.x()), y0 = std::floor(p.y());
    return InCell(x0, y0, p.x() - x0, p.y() - y0);
  }

  // The interpolant in cell [cx, cx+1] × [cy, cy+1] at local coordinates (s, t) ∈ [0, 1]².
  Eigen::Vector3d InCell(double cx, double cy, double s, double t) const {
    const int ix = Wrap(cx, width_), iy = Wrap(cy, height_);
    const int ix1 = ix + 1 == width_ ? 0 : ix + 1;
    const int iy1 = iy + 1 == height_ ? 0 : iy + 1;
    return (1 - t) * ((1 - s) * At(ix, iy) + s * At(ix1, iy)) +
           t * ((1 - s) * At(ix, iy1) + s * At(ix1, iy1));
  }

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  static int Wrap(double i, int n) {
    const double m = std::fmod(i, static_cast<double>(n));
    const int k = static_cast<int>(m < 0 ? m + n : m);
    return k >= n ? 0 : k;
  }
  // Grey images replicate their channel; alpha (4th channel) is ignored.
  Eigen::Vector3d At(int x, int y) const {
    const float* p = &image_.data[image_.Index(x, y)];
    return image_.channels >= 3 ? Eigen::Vector3d(p[0], p[1], p[2])
                                : Eigen::Vector3d::Constant(p[0]);
  }

  int width_, height_;
  Image image_;
};

using Polygon = std::vector<Eigen::Vector2d>;

// Sutherland–Hodgman clip of a convex polygon to the half plane sign·(p[axis] − bound) ≥ 0.
void ClipHalfPlane(const Polygon& in, int axis, double bound, double sign, Polygon* out) {
  out->clear();
  const size_t n = in.size();
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector2d& a = in[k];
    const Eigen::Vector2d& b = in[(k + 1) % n];
    const double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
    if (da >= 0) out->push_back(a);
    if ((da >= 0) != (db >= 0)) out->push_back(a + (da / (da - db)) * (b - a));
  }
}

// Exact integral of the bilinear texture over a convex polygon given in pixel-centre coordinates,
// and the polygon's signed area (the texel value is their ratio, so orientation cancels). The
// polygon is clipped to every unit cell it overlaps; in a cell the interpolant is a polynomial
// of degree 2 (terms 1, s, t, st), which the edge-midpoint rule integrates exactly over each
// triangle of a fan of the clipped piece. Returns false (nothing computed) when the polygon
// spans more than `max_cells` cells.
bool IntegratePolygon(const Texture& texture, const Polygon& polygon, int64_t max_cells,
                      Eigen::Vector3d* integral, double* area) {
  Eigen::Vector2d lo = polygon[0], hi = polygon[0];
  for (const Eigen::Vector2d& p : polygon) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double x0 = std::floor(lo.x()), x1 = std::floor(hi.x());
  const double y0 = std::floor(lo.y()), y1 = std::floor(hi.y());
  if ((x1 - x0 + 1) * (y1 - y0 + 1) > static_cast<double>(max_cells)) return false;
  *integral = Eigen::Vector3d::Zero();
  *area = 0.0;
  Polygon row, row_tmp, cell, cell_tmp;
  for (double cy = y0; cy <= y1; ++cy) {
    ClipHalfPlane(polygon, 1, cy, 1.0, &row_tmp);
    ClipHalfPlane(row_tmp, 1, cy + 1, -1.0, &row);
    if (row.size() < 3) continue;
    for (double cx = x0; cx <= x1; ++cx) {
      ClipHalfPlane(row, 0, cx, 1.0, &cell_tmp);
      ClipHalfPlane(cell_tmp, 0, cx + 1, -1.0, &cell);
      if (cell.size() < 3) continue;
      auto f = [&](const Eigen::Vector2d& p) {
        return texture.InCell(cx, cy, std::min(std::max(p.x() - cx, 0.0), 1.0),
                              std::min(std::max(p.y() - cy, 0.0), 1.0));
      };
      for (size_t k = 1; k + 1 < cell.size(); ++k) {
        const Eigen::Vector2d &a = cell[0], &b = cell[k], &c = cell[k + 1];
        const Eigen::Vector2d e1 = b - a, e2 = c - a;
        const double signed_area = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
        *integral += signed_area / 3.0 * (f(0.5 * (a + b)) + f(0.5 * (b + c)) + f(0.5 * (c + a)));
        *area += signed_area;
      }
    }
  }
  return true;
}

// Fills `albedo` (resolution r) with, for each texel, the area average of the bilinear texture
// over the part of the face's UV triangle that maps to the texel (MeshColors::TexelCenter
// describes the parts: a unit square of the texel grid, the half square along the edge α + β = 1,
// or, for the zero-area texels i + j = r, just a lattice point, where the texture is evaluated).
// Since barycentric → UV is affine, this is also the area average over the surface, which is what
// a renderer averaging over a pixel sees. The integral is exact (see IntegratePolygon). Regions
// spanning more than kMaxCells texture cells (UVs repeating the texture many times over one texel)
// fall back to a 64²-point centroid rule; faces with zero UV area get the point value.
void SampleTexture(const Texture& texture, const std::vector<Eigen::Vector2d>& corner_uvs,
                   int num_faces, int r, MeshColors* albedo) {
  const int64_t max_cells = 4 * static_cast<int64_t>(texture.width()) * texture.height() + 4096;
  *albedo = MeshColors(num_faces, r, 3);
  // Faces are independent and each texel is a pure function of its face: parallel and still
  // deterministic.
  tbb::parallel_for(0, num_faces, [&](int f) {
    const Eigen::Vector2d p0 = texture.ToPixel(corner_uvs[3 * f]);
    const Eigen::Vector2d p1 = texture.ToPixel(corner_uvs[3 * f + 1]);
    const Eigen::Vector2d p2 = texture.ToPixel(corner_uvs[3 * f + 2]);
    // Texel-grid coordinates (x, y) = r·(α, β) to pixel-centre coordinates.
    auto to_pixel = [&](double x, double y) -> Eigen::Vector2d {
      const double alpha = x / r, beta = y / r;
      return (1.0 - alpha - beta) * p0 + alpha * p1 + beta * p2;
    };
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; i + j <= r; ++j) {
        Polygon region;
        if (i + j <= r - 2) {
          region = {to_pixel(i, j), to_pixel(i + 1, j), to_pixel(i + 1, j + 1), to_pixel(i, j + 1)};
        } else if (i + j == r - 1) {
          region = {to_pixel(i, j), to_pixel(i + 1, j), to_pixel(i, j + 1)};
        }
        const Eigen::Vector2d centre = MeshColors::TexelCenter(r, i, j);
        Eigen::Vector3d value = texture.Sample(to_pixel(r * centre.x(), r * centre.y()));
        if (!region.empty()) {
          Eigen::Vector3d integral;
          double area = 0.0;
          if (IntegratePolygon(texture, region, max_cells, &integral, &area)) {
            // Zero UV area (degenerate mapping): keep the point value.
            if (std::abs(area) > 1e-12) value = integral / area;
          } else {
            // Centroid rule on a 64×64 subdivision of the region's (up to two) triangles.
            constexpr int m = 64;
            Eigen::Vector3d sum = Eigen::Vector3d::Zero();
            int count = 0;
            for (size_t t = 0; t + 2 < region.size();
                 ++t) {  // Fan; a parallelogram's halves are equal.
              const Eigen::Vector2d a = region[0], b = region[t + 1], c = region[t + 2];
              for (int u = 0; u < m; ++u) {
                for (int w = 0; u + w < m; ++w) {
                  sum +=
                      texture.Sample(a + (u + 1.0 / 3) / m * (b - a) + (w + 1.0 / 3) / m * (c - a));
                  ++count;
                  if (u + w <= m - 2) {
                    sum += texture.Sample(a + (u + 2.0 / 3) / m * (b - a) +
                                          (w + 2.0 / 3) / m * (c - a));
                    ++count;
                  }
                }
              }
            }
            value = sum / count;
          }
        }
        value = value.cwiseMax(0.0).cwiseMin(1.0);
        double* texel =
            albedo->texel(f * MeshColors::TexelsPerFace(r) + MeshColors::LocalIndex(r, i, j));
        for (int c = 0; c < 3; ++c) texel[c] = value[c];
      }
    }
  });
}

// Texture pixels kept across the texel regions (see TextureReduction): the area average over a
// region of the mip level differs from the full-resolution one only by the box filter's blur
// along the region's border, ~2/16 of the region's area (measured: at most 2.6% of a unit jump in
// the texture, mean 0.3%; 5.6% with 8 pixels, docs/design-notes.md 2026-11-24).
constexpr double kTexturePixelsAcrossTexel = 16.0;
// The percentile of faces (by UV size) whose texel regions must keep kTexturePixelsAcrossTexel:
// smaller faces' regions see a coarser mip level, as with trilinear filtering.
constexpr double kTextureReductionPercentile = 0.1;

// The power-of-two factor by which a width × height texture can be box-filtered (a mip level)
// before sampling into mesh colors of resolution r: the texel regions of the faces at the 10th
// percentile of UV size then still span kTexturePixelsAcrossTexel pixels. A texel region of a
// face whose UV triangle covers A pixels² is a square of 2A/r² pixels². 1 = no reduction.
int TextureReduction(const std::vector<Eigen::Vector2d>& corner_uvs, int num_faces, int r,
                     int width, int height) {
  std::vector<double> across;  // Pixels across a texel region, per face with UV area.
  across.reserve(num_faces);
  for (int f = 0; f < num_faces; ++f) {
    const Eigen::Vector2d e1 = corner_uvs[3 * f + 1] - corner_uvs[3 * f];
    const Eigen::Vector2d e2 = corner_uvs[3 * f + 2] - corner_uvs[3 * f];
    const double area = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x()) * width * height;
    if (area > 0) across.push_back(std::sqrt(2.0 * area) / r);
  }
  if (across.empty()) return 1;
  const size_t k = static_cast<size_t>(kTextureReductionPercentile * (across.size() - 1));
  std::nth_element(across.begin(), across.begin() + k, across.end());
  int reduction = 1;
  while (across[k] / (2 * reduction) >= kTexturePixelsAcrossTexel && width / (2 * reduction) >= 1 &&
         height / (2 * reduction) >= 1) {
    reduction *= 2;
  }
  return reduction;
}

// Checks the texture's values and turns them into linear albedo in place: non-finite values are
// an error naming the pixel; values outside [0, 1] are clamped and reported in one warning (a
// texture is data from another tool, often an HDR EXR: one bright texel should not stop a run,
// unlike a constant typed by the user, which is refused). "srgb" decodes after clamping.
Status PrepareTexture(const Context& ctx, const std::string& file, bool srgb, Image* image) {
  int64_t clamped = 0;
  float lowest = 0.0f, highest = 1.0f;
  for (size_t i = 0; i < image->data.size(); ++i) {
    float& v = image->data[i];
    if (!std::isfinite(v)) {
      const size_t pixel = i / image->channels;
      return ctx.Error("albedo_texture", file + ": pixel (" + std::to_string(pixel % image->width) +
                                             ", " + std::to_string(pixel / image->width) +
                                             ") has a non-finite value");
    }
    if (v < 0.0f || v > 1.0f) {
      ++clamped;
      lowest = std::min(lowest, v);
      highest = std::max(highest, v);
      v = std::min(std::max(v, 0.0f), 1.0f);
    }
    if (srgb) v = SrgbToLinear(v);
  }
  if (clamped > 0) {
    LOG(WARNING) << file << ": " << clamped << " texture values outside [0, 1] (from " << lowest
                 << " to " << highest << ") clamped to [0, 1] for albedo";
  }
  return Status::Ok();
}

// Box-filters `image` down by `reduction` (OpenCV INTER_AREA: exact block means for a power of
// two that divides the size).
Image ShrinkImage(const Image& image, int reduction) {
  const cv::Mat full(image.height, image.width, CV_32FC(image.channels),
                     const_cast<float*>(image.data.data()));
  Image small(std::max(1, image.width / reduction), std::max(1, image.height / reduction),
              image.channels);
  cv::Mat out(small.height, small.width, CV_32FC(small.channels), small.data.data());
  cv::resize(full, out, out.size(), 0, 0, cv::INTER_AREA);
  CHECK(out.data == reinterpret_cast<uchar*>(small.data.data())) << "resize reallocated";
  return small;
}

// ---- Procedural patterns ------------------------------------------------------------------------

double Fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }  // C2 quintic.

// Value noise: a hashed value in [0, 1) at each integer lattice point, interpolated with the
// quintic fade; smooth (C2) and deterministic from `seed`.
double ValueNoise(const Eigen::Vector3d& p, uint64_t seed) {
  const Eigen::Vector3d f = p.array().floor();
  const Eigen::Vector3d t = p - f;
  const int64_t ix = static_cast<int64_t>(f.x()), iy = static_cast<int64_t>(f.y()),
                iz = static_cast<int64_t>(f.z());
  const uint64_t key = Mix64(seed);
  auto lattice = [&](int64_t x, int64_t y, int64_t z) {
    // One SplitMix finalization of the coordinates spread by odd constants (a standard spatial
    // hash); plenty for a texture pattern.
    const uint64_t h = Mix64(key ^ (static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull) ^
                             (static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full) ^
                             (static_cast<uint64_t>(z) * 0x165667B19E3779F9ull));
    return static_cast<double>(h >> 11) * 0x1.0p-53;
  };
  const double u = Fade(t.x()), v = Fade(t.y()), w = Fade(t.z());
  double result = 0.0;
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const double weight = (dx ? u : 1 - u) * (dy ? v : 1 - v) * (dz ? w : 1 - w);
        result += weight * lattice(ix + dx, iy + dy, iz + dz);
      }
    }
  }
  return result;
}

// Fractal Brownian motion: 4 octaves of value noise, normalized to [0, 1].
double Fbm(const Eigen::Vector3d& p, uint64_t seed) {
  double sum = 0.0, amplitude = 1.0, total = 0.0, frequency = 1.0;
  for (int octave = 0; octave < 4; ++octave) {
    sum += amplitude * ValueNoise(frequency * p, seed + 7919 * octave);
    total += amplitude;
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return sum / total;
}

double SmoothStep(double lo, double hi, double x) {
  const double t = std::min(std::max((x - lo) / (hi - lo), 0.0), 1.0);
  return t * t * (3 - 2 * t);
}

// The mixing weight in [0, 1] of the second colour at object-space point `p`. Coordinates are
// normalized by the mesh's bounding box (centre, diagonal) so that `scale` counts features across
// the object whatever its size.
class Pattern {
 public:
  Pattern(bool wood, double scale, uint64_t seed, const Eigen::Vector3d& lo,
          const Eigen::Vector3d& hi)
      : wood_(wood), scale_(scale), seed_(seed), centre_(0.5 * (lo + hi)) {
    const double diagonal = (hi - lo).norm();
    inv_size_ = diagonal > 0 ? 1.0 / diagonal : 1.0;
    // Wood: the rings' axis runs along the longest side of the bounding box (like a log).
    (hi - lo).maxCoeff(&axis_);
  }

  double Weight(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d q = (p - centre_) * inv_size_;
    if (!wood_) {
      // Value-noise fBm clusters around 0.5; stretch its middle range to use both colours.
      return SmoothStep(0.3, 0.7, Fbm(scale_ * q, seed_));
    }
    Eigen::Vector3d radial = q;
    radial[axis_] = 0.0;
    // Ring coordinate, perturbed by low-frequency noise so that rings wobble.
    const double t = scale_ * radial.norm() + 1.5 * (Fbm(0.5 * scale_ * q, seed_) - 0.5);
    const double ring = t - std::floor(t);
    // Sharp-ish dark rings: mostly the first colour, the second on a band of each period.
    return SmoothStep(0.55, 0.75, ring) * (1.0 - SmoothStep(0.85, 1.0, ring));
  }

 private:
  bool wood_;
  double scale_;
  uint64_t seed_;
  Eigen::Vector3d centre_;
  double inv_size_ = 1.0;
  Eigen::Index axis_ = 2;
};

// ---- Loading ------------------------------------------------------------------------------------

const std::set<std::string>& KnownKeys() {
  static const std::set<std::string> keys = {
      "albedo",     "albedo_texture", "colorspace", "mesh_colors", "roughness_mesh_colors",
      "procedural", "colors",         "scale",      "roughness",   "roughness_range",
      "specular",   "fresnel",        "resolution", "seed"};
  return keys;
}

Status ReadMeshColorsFor(const Context& ctx, const std::string& field, const std::string& path,
                         int channels, int num_faces, MeshColors* colors) {
  Status status = ReadMeshColors(path, colors);
  if (!status.ok()) return ctx.Error(field, status.message());
  if (colors->channels() != channels) {
    return ctx.Error(field, path + " has " + std::to_string(colors->channels()) +
                                " channels, expected " + std::to_string(channels));
  }
  if (colors->num_faces() != num_faces) {
    return ctx.Error(field, path + " has " + std::to_string(colors->num_faces()) +
                                " faces, the mesh has " + std::to_string(num_faces));
  }
  for (size_t k = 0; k < colors->values().size(); ++k) {
    const double v = colors->values()[k];
    if (!(v >= 0.0 && v <= 1.0)) {
      return ctx.Error(field, path + ": texel " + std::to_string(k / channels) + " has value " +
                                  FormatNumber(v) + " outside [0, 1]");
    }
  }
  return Status::Ok();
}

Status BuildMaterial(const Context& ctx, const Json& json, const std::string& base_dir,
                     const TriMesh& mesh, Material* material) {
  if (!json.is_object()) return ctx.Error("expected a JSON object");
  for (auto it = json.begin(); it != json.end(); ++it) {
    if (KnownKeys().count(it.key()) == 0) {
      return ctx.Error("unknown key \"" + it.key() + "\"");
    }
  }
  const int num_faces = static_cast<int>(mesh.n_faces());
  auto has = [&](const char* key) { return json.contains(key); };

  // Exactly one albedo source (none: the default constant).
  std::vector<std::string> sources;
  for (const char* key : {"albedo", "albedo_texture", "mesh_colors", "procedural"}) {
    if (has(key)) sources.push_back(key);
  }
  if (sources.size() > 1) {
    return ctx.Error(sources[1], "cannot be combined with \"" + sources[0] + "\"");
  }
  const std::string source = sources.empty() ? "albedo" : sources[0];
  // Keys that belong to one form only.
  const std::pair<const char*, const char*> form_keys[] = {{"colorspace", "albedo_texture"},
                                                           {"colors", "procedural"},
                                                           {"scale", "procedural"},
                                                           {"seed", "procedural"},
                                                           {"roughness_range", "procedural"}};
  for (const auto& fk : form_keys) {
    if (has(fk.first) && source != fk.second) {
      return ctx.Error(fk.first, std::string("only applies with \"") + fk.second + "\"");
    }
  }
  if (has("resolution") && source == "mesh_colors") {
    return ctx.Error("resolution", "does not apply with \"mesh_colors\" (the file has its own)");
  }
  int roughness_sources = 0;
  for (const char* key : {"roughness", "roughness_mesh_colors", "roughness_range"}) {
    roughness_sources += has(key) ? 1 : 0;
  }
  if (roughness_sources > 1) {
    return ctx.Error("roughness",
                     "give only one of \"roughness\", \"roughness_mesh_colors\", "
                     "\"roughness_range\"");
  }

  Material result;
  // fresnel and specular.
  if (has("fresnel")) {
    const Json& v = json["fresnel"];
    if (v == "constant") {
      result.fresnel = FresnelMode::kConstant;
    } else if (v == "schlick") {
      result.fresnel = FresnelMode::kSchlick;
    } else {
      return ctx.Error("fresnel", "expected \"constant\" or \"schlick\", got " + v.dump());
    }
  }
  if (has("specular")) {
    // The constant Fresnel weight (or Schlick's F0) is a reflectance: above 1 the glossy lobe
    // reflects more than arrives (1e20 gave inf pixels).
    SFT_RETURN_IF_ERROR(ReadNumber(ctx, json, "specular", 0.0, 1.0, &result.specular));
  }
  int resolution = source == "albedo" ? 1 : kDefaultSampledResolution;
  if (has("resolution")) {
    const Json& v = json["resolution"];
    if (!v.is_number_integer() || v.get<int64_t>() < 1 || v.get<int64_t>() > kMaxResolution) {
      return ctx.Error("resolution", "expected an integer in [1, " +
                                         std::to_string(kMaxResolution) + "], got " + v.dump());
    }
    resolution = static_cast<int>(v.get<int64_t>());
  }

  // Albedo.
  std::vector<double> weights;  // Procedural mixing weight per texel (for roughness_range).
  if (source == "albedo") {
    Eigen::Vector3d albedo = Eigen::Vector3d::Constant(kDefaultAlbedo);
    if (has("albedo")) SFT_RETURN_IF_ERROR(ParseColor(ctx, "albedo", json["albedo"], &albedo));
    FillConstant(num_faces, resolution, albedo.data(), 3, &result.albedo);
  } else if (source == "albedo_texture") {
    std::string file;
    SFT_RETURN_IF_ERROR(ReadString(ctx, json, "albedo_texture", &file));
    file = JoinPath(base_dir, file);
    // Default: texel values are albedo as stored (the issue-2 CLI contract), for PNG and EXR
    // alike; "colorspace": "srgb" decodes sRGB-encoded textures.
    bool srgb = false;
    if (has("colorspace")) {
      const Json& v = json["colorspace"];
      if (v != "linear" && v != "srgb") {
        return ctx.Error("colorspace", "expected \"linear\" or \"srgb\", got " + v.dump());
      }
      srgb = v == "srgb";
    }
    const std::vector<Eigen::Vector2d> corner_uvs = FaceCornerUvs(mesh);
    if (corner_uvs.size() != 3 * static_cast<size_t>(num_faces) || num_faces == 0) {
      return ctx.Error("albedo_texture", "the mesh has no texture coordinates (UVs)");
    }
    if (!FileExists(file)) return ctx.Error("albedo_texture", file + ": file not found");
    Image image;
    Status status = ReadImage(file, &image, /*srgb=*/false);
    if (!status.ok()) return ctx.Error("albedo_texture", status.message());
    if (image.width < 1 || image.height < 1 || image.channels < 1) {
      return ctx.Error("albedo_texture", file + ": empty image");
    }
    SFT_RETURN_IF_ERROR(PrepareTexture(ctx, file, srgb, &image));
    // Only the detail that texel regions can hold is kept: an 8192² texture at resolution 64 held
    // 2.4 GB while sampled (docs/design-notes.md, 2026-11-24).
    const int reduction =
        TextureReduction(corner_uvs, num_faces, resolution, image.width, image.height);
    if (reduction > 1) image = ShrinkImage(image, reduction);
    SampleTexture(Texture(std::move(image)), corner_uvs, num_faces, resolution, &result.albedo);
  } else if (source == "mesh_colors") {
    std::string file;
    SFT_RETURN_IF_ERROR(ReadString(ctx, json, "mesh_colors", &file));
    SFT_RETURN_IF_ERROR(ReadMeshColorsFor(ctx, "mesh_colors", JoinPath(base_dir, file), 3,
                                          num_faces, &result.albedo));
    resolution = result.albedo.resolution();
  } else {  // procedural
    const Json& kind = json["procedural"];
    if (kind != "wood" && kind != "noise") {
      return ctx.Error("procedural", "expected \"wood\" or \"noise\", got " + kind.dump());
    }
    const bool wood = kind == "wood";
    Eigen::Vector3d colors[2] = {Eigen::Vector3d(0.65, 0.45, 0.25),
                                 Eigen::Vector3d(0.35, 0.2, 0.1)};
    if (!wood) {
      colors[0] = Eigen::Vector3d::Constant(0.8);
      colors[1] = Eigen::Vector3d::Constant(0.2);
    }
    if (has("colors")) {
      const Json& v = json["colors"];
      if (!v.is_array() || v.size() != 2) {
        return ctx.Error("colors", "expected two colors [[r,g,b],[r,g,b]], got " + v.dump());
      }
      for (int k = 0; k < 2; ++k) SFT_RETURN_IF_ERROR(ParseColor(ctx, "colors", v[k], &colors[k]));
    }
    double scale = wood ? kDefaultWoodScale : kDefaultNoiseScale;
    if (has("scale")) {
      SFT_RETURN_IF_ERROR(ReadNumber(ctx, json, "scale", 0.0, 1e6, &scale));
      if (scale <= 0.0) return ctx.Error("scale", "must be positive");
    }
    uint64_t seed = 0;
    if (has("seed")) {
      const Json& v = json["seed"];
      if (!v.is_number_integer() || v.get<int64_t>() < 0) {
        return ctx.Error("seed", "expected a non-negative integer, got " + v.dump());
      }
      seed = static_cast<uint64_t>(v.get<int64_t>());
    }
    std::vector<Eigen::Vector3d> positions;
    std::vector<Eigen::Vector3i> faces;
    MeshToArrays(mesh, &positions, &faces);
    Eigen::Vector3d lo, hi;
    MeshBounds(mesh, &lo, &hi);
    const Pattern pattern(wood, scale, seed, lo, hi);
    result.albedo = MeshColors(num_faces, resolution, 3);
    weights.resize(result.albedo.num_texels());
    tbb::parallel_for(0, num_faces, [&](int f) {  // Per-texel pure function: deterministic.
      const Eigen::Vector3d& p0 = positions[faces[f][0]];
      const Eigen::Vector3d& p1 = positions[faces[f][1]];
      const Eigen::Vector3d& p2 = positions[faces[f][2]];
      for (int i = 0; i <= resolution; ++i) {
        for (int j = 0; i + j <= resolution; ++j) {
          const Eigen::Vector2d ab = MeshColors::TexelCenter(resolution, i, j);
          const Eigen::Vector3d p = (1.0 - ab.x() - ab.y()) * p0 + ab.x() * p1 + ab.y() * p2;
          const int k =
              f * MeshColors::TexelsPerFace(resolution) + MeshColors::LocalIndex(resolution, i, j);
          const double w = pattern.Weight(p);
          weights[k] = w;
          const Eigen::Vector3d c = (1.0 - w) * colors[0] + w * colors[1];
          for (int ch = 0; ch < 3; ++ch) result.albedo.texel(k)[ch] = c[ch];
        }
      }
    });
  }

  // Roughness.
  if (has("roughness_mesh_colors")) {
    std::string file;
    SFT_RETURN_IF_ERROR(ReadString(ctx, json, "roughness_mesh_colors", &file));
    SFT_RETURN_IF_ERROR(ReadMeshColorsFor(ctx, "roughness_mesh_colors", JoinPath(base_dir, file), 1,
                                          num_faces, &result.roughness));
  } else if (has("roughness_range")) {
    const Json& v = json["roughness_range"];
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number() ||
        !(v[0].get<double>() >= 0.0) || !(v[1].get<double>() <= 1.0) ||
        !(v[0].get<double>() <= v[1].get<double>())) {
      return ctx.Error("roughness_range",
                       "expected [lo, hi] with 0 <= lo <= hi <= 1, got " + v.dump());
    }
    const double lo = v[0].get<double>(), hi = v[1].get<double>();
    result.roughness = MeshColors(num_faces, resolution, 1);
    for (int k = 0; k < result.roughness.num_texels(); ++k) {
      result.roughness.texel(k)[0] = lo + (hi - lo) * weights[k];
    }
  } else {
    double roughness = kDefaultRoughness;
    if (has("roughness")) {
      SFT_RETURN_IF_ERROR(ReadNumber(ctx, json, "roughness", 0.0, 1.0, &roughness));
    }
    FillConstant(num_faces, resolution, &roughness, 1, &result.roughness);
  }
  *material = std::move(result);
  return Status::Ok();
}

}  // namespace

Material ConstantMaterial(int num_faces, const Eigen::Vector3d& albedo, double roughness,
                          double specular, int resolution) {
  Material material;
  FillConstant(num_faces, resolution, albedo.data(), 3, &material.albedo);
  FillConstant(num_faces, resolution, &roughness, 1, &material.roughness);
  material.specular = specular;
  return material;
}

Status LoadMaterial(const std::string& spec, const TriMesh& mesh, Material* material) {
  const size_t first = spec.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) {
    *material = ConstantMaterial(static_cast<int>(mesh.n_faces()),
                                 Eigen::Vector3d::Constant(kDefaultAlbedo), kDefaultRoughness, 0.0);
    return Status::Ok();
  }
  std::string text;
  std::string base_dir;
  std::string where;
  if (spec[first] == '{') {
    text = spec;
    where = "material (inline JSON)";
  } else {
    SFT_RETURN_IF_ERROR(ReadTextFile(spec, &text));
    StripUtf8Bom(&text);  // nlohmann::json skips it too; explicit for every reader.
    base_dir = std::filesystem::path(spec).parent_path().string();
    where = spec;
  }
  const Context ctx(where);
  Json json;
  try {
    json = Json::parse(text);
  } catch (const Json::exception& e) {
    return ctx.Error(std::string("invalid JSON (") + e.what() + ")");
  }
  try {
    return BuildMaterial(ctx, json, base_dir, mesh, material);
  } catch (const Json::exception& e) {
    // Every access is type-checked above; this is a safety net so that no exception escapes.
    return ctx.Error(std::string("malformed material (") + e.what() + ")");
  }
}

Status SaveMaterial(const std::string& json_path, const Material& material) {
  if (material.albedo.channels() != 3 || material.roughness.channels() != 1) {
    return Status::Error(json_path + ": material needs 3 albedo channels and 1 roughness channel");
  }
  const std::filesystem::path path(json_path);
  const std::string stem = path.stem().string();
  const std::string albedo_name = stem + "_albedo.meshcolors";
  const std::string roughness_name = stem + "_roughness.meshcolors";
  const std::string dir = path.parent_path().string();
  SFT_RETURN_IF_ERROR(WriteMeshColors(JoinPath(dir, albedo_name), material.albedo,
                                      {"albedo_r", "albedo_g", "albedo_b"}));
  SFT_RETURN_IF_ERROR(
      WriteMeshColors(JoinPath(dir, roughness_name), material.roughness, {"roughness"}));
  // The JSON last, so that it never references a file that is not there yet.
  Json json;
  json["mesh_colors"] = albedo_name;
  json["roughness_mesh_colors"] = roughness_name;
  json["specular"] = material.specular;
  json["fresnel"] = material.fresnel == FresnelMode::kSchlick ? "schlick" : "constant";
  return WriteTextFile(json_path, json.dump(2) + "\n");
}

}  // namespace sft
