// Packing parameterised charts into one square atlas (our own packer).
//
// Each chart is first turned to its minimum-area bounding rectangle (one side along an edge of
// its convex hull, which is where the minimum lies) and then to lie wider than tall. All charts
// share one scale s (texels per scene unit: one texel density over the whole surface). For a given
// s, the rectangles (chart box rounded up to whole texels, plus `gutter` texels to the right and
// below) are placed first-fit decreasing-height on shelves from the atlas's top-left corner, which
// is `gutter` texels in from both edges; the largest s for which everything fits is found by
// bisection. Any two charts are then at least `gutter` texels apart, and every chart at least
// `gutter` texels from the atlas's edge.
#ifndef SFT_ATLAS_ATLAS_PACKING_H_
#define SFT_ATLAS_ATLAS_PACKING_H_

#include <Eigen/Core>
#include <vector>

#include "src/core/status.h"

namespace sft {

// One chart's corner UVs (surface units) in, atlas UVs out: u to the right, v up, both in
// [0, 1] (the OBJ convention; texel row 0 is the top row, v = 1).
using ChartCorners = std::vector<Eigen::Vector2d>;

// Packs the charts in place into a texture_size² atlas. *texels_per_unit = s. Error when even a
// vanishing scale cannot fit the charts (more charts than the atlas has room for, with gutters).
Status PackCharts(int texture_size, int gutter, std::vector<ChartCorners>* charts,
                  double* texels_per_unit);

}  // namespace sft

#endif  // SFT_ATLAS_ATLAS_PACKING_H_
