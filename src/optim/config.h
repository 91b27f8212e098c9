// The reconstruction's configuration file: one flat JSON object whose keys are documented in
// docs/reconstruct.md (every key optional; unknown keys are an error naming the key). Command-line
// flags of `sft reconstruct` override it. The effective configuration is written back to
// OUT/state.json, so that a resumed run continues with the same options.
#ifndef SFT_OPTIM_CONFIG_H_
#define SFT_OPTIM_CONFIG_H_

#include <nlohmann/json.hpp>
#include <string>

#include "src/core/status.h"
#include "src/optim/reconstruct.h"

namespace sft {

// Applies the keys of `config` to `options`; `source` names the file in errors
// ("cfg.json: steps: expected an integer in [1, 1000]").
Status ApplyReconstructConfig(const nlohmann::json& config, const std::string& source,
                              ReconstructOptions* options);
// Reads and applies a config file.
Status ReadReconstructConfig(const std::string& path, ReconstructOptions* options);
// Every key with its current value (ApplyReconstructConfig of it reproduces `options`).
nlohmann::json ReconstructConfigJson(const ReconstructOptions& options);

}  // namespace sft

#endif  // SFT_OPTIM_CONFIG_H_
