// Scene pieces `sft synth` adds for synthetic captures (issue 12, item 6): a textured ground plane
// under the object, so that structure-from-motion has near-field texture and parallax, and an
// orbit camera path whose views come in path order, as frames of a video would.
//
// The renderer takes one mesh and one material, so the plane is appended to a copy of the object
// mesh and its texels to a copy of the object's mesh colors (same resolution). The object keeps
// faces [0, object_faces); the plane's faces follow. Masks stay object-only: `sft synth` renders a
// coverage pass of the object alone (docs/cli.md "sft synth"); with every camera above the plane
// the plane never occludes the object, so that coverage is the object's visible silhouette.
#ifndef SFT_IO_SYNTH_SCENE_H_
#define SFT_IO_SYNTH_SCENE_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"

namespace sft {

struct GroundOptions {
  double half_size = 2.0;  // half the side of the square plane, in object-box diagonals, (0, 1e3].
  double gap = 1e-3;       // plane height below the object's lowest point, in diagonals, [0, 1].
  int cells = 96;          // grid cells per side (2 triangles each), [1, 1024].
  double feature = 0.01;   // finest noise wavelength, in diagonals, (0, 1]; coarser octaves ×3.
  uint64_t seed = 7;       // noise seed.
  // Half the side of a plain floor around the textured plane, in object-box diagonals; 0 = none,
  // else in (half_size, 1e3]. A finite plane under a far-field probe lets the probe's light below
  // the horizon reach the object past the plane's edge; a floor many diagonals wide keeps it off
  // (`--probe-ground` models either as a disc, docs/dataset.md).
  double floor_half_size = 0.0;

  bool Check(std::string* why) const;
};

// The ground plane's height (z) under an object whose bounding box is [lo, hi].
double GroundHeight(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                    const GroundOptions& options);

// Appends a square ground plane (normal +z, at the object's lowest z minus `gap`, centred under the
// object's bounding-box centre) to `object`, and a high-frequency procedural albedo (four octaves
// of value noise mapped to a warm/cool palette, roughness 0.8) to the material. With
// `floor_half_size`, four rectangles (8 faces, a uniform grey-brown albedo) extend the plane to a
// square floor of that half side. `mesh` and
// `material` receive the merged scene; The object keeps faces [0, object.n_faces()).
Status AddGroundPlane(const TriMesh& object, const Material& object_material,
                      const GroundOptions& options, TriMesh* mesh, Material* material);

// Camera centres along an orbit around `target` (z up): frame k of n at azimuth 2πk/n and
// elevation (lo + hi)/2 + (hi − lo)/2 · sin(4πk/n) degrees (two height oscillations per turn),
// at `distance`. Views in path order.
std::vector<Eigen::Vector3d> OrbitPath(int n, const Eigen::Vector3d& target, double distance,
                                       double elevation_lo_deg, double elevation_hi_deg);

}  // namespace sft

#endif  // SFT_IO_SYNTH_SCENE_H_
