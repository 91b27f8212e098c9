#include "src/core/progress.h"

#include <glog/logging.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace sft {

double RemainingSeconds(const std::vector<WorkKind>& kinds) {
  int64_t timed = 0;
  double seconds = 0.0;
  for (const WorkKind& kind : kinds) {
    timed += kind.timed;
    seconds += kind.seconds;
  }
  if (timed <= 0) return 0.0;
  const double overall_rate = seconds / static_cast<double>(timed);
  double remaining = 0.0;
  for (const WorkKind& kind : kinds) {
    const double rate =
        kind.timed > 0 ? kind.seconds / static_cast<double>(kind.timed) : overall_rate;
    remaining += static_cast<double>(std::max<int64_t>(0, kind.total - kind.done)) * rate;
  }
  return remaining;
}

Progress::Progress(std::string label, int64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      enabled_(enabled),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_),
      last_advance_(start_) {}

Progress::Progress(std::string label, const std::vector<int64_t>& totals, bool enabled)
    : Progress(std::move(label), std::accumulate(totals.begin(), totals.end(), int64_t{0}),
               enabled) {
  if (totals.size() > 1) {
    kinds_.resize(totals.size());
    for (size_t k = 0; k < totals.size(); ++k) kinds_[k].total = totals[k];
  }
}

double Progress::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::Advance(int64_t units, int kind) {
  done_ += units;
  if (kinds_.empty() && !enabled_) return;  // kinds_ is fixed at construction.
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!kinds_.empty()) {
    CHECK(kind >= 0 && kind < static_cast<int>(kinds_.size())) << "no work kind " << kind;
    WorkKind& k = kinds_[kind];
    if (k.done > 0) {  // not the kind's first step (WorkKind).
      k.timed += units;
      k.seconds += std::chrono::duration<double>(now - last_advance_).count();
    }
    k.done += units;
    last_advance_ = now;
  }
  if (!enabled_) return;
  if (now - last_print_ < std::chrono::milliseconds(250)) return;
  last_print_ = now;
  Print(false);
}

std::vector<WorkKind> Progress::kinds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return kinds_;
}

void Progress::Finish() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  // A log file already has the final count when the last Advance printed it.
  if (!isatty(fileno(stderr)) && last_printed_ == done_.load()) return;
  Print(true);
}

void Progress::Warn(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool tty = isatty(fileno(stderr));
  std::fprintf(stderr, "%ssft %s: warning: %s\n", (enabled_ && tty) ? "\r\033[K" : "",
               label_.c_str(), message.c_str());
  std::fflush(stderr);
}

void Progress::Note(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool tty = isatty(fileno(stderr));
  std::fprintf(stderr, "%ssft %s: %s\n", (enabled_ && tty) ? "\r\033[K" : "", label_.c_str(),
               message.c_str());
  std::fflush(stderr);
}

void Progress::SetDetail(const std::string& detail) {
  std::lock_guard<std::mutex> lock(mutex_);
  detail_ = detail;
}

void Progress::Print(bool final_line) {
  const int64_t done = done_.load();
  last_printed_ = done;
  const double elapsed = ElapsedSeconds();
  const double fraction = static_cast<double>(done) / static_cast<double>(total_);
  bool timed = false;
  for (const WorkKind& kind : kinds_) timed = timed || kind.timed > 0;
  const double eta = timed          ? RemainingSeconds(kinds_)
                     : fraction > 0 ? elapsed * (1.0 - fraction) / fraction
                                    : 0.0;
  // A carriage return keeps one line on a terminal; a log file gets one line per update.
  const bool tty = isatty(fileno(stderr));
  const std::string label = detail_.empty() ? label_ : label_ + " [" + detail_ + "]";
  std::fprintf(stderr, "%s%s: %lld/%lld (%.0f%%) elapsed %.1fs ETA %.1fs%s", tty ? "\r\033[K" : "",
               label.c_str(), static_cast<long long>(done), static_cast<long long>(total_),
               100.0 * fraction, elapsed, final_line ? 0.0 : eta, (final_line || !tty) ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace sft
