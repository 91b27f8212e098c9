// The command table of the `sft` CLI. Each command lives in apps/<name>_command.cc and provides a
// Setup function that declares its options on a CLI11 subcommand and returns the function that
// runs it. A command returns the process exit code: 0 on success, 1 on a user error (after
// printing one line "sft CMD: error: ..." via PrintError), 2 on a usage error.
#ifndef SFT_APPS_COMMANDS_H_
#define SFT_APPS_COMMANDS_H_

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "src/core/status.h"
#include "src/render/derivatives.h"

namespace sft {

using CommandRunner = std::function<int()>;
using CommandSetup = CommandRunner (*)(CLI::App* app);

struct CommandEntry {
  const char* name;
  const char* description;
  CommandSetup setup;
};

// Prints "sft CMD: error: MESSAGE" on stderr and returns 1.
int PrintError(const std::string& command, const Status& status);

int RunCommandTable(int argc, char** argv);

// Declares --primary-edge-ratio, --shadow-edge-ratio, --secondary-edge-samples and
// --texel-edge-ratio (the edge-sampling budgets of vertex derivatives) on `app`, bound to
// `request`'s fields (defaults shown; DerivativeRequest::Check validates them).
void AddEdgeBudgetOptions(CLI::App* app, DerivativeRequest* request);

// The file a --material value names, or "" for inline JSON and the default material (for the
// output checks of CheckOutputDirectory/CheckOutputFile).
std::string MaterialFile(const std::string& material);

// One per command file.
CommandRunner SetupSynthCommand(CLI::App* app);
CommandRunner SetupRenderCommand(CLI::App* app);
CommandRunner SetupGradcheckCommand(CLI::App* app);
CommandRunner SetupBenchCommand(CLI::App* app);
// Adds `sft bench reconstruct` under `bench`; its runner returns -1 when it was not the one parsed.
CommandRunner AddBenchReconstructCommand(CLI::App* bench);
CommandRunner SetupReconstructCommand(CLI::App* app);
CommandRunner SetupPerturbCommand(CLI::App* app);
CommandRunner SetupEvalCommand(CLI::App* app);
CommandRunner SetupCompareCommand(CLI::App* app);
CommandRunner SetupImportCommand(CLI::App* app);
// Adds `sft import nerf`, `idr` and `middlebury` under `import`; its runner returns -1 when none of
// them was the one parsed.
CommandRunner AddCalibratedImportCommands(CLI::App* import);
CommandRunner SetupAlignProbeCommand(CLI::App* app);
CommandRunner SetupInitCommand(CLI::App* app);
CommandRunner SetupExportCommand(CLI::App* app);
CommandRunner SetupSweepCommand(CLI::App* app);

}  // namespace sft

#endif  // SFT_APPS_COMMANDS_H_
