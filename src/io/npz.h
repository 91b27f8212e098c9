// NumPy's .npz archives (numpy.savez / savez_compressed): a zip file whose members NAME.npy are
// .npy arrays (npy.h). The zip container is read with libzip (stored and deflated members, CRC
// checked); each member is parsed by ParseNpy. Core and libzip only, for the fuzz target.
#ifndef SFT_IO_NPZ_H_
#define SFT_IO_NPZ_H_

#include <map>
#include <string>

#include "src/core/status.h"
#include "src/io/npy.h"

namespace sft {

// Limits against hostile archives (checked from the zip directory before anything is read):
// members, and uncompressed bytes per member and in all.
constexpr int64_t kMaxNpzMembers = 100000;
constexpr int64_t kMaxNpzMemberBytes = int64_t{1} << 28;
constexpr int64_t kMaxNpzTotalBytes = int64_t{1} << 30;

// Parses an archive held in `bytes`: every member whose name ends in ".npy" becomes
// (*arrays)[name without ".npy"]; other members are ignored. `file` prefixes the errors
// ("cameras.npz: not a zip archive (...)", "cameras.npz: world_mat_0.npy: descr ...").
Status ParseNpz(const std::string& bytes, const std::string& file,
                std::map<std::string, NpyArray>* arrays);

// Reads and parses the file at `path`.
Status ReadNpz(const std::string& path, std::map<std::string, NpyArray>* arrays);

}  // namespace sft

#endif  // SFT_IO_NPZ_H_
