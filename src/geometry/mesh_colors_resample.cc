#include "src/geometry/mesh_colors_resample.h"

#include <glog/logging.h>

#include <algorithm>

namespace sft {

MeshColors ResampleMeshColors(const MeshColors& colors, int new_resolution) {
  CHECK_GE(new_resolution, 0);
  if (colors.channels() < 1) return MeshColors();  // default-constructed: nothing to resample.
  const int r = new_resolution;
  const int channels = colors.channels();
  MeshColors result(colors.num_faces(), r, channels);
  int k = 0;  // new texels in order: face, then row i, then j.
  for (int f = 0; f < colors.num_faces(); ++f) {
    for (int i = 0; i <= r; ++i) {
      for (int j = 0; j <= r - i; ++j, ++k) {
        const Eigen::Vector2d center = MeshColors::TexelCenter(r, i, j);
        const double* value = colors.texel(colors.TexelIndex(f, center.x(), center.y()));
        std::copy(value, value + channels, result.texel(k));
      }
    }
  }
  return result;
}

}  // namespace sft
