// NumPy .npy and .npz files written by tests (fixtures for src/io/npy.h, npz.h and `sft import
// idr`), so that no binary fixture needs to be checked in. The zip container is written with
// libzip.
#ifndef SFT_TESTS_TESTING_NPZ_WRITER_H_
#define SFT_TESTS_TESTING_NPZ_WRITER_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace sft {
namespace testing {

// A .npy file (version 1.0) of `values` with the given shape: "<f4" writes 4-byte floats, any
// other `descr` 8-byte doubles under that descr (so ">f8" or "<i8" make rejection fixtures);
// `fortran_order` only changes the header.
std::string NpyBytes(const std::vector<int64_t>& shape, const std::vector<double>& values,
                     const std::string& descr = "<f8", bool fortran_order = false);

// Writes a zip archive with one member per entry (name -> bytes), deflated when `compress`.
// Aborts the test (ADD_FAILURE) when libzip fails.
void WriteZip(const std::string& path, const std::map<std::string, std::string>& members,
              bool compress = true);

}  // namespace testing
}  // namespace sft

#endif  // SFT_TESTS_TESTING_NPZ_WRITER_H_
