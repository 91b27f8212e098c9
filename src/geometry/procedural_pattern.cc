#include "src/geometry/procedural_pattern.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "src/core/rng.h"

namespace sft {
namespace {

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

}  // namespace

std::vector<double> ProceduralWeights(const TriMesh& mesh, const ProceduralPattern& spec,
                                      int resolution) {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const Pattern pattern(spec.wood, spec.scale, spec.seed, lo, hi);
  const int num_faces = static_cast<int>(faces.size());
  const int per_face = MeshColors::TexelsPerFace(resolution);
  std::vector<double> weights(static_cast<size_t>(num_faces) * per_face);
  tbb::parallel_for(0, num_faces, [&](int f) {  // Per-texel pure function: deterministic.
    const Eigen::Vector3d& p0 = positions[faces[f][0]];
    const Eigen::Vector3d& p1 = positions[faces[f][1]];
    const Eigen::Vector3d& p2 = positions[faces[f][2]];
    for (int i = 0; i <= resolution; ++i) {
      for (int j = 0; i + j <= resolution; ++j) {
        const Eigen::Vector2d ab = MeshColors::TexelCenter(resolution, i, j);
        const Eigen::Vector3d p = (1.0 - ab.x() - ab.y()) * p0 + ab.x() * p1 + ab.y() * p2;
        weights[f * per_face + MeshColors::LocalIndex(resolution, i, j)] = pattern.Weight(p);
      }
    }
  });
  return weights;
}

}  // namespace sft
