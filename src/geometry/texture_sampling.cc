#include "src/geometry/texture_sampling.h"

#include <glog/logging.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "src/core/file_util.h"
#include "src/image/image_io.h"

namespace sft {
namespace {

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

// The mean of the texture over `region` (a triangle or a fan of two) by the centroid rule on a
// 64×64 subdivision of each triangle (a parallelogram's halves are equal): the fallback for regions
// too large for IntegratePolygon.
Eigen::Vector3d CentroidRuleAverage(const Texture& texture, const Polygon& region) {
  constexpr int m = 64;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t t = 0; t + 2 < region.size(); ++t) {
    const Eigen::Vector2d a = region[0], b = region[t + 1], c = region[t + 2];
    for (int u = 0; u < m; ++u) {
      for (int w = 0; u + w < m; ++w) {
        sum += texture.Sample(a + (u + 1.0 / 3) / m * (b - a) + (w + 1.0 / 3) / m * (c - a));
        ++count;
        if (u + w <= m - 2) {
          sum += texture.Sample(a + (u + 2.0 / 3) / m * (b - a) + (w + 2.0 / 3) / m * (c - a));
          ++count;
        }
      }
    }
  }
  return sum / count;
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
            value = CentroidRuleAverage(texture, region);
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

// Checks the texture's values and turns them into linear values in place: non-finite values are
// an error naming the pixel; values outside [0, 1] are clamped and reported in one warning (a
// texture is data from another tool, often an HDR EXR: one bright texel should not stop a run,
// unlike a constant typed by the user, which is refused). "srgb" decodes after clamping.
Status PrepareTexture(const std::string& file, bool srgb, const std::string& what, Image* image) {
  int64_t clamped = 0;
  float lowest = 0.0f, highest = 1.0f;
  for (size_t i = 0; i < image->data.size(); ++i) {
    float& v = image->data[i];
    if (!std::isfinite(v)) {
      const size_t pixel = i / image->channels;
      return Status::Error(file + ": pixel (" + std::to_string(pixel % image->width) + ", " +
                           std::to_string(pixel / image->width) + ") has a non-finite value");
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
                 << " to " << highest << ") clamped to [0, 1] for " << what;
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

}  // namespace

Status ReadTextureImage(const std::string& file, bool srgb, const std::string& what, Image* image) {
  if (!FileExists(file)) return Status::Error(file + ": file not found");
  SFT_RETURN_IF_ERROR(ReadImage(file, image, /*srgb=*/false));
  if (image->width < 1 || image->height < 1 || image->channels < 1) {
    return Status::Error(file + ": empty image");
  }
  return PrepareTexture(file, srgb, what, image);
}

void SampleTextureIntoMeshColors(Image image, const std::vector<Eigen::Vector2d>& corner_uvs,
                                 int num_faces, int resolution, MeshColors* albedo) {
  // Only the detail that texel regions can hold is kept: an 8192² texture at resolution 64 held
  // 2.4 GB while sampled (docs/design-notes.md, 2026-11-24).
  const int reduction =
      TextureReduction(corner_uvs, num_faces, resolution, image.width, image.height);
  if (reduction > 1) image = ShrinkImage(image, reduction);
  SampleTexture(Texture(std::move(image)), corner_uvs, num_faces, resolution, albedo);
}

}  // namespace sft
