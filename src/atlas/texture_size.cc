#include "src/atlas/texture_size.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "src/geometry/mesh_colors.h"

namespace sft {

int TextureSizeFromFootprint(const Dataset& dataset, const Eigen::Vector3d& center, double area) {
  double footprint = std::numeric_limits<double>::infinity();
  for (const ViewSpec& view : dataset.views) {
    if (view.camera < 0 || view.camera >= static_cast<int>(dataset.cameras.size())) continue;
    const double focal = dataset.cameras[view.camera].Focal().maxCoeff();
    const Eigen::Vector3d eye = view.cam_from_world.Inverse().translation;
    const double distance = (eye - center).norm();
    if (focal > 0.0 && distance > 0.0) footprint = std::min(footprint, distance / focal);
  }
  if (!std::isfinite(footprint) || !(area > 0.0)) return kDefaultTextureSize;
  const double side = std::sqrt(area / (footprint * footprint) / 0.5);
  int size = 256;
  while (size < side && size < 4096) size *= 2;
  return size;
}

int TextureSizeForMeshColors(int num_faces, int resolution) {
  constexpr double kUtilization = 0.35;
  constexpr double kTexelsPerSample = 4.0;
  const double samples =
      static_cast<double>(std::max(num_faces, 0)) * MeshColors::TexelsPerFace(resolution);
  const double side = std::sqrt(kTexelsPerSample * samples / kUtilization);
  int size = 256;
  while (size < side && size < 4096) size *= 2;
  return size;
}

}  // namespace sft
