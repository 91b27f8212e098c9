// The fitted light intensity scales of a reconstruction (`OUT/lights.json`), so that a re-render
// reproduces the fit: {"format": "sft-light-scales/1", "lights": [{"id": ID, "scale": s}, ...]},
// one entry per dataset light in dataset order (matched by id on reading). A point light's
// intensity, or an environment light's scale, is multiplied by s.
#ifndef SFT_IO_LIGHT_SCALES_H_
#define SFT_IO_LIGHT_SCALES_H_

#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/io/dataset.h"

namespace sft {

Status WriteLightScales(const std::string& path, const Dataset& dataset,
                        const std::vector<double>& scales);
// Reads scales for `dataset`'s lights (every dataset light must be listed, by id; scales finite
// and > 0). Errors name the file and the entry.
Status ReadLightScales(const std::string& path, const Dataset& dataset,
                       std::vector<double>* scales);
// Multiplies the dataset's light intensities (point) and scales (environment) by `scales`.
void ApplyLightScales(const std::vector<double>& scales, Dataset* dataset);

}  // namespace sft

#endif  // SFT_IO_LIGHT_SCALES_H_
