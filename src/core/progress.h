// A progress line with ETA on stderr for long commands. Thread-safe: Advance() may be called from
// worker threads. Prints at most ~4 times per second, and a final line on Finish().
#ifndef SFT_CORE_PROGRESS_H_
#define SFT_CORE_PROGRESS_H_

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace sft {

class Progress {
 public:
  // `total` units of work; `label` is printed in front ("render", "synth"...). Quiet when
  // `enabled` is false (tests, --quiet).
  Progress(std::string label, int64_t total, bool enabled = true);
  void Advance(int64_t units = 1);
  void Finish();
  double ElapsedSeconds() const;
  // Prints "sft LABEL: warning: MESSAGE" on its own line of stderr, also when the progress line
  // is disabled (a warning is never quiet); on a terminal the progress line is redrawn below it.
  void Warn(const std::string& message);
  // Prints "sft LABEL: MESSAGE" on its own line of stderr (an event such as a stage change), also
  // when the progress line is disabled.
  void Note(const std::string& message);
  // A detail shown after the label on the progress line ("reconstruct [half]: ..."); "" = none.
  void SetDetail(const std::string& detail);

 private:
  void Print(bool final_line);

  std::string label_;
  std::string detail_;  // guarded by mutex_.
  int64_t total_;
  bool enabled_;
  std::atomic<int64_t> done_{0};
  int64_t last_printed_ = -1;  // `done_` at the last printed line (guarded by mutex_).
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_print_;
  std::mutex mutex_;
};

}  // namespace sft

#endif  // SFT_CORE_PROGRESS_H_
