#include "tests/testing/synth_dataset.h"

#include <cstdlib>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace testing {

std::string SynthIcosphere(const std::string& dir, const std::string& args) {
  std::string output;
  const int code = RunCommand(SftBinary() + " synth --quiet --mesh " + DataDir() +
                                  "/meshes/icosphere_r1_320f.obj --out " + dir + " " + args,
                              &output);
  return code == 0 ? std::string() : "sft synth failed (" + std::to_string(code) + "): " + output;
}

std::string CorruptMask(const std::string& dir, int view, bool hole) {
  Dataset dataset;
  Image mask;
  Status status = ReadDataset(dir, &dataset);
  if (status.ok()) status = LoadViewMask(dataset, view, &mask);
  if (!status.ok()) return status.message();
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      const bool centre = std::abs(2 * x - mask.width) < mask.width / 4 &&
                          std::abs(2 * y - mask.height) < mask.height / 4;
      if (!hole || centre) mask.at(x, y) = 0.f;
    }
  }
  status = WritePng(JoinPath(dataset.root, dataset.views[view].mask), mask, /*srgb=*/false);
  return status.ok() ? std::string() : status.message();
}

}  // namespace testing
}  // namespace sft
