// Memory estimates and the machine's memory budget, so that commands refuse work that cannot fit
// with one clear error (estimated and available bytes) instead of dying in std::bad_alloc. The
// reconstruction shares these for its own memory reporting.
#ifndef SFT_CORE_MEMORY_H_
#define SFT_CORE_MEMORY_H_

#include <cstdint>
#include <string>

namespace sft {

// Bytes of a width × height image with `channels` values of `bytes_per_value` bytes each
// (saturating at UINT64_MAX; negative sizes count as 0).
uint64_t EstimateImageBytes(int64_t width, int64_t height, int channels, int bytes_per_value = 4);

// Memory this process can still allocate without swapping: MemAvailable of /proc/meminfo (else
// MemTotal, else sysconf's available physical pages), lowered to the cgroup's memory.max minus
// memory.current when the process runs under a cgroup v2 limit. 0 when nothing can be read.
uint64_t AvailableMemoryBytes();

// "1.5 GB", "320 MB", "12 kB" (powers of 1024, as free(1) prints them).
std::string FormatBytes(uint64_t bytes);

// True when `bytes` fit into AvailableMemoryBytes() (or when that is unknown). Otherwise false
// and *why = "<what> needs an estimated X, more than the Y of memory available".
bool CheckMemoryBudget(uint64_t bytes, const std::string& what, std::string* why);

// A field of /proc/self/status in bytes (e.g. "VmRSS:", "VmHWM:" the peak resident set); 0 when
// unavailable.
int64_t ProcessStatusBytes(const std::string& key);

// Resets the process's peak resident set (VmHWM) to the current one (Linux ≥ 4.0); false when the
// kernel does not allow it.
bool ResetPeakResidentSet();

}  // namespace sft

#endif  // SFT_CORE_MEMORY_H_
