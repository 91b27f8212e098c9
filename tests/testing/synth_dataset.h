// Small datasets synthesized by the `sft synth` CLI for tests that need a whole dataset.
#ifndef SFT_TESTS_TESTING_SYNTH_DATASET_H_
#define SFT_TESTS_TESTING_SYNTH_DATASET_H_

#include <functional>
#include <string>

#include "src/io/dataset.h"

namespace sft {
namespace testing {

// Runs `sft synth --quiet --mesh DATA/meshes/icosphere_r1_320f.obj --out DIR ARGS`; returns the
// command's output on failure (for the assertion message) and "" on success.
std::string SynthIcosphere(const std::string& dir, const std::string& args);

// Overwrites view `view`'s mask in the dataset at `dir`: with `hole`, a centred square of a quarter
// of the image's size becomes background (carving would cut a tunnel through the hull); without,
// every pixel does (an empty mask, which carving refuses). Returns "" on success, else the error.
std::string CorruptMask(const std::string& dir, int view, bool hole);

// Copies the dataset at `from` (with its gt/ folder) to `to` with its lights changed by
// `relight`, its images rendered anew by sft's renderer from gt/mesh.ply and gt/material.json
// (64 spp, one segment, flat shading, as `sft synth` renders) and its masks rewritten. Returns ""
// on success, else the error.
std::string RelightDataset(const std::string& from, const std::string& to,
                           const std::function<void(Dataset*)>& relight);

// Unknown lighting: `dataset` with every light and every view's light list removed.
void RemoveLights(Dataset* dataset);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_SYNTH_DATASET_H_
