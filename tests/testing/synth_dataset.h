// Small datasets synthesized by the `sft synth` CLI for tests that need a whole dataset.
#ifndef SFT_TESTS_TESTING_SYNTH_DATASET_H_
#define SFT_TESTS_TESTING_SYNTH_DATASET_H_

#include <string>

namespace sft {
namespace testing {

// Runs `sft synth --quiet --mesh DATA/meshes/icosphere_r1_320f.obj --out DIR ARGS`; returns the
// command's output on failure (for the assertion message) and "" on success.
std::string SynthIcosphere(const std::string& dir, const std::string& args);

// Overwrites view `view`'s mask in the dataset at `dir`: with `hole`, a centred square of a quarter
// of the image's size becomes background (carving would cut a tunnel through the hull); without,
// every pixel does (an empty mask, which carving refuses). Returns "" on success, else the error.
std::string CorruptMask(const std::string& dir, int view, bool hole);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_SYNTH_DATASET_H_
