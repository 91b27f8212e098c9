#include "tests/testing/synth_dataset.h"

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

}  // namespace testing
}  // namespace sft
