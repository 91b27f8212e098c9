#include "src/core/memory.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

namespace sft {
namespace {

constexpr uint64_t kUnknown = 0;

// A "Key:  123 kB" line of /proc/meminfo, in bytes; kUnknown when absent.
uint64_t MemInfoBytes(const std::string& key) {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size() + 1, key + ":") != 0) continue;
    std::istringstream fields(line.substr(key.size() + 1));
    uint64_t kb = 0;
    if (fields >> kb) return kb * 1024;
  }
  return kUnknown;
}

// A cgroup v2 file holding one number ("max" = no limit); kUnknown when absent or "max".
uint64_t CgroupNumber(const std::string& file) {
  std::ifstream in("/sys/fs/cgroup/" + file);
  uint64_t value = 0;
  if (in >> value) return value;
  return kUnknown;
}

}  // namespace

uint64_t EstimateImageBytes(int64_t width, int64_t height, int channels, int bytes_per_value) {
  if (width <= 0 || height <= 0 || channels <= 0 || bytes_per_value <= 0) return 0;
  const long double bytes = static_cast<long double>(width) * height * channels * bytes_per_value;
  const long double max = static_cast<long double>(std::numeric_limits<uint64_t>::max());
  return bytes >= max ? std::numeric_limits<uint64_t>::max() : static_cast<uint64_t>(bytes);
}

uint64_t AvailableMemoryBytes() {
  uint64_t available = MemInfoBytes("MemAvailable");
  if (available == kUnknown) available = MemInfoBytes("MemTotal");
  if (available == kUnknown) {
    const long pages = sysconf(_SC_AVPHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page_size > 0) {
      available = static_cast<uint64_t>(pages) * static_cast<uint64_t>(page_size);
    }
  }
  const uint64_t limit = CgroupNumber("memory.max");
  if (limit != kUnknown) {
    const uint64_t used = CgroupNumber("memory.current");
    const uint64_t left = limit > used ? limit - used : 0;
    available = available == kUnknown ? left : std::min(available, left);
  }
  return available;
}

std::string FormatBytes(uint64_t bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  double value = static_cast<double>(bytes);
  int unit = 0;
  while (value >= 1024.0 && unit < 6) {
    value /= 1024.0;
    ++unit;
  }
  char buffer[48];
  if (unit == 0) {
    std::snprintf(buffer, sizeof(buffer), "%llu bytes", static_cast<unsigned long long>(bytes));
  } else {
    std::snprintf(buffer, sizeof(buffer), "%.3g %s", value, units[unit]);
  }
  return buffer;
}

bool CheckMemoryBudget(uint64_t bytes, const std::string& what, std::string* why) {
  const uint64_t available = AvailableMemoryBytes();
  if (available == kUnknown || bytes <= available) return true;
  if (why != nullptr) {
    *why = what + " needs an estimated " + FormatBytes(bytes) + ", more than the " +
           FormatBytes(available) + " of memory available";
  }
  return false;
}

int64_t ProcessStatusBytes(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) != 0) continue;
    std::istringstream fields(line.substr(key.size()));
    int64_t kilobytes = 0;
    fields >> kilobytes;
    return fields ? kilobytes * 1024 : 0;
  }
  return 0;
}

bool ResetPeakResidentSet() {
  std::ofstream out("/proc/self/clear_refs");
  if (!out) return false;
  out << "5";
  out.close();
  return !out.fail();
}

}  // namespace sft
