// sft compare: one CSV and one HTML report of cost, Chamfer and F1 against wall time over several
// sft reconstruct runs (src/eval/run_comparison.h).
#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/eval/run_comparison.h"

namespace sft {
namespace {

struct CompareOptions {
  std::vector<std::string> runs;    // reconstruction output folders.
  std::vector<std::string> labels;  // one per run; default: the folder names.
  std::string out;                  // output folder.
};

Status RunCompare(const CompareOptions& opts) {
  std::vector<std::string> labels = opts.labels;
  if (labels.empty()) labels = opts.runs;
  RunInputs inputs;
  inputs.directories = opts.runs;
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(opts.out, inputs, "--out"));
  return CompareRuns(opts.runs, labels, opts.out);
}

}  // namespace

CommandRunner SetupCompareCommand(CLI::App* app) {
  auto opts = std::make_shared<CompareOptions>();
  app->add_option("--runs", opts->runs, "sft reconstruct output folders (comma-separated)")
      ->required()
      ->delimiter(',');
  app->add_option("--labels", opts->labels, "A name per run (comma-separated)")->delimiter(',');
  app->add_option("--out", opts->out, "Output folder (comparison.csv, report.html)")->required();
  return [opts]() {
    const Status status = RunCompare(*opts);
    return status.ok() ? 0 : PrintError("compare", status);
  };
}

}  // namespace sft
