#include "src/io/synth_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace sft {
namespace {

// Hash of an integer lattice point to [0, 1) (splitmix64 finaliser).
double LatticeValue(int64_t x, int64_t y, uint64_t seed) {
  uint64_t h = seed * 0x9E3779B97F4A7C15ull ^ (static_cast<uint64_t>(x) * 0xBF58476D1CE4E5B9ull) ^
               (static_cast<uint64_t>(y) * 0x94D049BB133111EBull);
  h ^= h >> 30;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 27;
  h *= 0x94D049BB133111EBull;
  h ^= h >> 31;
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

// Bilinear value noise of wavelength `scale` at (x, y), in [0, 1).
double ValueNoise(double x, double y, double scale, uint64_t seed) {
  const double u = x / scale, v = y / scale;
  const double fu = std::floor(u), fv = std::floor(v);
  const int64_t iu = static_cast<int64_t>(fu), iv = static_cast<int64_t>(fv);
  const double tu = u - fu, tv = v - fv;
  const double a = LatticeValue(iu, iv, seed), b = LatticeValue(iu + 1, iv, seed);
  const double c = LatticeValue(iu, iv + 1, seed), d = LatticeValue(iu + 1, iv + 1, seed);
  return (a * (1 - tu) + b * tu) * (1 - tv) + (c * (1 - tu) + d * tu) * tv;
}

Eigen::Vector3d GroundAlbedo(double x, double y, const GroundOptions& options) {
  double n = 0, weight = 0, scale = options.feature, w = 1;
  for (int octave = 0; octave < 4; ++octave, scale *= 3, w *= 1.2) {
    n += w * ValueNoise(x, y, scale, options.seed + octave);
    weight += w;
  }
  n /= weight;
  // Contrast stretch around the mean (the sum of octaves concentrates near 0.5).
  const double t = std::clamp(0.5 + 2.5 * (n - 0.5), 0.0, 1.0);
  const double hue = ValueNoise(x, y, 9 * options.feature, options.seed + 100);
  const Eigen::Vector3d warm(0.85, 0.55, 0.25), cool(0.2, 0.35, 0.7);
  const Eigen::Vector3d tint = warm * hue + cool * (1 - hue);
  return (0.04 + 0.9 * t) * tint;
}

// Four rectangles, 2 faces each, normal +z, that fill the square of half side `outer` around
// the square of half side `inner` (both centred on `centre`'s x, y, at height z). Their edges meet
// the inner grid's boundary in T-junctions, which leave no gap: the grid's boundary vertices lie
// on the rectangles' edges.
void AddFloorRing(const Eigen::Vector3d& centre, double z, double inner, double outer,
                  TriMesh* mesh) {
  auto add_rect = [&](double x0, double y0, double x1, double y1) {
    const auto a = mesh->add_vertex(TriMesh::Point(centre.x() + x0, centre.y() + y0, z));
    const auto b = mesh->add_vertex(TriMesh::Point(centre.x() + x1, centre.y() + y0, z));
    const auto c = mesh->add_vertex(TriMesh::Point(centre.x() + x1, centre.y() + y1, z));
    const auto d = mesh->add_vertex(TriMesh::Point(centre.x() + x0, centre.y() + y1, z));
    mesh->add_face(a, b, c);
    mesh->add_face(a, c, d);
  };
  add_rect(-outer, -outer, outer, -inner);  // below
  add_rect(-outer, inner, outer, outer);    // above
  add_rect(-outer, -inner, -inner, inner);  // left
  add_rect(inner, -inner, outer, inner);    // right
}

}  // namespace

bool GroundOptions::Check(std::string* why) const {
  if (!(half_size > 0 && half_size <= 1e3)) {
    *why = "--ground-size: must be in (0, 1000]";
    return false;
  }
  if (!(gap >= 0 && gap <= 1)) {
    *why = "ground gap: must be in [0, 1]";
    return false;
  }
  if (cells < 1 || cells > 1024) {
    *why = "--ground-cells: must be in [1, 1024]";
    return false;
  }
  if (!(feature > 0 && feature <= 1)) {
    *why = "--ground-feature: must be in (0, 1]";
    return false;
  }
  if (!(floor_half_size == 0 || (floor_half_size > half_size && floor_half_size <= 1e3))) {
    *why = "--ground-floor: must be 0 or in (--ground-size, 1000]";
    return false;
  }
  return true;
}

double GroundHeight(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                    const GroundOptions& options) {
  return lo.z() - options.gap * (hi - lo).norm();
}

Status AddGroundPlane(const TriMesh& object, const Material& object_material,
                      const GroundOptions& options, TriMesh* mesh, Material* material) {
  std::string why;
  if (!options.Check(&why)) return Status::Error(why);
  Eigen::Vector3d lo, hi;
  MeshBounds(object, &lo, &hi);
  const double diagonal = (hi - lo).norm();
  if (!(diagonal > 0)) return Status::Error("--ground: the object has zero extent");
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double z = GroundHeight(lo, hi, options);
  const double half = options.half_size * diagonal;
  const int n = options.cells;

  *mesh = object;
  const int object_faces = static_cast<int>(object.n_faces());
  std::vector<TriMesh::VertexHandle> grid((n + 1) * (n + 1));
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = centre.x() - half + 2 * half * i / n;
      const double y = centre.y() - half + 2 * half * j / n;
      grid[j * (n + 1) + i] = mesh->add_vertex(TriMesh::Point(x, y, z));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const auto a = grid[j * (n + 1) + i], b = grid[j * (n + 1) + i + 1];
      const auto c = grid[(j + 1) * (n + 1) + i + 1], d = grid[(j + 1) * (n + 1) + i];
      mesh->add_face(a, b, c);  // counter-clockwise seen from +z: normal +z.
      mesh->add_face(a, c, d);
    }
  }
  const int plane_faces = static_cast<int>(mesh->n_faces());
  if (options.floor_half_size > 0)
    AddFloorRing(centre, z, half, options.floor_half_size * diagonal, mesh);
  const int total_faces = static_cast<int>(mesh->n_faces());
  const int floor_faces = options.floor_half_size > 0 ? 8 : 0;
  if (total_faces != object_faces + 2 * n * n + floor_faces) {
    return Status::Error("--ground: could not add the plane's faces to the mesh");
  }

  // Merged mesh colors: the object's texels first, then the plane's sampled from the noise at
  // each texel's representative point.
  const int r = object_material.albedo.resolution();
  const int rr = object_material.roughness.resolution();
  if (object_material.albedo.num_faces() != object_faces ||
      object_material.roughness.num_faces() != object_faces) {
    return Status::Error("--ground: the material does not match the mesh's faces");
  }
  material->albedo = MeshColors(total_faces, r, 3);
  material->roughness = MeshColors(total_faces, rr, 1, 0.8);
  material->specular = object_material.specular;
  material->fresnel = object_material.fresnel;
  std::copy(object_material.albedo.values().begin(), object_material.albedo.values().end(),
            material->albedo.values().begin());
  std::copy(object_material.roughness.values().begin(), object_material.roughness.values().end(),
            material->roughness.values().begin());
  const Eigen::Vector3d kFloorAlbedo(0.35, 0.3, 0.25);
  for (int f = plane_faces; f < total_faces; ++f) {
    for (int k = 0; k < MeshColors::TexelsPerFace(r); ++k) {
      double* t = material->albedo.texel(f * MeshColors::TexelsPerFace(r) + k);
      for (int c = 0; c < 3; ++c) t[c] = kFloorAlbedo[c];
    }
  }
  for (int f = object_faces; f < plane_faces; ++f) {
    Eigen::Vector3d p[3];
    int k = 0;
    for (auto fv : mesh->fv_range(mesh->face_handle(f))) {
      const auto q = mesh->point(fv);
      p[k++] = Eigen::Vector3d(q[0], q[1], q[2]);
    }
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; j <= r - i; ++j) {
        const Eigen::Vector2d ab = MeshColors::TexelCenter(r, i, j);
        const Eigen::Vector3d x = (1 - ab.x() - ab.y()) * p[0] + ab.x() * p[1] + ab.y() * p[2];
        const Eigen::Vector3d albedo = GroundAlbedo(x.x(), x.y(), options);
        double* t = material->albedo.texel(f * MeshColors::TexelsPerFace(r) +
                                           MeshColors::LocalIndex(r, i, j));
        for (int c = 0; c < 3; ++c) t[c] = albedo[c];
      }
    }
  }
  return Status::Ok();
}

std::vector<Eigen::Vector3d> OrbitPath(int n, const Eigen::Vector3d& target, double distance,
                                       double elevation_lo_deg, double elevation_hi_deg) {
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < n; ++k) {
    const double azimuth = 2 * M_PI * k / n;
    const double elevation_deg =
        0.5 * (elevation_lo_deg + elevation_hi_deg) +
        0.5 * (elevation_hi_deg - elevation_lo_deg) * std::sin(4 * M_PI * k / n);
    const double e = elevation_deg * M_PI / 180;
    centres.push_back(target + distance * Eigen::Vector3d(std::cos(e) * std::cos(azimuth),
                                                          std::cos(e) * std::sin(azimuth),
                                                          std::sin(e)));
  }
  return centres;
}

}  // namespace sft
