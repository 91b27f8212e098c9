// NumPy's .npy array files (numpy.org/neps/nep-0001-npy-format.html, facts only): the magic
// "\x93NUMPY", a major and minor version byte, the header length (2 bytes little-endian for
// version 1, 4 bytes for versions 2 and 3), a header that is a Python dict literal
//   {'descr': '<f8', 'fortran_order': False, 'shape': (4, 4), }
// padded with spaces to a newline, then the raw values. sft reads little-endian float64 ('<f8')
// and float32 ('<f4') in C order, which is what numpy writes for the camera matrices of the
// IDR/NeuS datasets; anything else is one error naming the array and the field. Pure parsing (core
// only), for the fuzz target.
#ifndef SFT_IO_NPY_H_
#define SFT_IO_NPY_H_

#include <cstdint>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

struct NpyArray {
  std::vector<int64_t> shape;  // numpy's shape; empty for a scalar (0-d array).
  std::vector<double> values;  // C order (last index fastest), converted to double.
};

// Largest array accepted, in values (the size is checked against the bytes present before
// anything is allocated).
constexpr int64_t kMaxNpyValues = int64_t{1} << 27;

// Parses a whole .npy file held in `bytes`; `name` prefixes the errors ("cameras.npz:
// world_mat_0.npy: descr '>f8' is not supported (need '<f8' or '<f4')"). The data must fill
// exactly the bytes after the header.
Status ParseNpy(const std::string& bytes, const std::string& name, NpyArray* array);

// "(4, 4)" for messages.
std::string NpyShapeText(const std::vector<int64_t>& shape);

}  // namespace sft

#endif  // SFT_IO_NPY_H_
