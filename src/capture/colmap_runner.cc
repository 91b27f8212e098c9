#include "src/capture/colmap_runner.h"

#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <regex>

#include "src/core/progress.h"

namespace sft {
namespace {

// Single-quotes `arg` for /bin/sh.
std::string ShellQuote(const std::string& arg) {
  std::string quoted = "'";
  for (char c : arg) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

}  // namespace

bool ParseColmapProgress(const std::string& stage, const std::string& line, int* done, int* total) {
  std::smatch m;
  if (stage == "feature_extractor") {
    static const std::regex re(R"(Processed file \[(\d+)/(\d+)\])");
    if (!std::regex_search(line, m, re)) return false;
    *done = std::stoi(m[1]);
    *total = std::stoi(m[2]);
    return true;
  }
  if (stage == "exhaustive_matcher") {
    static const std::regex re(R"(Matching block \[(\d+)/(\d+), (\d+)/(\d+)\])");
    if (!std::regex_search(line, m, re)) return false;
    const int i = std::stoi(m[1]), n = std::stoi(m[2]), j = std::stoi(m[3]), n2 = std::stoi(m[4]);
    *done = (i - 1) * n2 + j;
    *total = n * n2;
    return true;
  }
  if (stage == "sequential_matcher") {
    static const std::regex re(R"(Matching image \[(\d+)/(\d+)\])");
    if (!std::regex_search(line, m, re)) return false;
    *done = std::stoi(m[1]);
    *total = std::stoi(m[2]);
    return true;
  }
  if (stage == "mapper") {
    static const std::regex re(R"(Registering image #\d+ \((\d+)\))");
    if (!std::regex_search(line, m, re)) return false;
    *done = std::stoi(m[1]);
    *total = 0;
    return true;
  }
  return false;
}

Status RunColmapStage(const std::string& colmap_binary, const std::string& stage,
                      const std::vector<std::string>& args, const std::string& log_path,
                      int expected_total, bool progress_enabled, double* seconds) {
  const auto start = std::chrono::steady_clock::now();
  std::string command = "QT_QPA_PLATFORM=offscreen OMP_WAIT_POLICY=passive " +
                        ShellQuote(colmap_binary) + " " + ShellQuote(stage);
  for (const std::string& arg : args) command += " " + ShellQuote(arg);
  command += " 2>&1";
  std::ofstream log(log_path, std::ios::app);
  if (!log) return Status::Error(log_path + ": cannot write the COLMAP log");
  log << "$ " << command << "\n";
  log.flush();
  std::fflush(nullptr);
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return Status::Error("cannot start " + colmap_binary + " " + stage);
  Progress progress("import video: " + stage, expected_total > 0 ? expected_total : 1,
                    progress_enabled);
  int shown = 0;
  std::string line;
  char buffer[4096];
  while (std::fgets(buffer, sizeof(buffer), pipe) != nullptr) {
    line += buffer;
    if (line.empty() || line.back() != '\n') continue;
    log << line;
    int done = 0, total = 0;
    if (ParseColmapProgress(stage, line, &done, &total)) {
      // The Progress total is fixed at construction: counts are rescaled to it.
      const int scale_total = expected_total > 0 ? expected_total : 1;
      const int target = total > 0
                             ? static_cast<int>(static_cast<int64_t>(done) * scale_total / total)
                             : std::min(done, scale_total);
      if (target > shown) {
        progress.Advance(target - shown);
        shown = target;
      }
    }
    line.clear();
  }
  if (!line.empty()) log << line << "\n";
  const int status = pclose(pipe);
  progress.Finish();
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  log << "# " << stage << ": " << *seconds << " s, exit status " << status << "\n";
  if (status == -1 || !WIFEXITED(status)) {
    return Status::Error("COLMAP " + stage + " did not finish (see " + log_path + ")");
  }
  const int code = WEXITSTATUS(status);
  if (code == 127) {
    return Status::Error("COLMAP not found: '" + colmap_binary +
                         "' could not be run (install colmap or pass --colmap PATH)");
  }
  if (code != 0) {
    return Status::Error("COLMAP " + stage + " failed with exit code " + std::to_string(code) +
                         " (see " + log_path + ")");
  }
  return Status::Ok();
}

}  // namespace sft
