// Lights files: a JSON object whose "lights" array holds lights in scene.json's format
// (docs/dataset.md), for `sft eval --relight` and the lights `sft reconstruct` estimates beside
// unknown lighting (`--estimate-lights`, the run's estimated_lights.json). Implemented beside the
// scene.json reader and writer (dataset.cc, dataset_write.cc), whose light parser and serializer
// they share.
#ifndef SFT_IO_LIGHTS_FILE_H_
#define SFT_IO_LIGHTS_FILE_H_

#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/io/dataset.h"

namespace sft {

// Reads a lights file: the "lights" array is required and holds at least one light, checked by
// scene.json's reader; errors name the file and the JSON path ("l.json: lights[0].intensity: must
// be non-negative"). An environment light's `image` may be absolute or relative to the file's
// folder (".." allowed); it is returned as an absolute path. Does not open the probes.
Status ReadLightsFile(const std::string& file, std::vector<LightSpec>* lights);

// Writes `lights` as a lights file that ReadLightsFile reads back, atomically. Probe paths are
// written as stored.
Status WriteLightsFile(const std::string& file, const std::vector<LightSpec>& lights);

// The same in memory (an MPI handshake sends lights this way): the file's text, and its parse
// (errors prefixed by `source`; probe paths kept as written).
Status LightsFileText(const std::vector<LightSpec>& lights, std::string* text);
Status ParseLightsFileText(std::string text, const std::string& source,
                           std::vector<LightSpec>* lights);

}  // namespace sft

#endif  // SFT_IO_LIGHTS_FILE_H_
