// sft perturb: writes a copy of a mesh displaced by a smooth random field (the low-frequency
// field of vertex gradchecks, SmoothDisplacementField), scaled so that the largest displacement
// is --amplitude × the mesh's bounding-box diagonal. Faces and their order are kept. Used to make
// starting meshes for geometry reconstruction tests and the built-in example.
#include <cmath>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/eval/gradcheck.h"
#include "src/geometry/mesh.h"

namespace sft {
namespace {

struct PerturbOptions {
  std::string mesh;         // input mesh.
  std::string out;          // output mesh file (OBJ, PLY, OFF).
  double amplitude = 0.01;  // largest displacement / bounding-box diagonal, [0, 1].
  uint64_t seed = 1;        // field seed.
};

Status RunPerturb(const PerturbOptions& opts) {
  if (!(opts.amplitude >= 0.0 && opts.amplitude <= 1.0)) {
    return Status::Error("--amplitude: must be in [0, 1]");
  }
  SFT_RETURN_IF_ERROR(CheckOutputFile(opts.out, {{}, {opts.mesh}}, "--out"));
  TriMesh mesh;
  SFT_RETURN_IF_ERROR(ReadMesh(opts.mesh, &mesh));
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> faces;
  MeshToArrays(mesh, &positions, &faces);
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const double scale = opts.amplitude * (hi - lo).norm();
  const std::vector<double> field = SmoothDisplacementField(positions, opts.seed);
  int v = 0;
  for (auto vh : mesh.vertices()) {
    const Eigen::Vector3d p =
        positions[v] + scale * Eigen::Vector3d(field[3 * v], field[3 * v + 1], field[3 * v + 2]);
    mesh.set_point(vh, TriMesh::Point(p.x(), p.y(), p.z()));
    ++v;
  }
  return WriteMesh(opts.out, mesh);
}

}  // namespace

CommandRunner SetupPerturbCommand(CLI::App* app) {
  auto opts = std::make_shared<PerturbOptions>();
  app->add_option("--mesh", opts->mesh, "Input mesh (OBJ, PLY, OFF)")->required();
  app->add_option("--out", opts->out, "Output mesh file (OBJ, PLY, OFF)")->required();
  app->add_option("--amplitude", opts->amplitude,
                  "Largest displacement as a fraction of the bounding-box diagonal, [0, 1]")
      ->capture_default_str();
  app->add_option("--seed", opts->seed, "Seed of the displacement field")->capture_default_str();
  return [opts]() {
    const Status status = RunPerturb(*opts);
    return status.ok() ? 0 : PrintError("perturb", status);
  };
}

}  // namespace sft
