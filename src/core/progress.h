// A progress line with ETA on stderr for long commands. Thread-safe: Advance() may be called from
// worker threads. Prints at most ~4 times per second, and a final line on Finish().
//
// Work may come in kinds whose cost per unit differs (a reconstruction's LM and Adam steps, its
// texture and geometry phases): the ETA then prices each kind's remaining units at that kind's
// own measured seconds per unit, so that a run which starts with an expensive kind does not
// extrapolate its rate to the cheaper work that follows.
#ifndef SFT_CORE_PROGRESS_H_
#define SFT_CORE_PROGRESS_H_

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace sft {

// One kind of work: its units in all, the units done, and of those the units whose wall time is
// measured (`timed`, taking `seconds`). A kind's first step is done but not timed: it carries the
// set-up of whatever started it (a run's loading, a stage's first renders), which the remaining
// steps of the kind do not repeat.
struct WorkKind {
  int64_t total = 0;
  int64_t done = 0;
  int64_t timed = 0;
  double seconds = 0.0;
};

// Seconds left: each kind's remaining units (total − done, at least 0) at its own rate
// (seconds / timed), or, for a kind with nothing timed yet, at the rate over all kinds' timed
// units. 0 when nothing is timed anywhere (no rate to extrapolate).
double RemainingSeconds(const std::vector<WorkKind>& kinds);

class Progress {
 public:
  // `total` units of work; `label` is printed in front ("render", "synth"...). Quiet when
  // `enabled` is false (tests, --quiet).
  Progress(std::string label, int64_t total, bool enabled = true);
  // Work of `totals.size()` kinds (units of kind k: totals[k]); Advance names the kind. The
  // wall time between two Advance calls is the advancing kind's, except for its first Advance
  // (WorkKind); RemainingSeconds prices the rest, and until some kind has been timed the ETA is
  // the single-rate one.
  Progress(std::string label, const std::vector<int64_t>& totals, bool enabled = true);
  // `kind` in [0, number of kinds) (CHECKed); 0 for single-kind progress.
  void Advance(int64_t units = 1, int kind = 0);
  void Finish();
  double ElapsedSeconds() const;
  // Prints "sft LABEL: warning: MESSAGE" on its own line of stderr, also when the progress line
  // is disabled (a warning is never quiet); on a terminal the progress line is redrawn below it.
  void Warn(const std::string& message);
  // Prints "sft LABEL: MESSAGE" on its own line of stderr (an event such as a stage change), also
  // when the progress line is disabled.
  void Note(const std::string& message);
  // The kinds' units and seconds so far (empty for single-kind progress).
  std::vector<WorkKind> kinds() const;
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
  // Per kind when there are several (guarded by mutex_; empty for single-kind progress), and the
  // time of the last Advance, from which the next one's seconds are counted (declared after
  // start_, which initialises it).
  std::vector<WorkKind> kinds_;
  std::chrono::steady_clock::time_point last_advance_;
  mutable std::mutex mutex_;
};

}  // namespace sft

#endif  // SFT_CORE_PROGRESS_H_
