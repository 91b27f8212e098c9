#include "src/core/progress.h"

#include <unistd.h>

#include <cstdio>

namespace sft {

Progress::Progress(std::string label, int64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      enabled_(enabled),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_) {}

double Progress::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::Advance(int64_t units) {
  done_ += units;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (now - last_print_ < std::chrono::milliseconds(250)) return;
  last_print_ = now;
  Print(false);
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
  const double eta = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  // A carriage return keeps one line on a terminal; a log file gets one line per update.
  const bool tty = isatty(fileno(stderr));
  const std::string label = detail_.empty() ? label_ : label_ + " [" + detail_ + "]";
  std::fprintf(stderr, "%s%s: %lld/%lld (%.0f%%) elapsed %.1fs ETA %.1fs%s", tty ? "\r\033[K" : "",
               label.c_str(), static_cast<long long>(done), static_cast<long long>(total_),
               100.0 * fraction, elapsed, final_line ? 0.0 : eta, (final_line || !tty) ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace sft
