#include "src/optim/adam_checkpoint.h"

#include <cmath>
#include <cstring>
#include <filesystem>

#include "src/core/file_util.h"

namespace sft {
namespace {

constexpr char kMagic[8] = {'S', 'F', 'T', 'A', 'D', 'A', 'M', '\0'};
constexpr uint32_t kVersion = 1;
// magic, version, stage, outer_done, n, t, lambda.
constexpr size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8 + 8 + 8;

// Little-endian byte order whatever the host's.
void PutUint(uint64_t value, int bytes, std::string* out) {
  for (int b = 0; b < bytes; ++b) out->push_back(static_cast<char>((value >> (8 * b)) & 0xff));
}

void PutDouble(double value, std::string* out) {
  uint64_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  PutUint(bits, 8, out);
}

uint64_t GetUint(const std::string& in, size_t* pos, int bytes) {
  uint64_t value = 0;
  for (int b = 0; b < bytes; ++b) {
    value |= static_cast<uint64_t>(static_cast<unsigned char>(in[*pos + b])) << (8 * b);
  }
  *pos += bytes;
  return value;
}

double GetDouble(const std::string& in, size_t* pos) {
  const uint64_t bits = GetUint(in, pos, 8);
  double value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

}  // namespace

Status WriteAdamCheckpoint(const std::string& out, const AdamCheckpoint& checkpoint) {
  const AdamState& s = checkpoint.state;
  const std::string path = JoinPath(out, kAdamStateFile);
  if (s.m.size() != s.v.size()) {
    return Status::Error(path + ": Adam's moments differ in size (programming error)");
  }
  std::string bytes(kMagic, sizeof(kMagic));
  bytes.reserve(kHeaderBytes + 16 * s.m.size());
  PutUint(kVersion, 4, &bytes);
  PutUint(static_cast<uint32_t>(checkpoint.stage), 4, &bytes);
  PutUint(static_cast<uint64_t>(checkpoint.outer_done), 8, &bytes);
  PutUint(s.m.size(), 8, &bytes);
  PutUint(static_cast<uint64_t>(s.t), 8, &bytes);
  PutDouble(s.lambda, &bytes);
  for (double m : s.m) PutDouble(m, &bytes);
  for (double v : s.v) PutDouble(v, &bytes);
  return WriteTextFile(path, bytes);
}

Status ReadAdamCheckpoint(const std::string& out, AdamCheckpoint* checkpoint, bool* found) {
  const std::string path = JoinPath(out, kAdamStateFile);
  *found = FileExists(path);
  if (!*found) return Status::Ok();
  std::string bytes;
  SFT_RETURN_IF_ERROR(ReadTextFile(path, &bytes));
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    return Status::Error(path + ": not an sft Adam state (" + std::to_string(bytes.size()) +
                         " bytes, no SFTADAM header)");
  }
  size_t pos = sizeof(kMagic);
  const uint64_t version = GetUint(bytes, &pos, 4);
  if (version != kVersion) {
    return Status::Error(path + ": version " + std::to_string(version) + " is not " +
                         std::to_string(kVersion));
  }
  checkpoint->stage = static_cast<int>(GetUint(bytes, &pos, 4));
  checkpoint->outer_done = static_cast<int64_t>(GetUint(bytes, &pos, 8));
  const uint64_t n = GetUint(bytes, &pos, 8);
  const int64_t t = static_cast<int64_t>(GetUint(bytes, &pos, 8));
  const double lambda = GetDouble(bytes, &pos);
  // 16 n + header overflows only for a corrupt n.
  const bool representable = n <= (UINT64_MAX - kHeaderBytes) / 16;
  if (!representable || bytes.size() != kHeaderBytes + 16 * n) {
    return Status::Error(path + ": truncated or corrupt (" + std::to_string(bytes.size()) +
                         " bytes; the header's " + std::to_string(n) + " moments need " +
                         (representable ? std::to_string(kHeaderBytes + 16 * n) : "more") + ")");
  }
  if (checkpoint->outer_done < 0 || t < 0 || !std::isfinite(lambda) || lambda < 0.0) {
    return Status::Error(path + ": corrupt header (negative outer_done or t, or invalid lambda)");
  }
  AdamState& s = checkpoint->state;
  s.t = t;
  s.lambda = lambda;
  s.m.resize(n);
  s.v.resize(n);
  for (double& m : s.m) m = GetDouble(bytes, &pos);
  for (double& v : s.v) v = GetDouble(bytes, &pos);
  for (uint64_t k = 0; k < n; ++k) {
    if (!std::isfinite(s.m[k]) || !(s.v[k] >= 0.0) || !std::isfinite(s.v[k])) {
      return Status::Error(path + ": corrupt moments (entry " + std::to_string(k) +
                           " is not finite or has a negative second moment)");
    }
  }
  return Status::Ok();
}

void RemoveAdamCheckpoint(const std::string& out) {
  std::error_code ec;
  std::filesystem::remove(JoinPath(out, kAdamStateFile), ec);
}

}  // namespace sft
