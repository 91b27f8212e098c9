#include "tests/testing/npz_writer.h"

#include <gtest/gtest.h>
#include <zip.h>

#include <cstdlib>
#include <cstring>

namespace sft {
namespace testing {

std::string NpyBytes(const std::vector<int64_t>& shape, const std::vector<double>& values,
                     const std::string& descr, bool fortran_order) {
  std::string dims;
  for (size_t i = 0; i < shape.size(); ++i) dims += (i ? ", " : "") + std::to_string(shape[i]);
  if (shape.size() == 1) dims += ",";
  std::string header = "{'descr': '" + descr +
                       "', 'fortran_order': " + (fortran_order ? "True" : "False") +
                       ", 'shape': (" + dims + "), }";
  // Magic (6) + version (2) + length (2) + header + '\n' is a multiple of 64.
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string bytes("\x93NUMPY\x01\x00", 8);
  bytes += static_cast<char>(header.size() & 0xff);
  bytes += static_cast<char>(header.size() >> 8);
  bytes += header;
  for (double v : values) {
    if (descr == "<f4") {
      const float f = static_cast<float>(v);
      char raw[4];
      std::memcpy(raw, &f, 4);
      bytes.append(raw, 4);
    } else {
      char raw[8];
      std::memcpy(raw, &v, 8);
      bytes.append(raw, 8);
    }
  }
  return bytes;
}

void WriteZip(const std::string& path, const std::map<std::string, std::string>& members,
              bool compress) {
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  if (archive == nullptr) {
    ADD_FAILURE() << path << ": zip_open failed (" << error << ")";
    return;
  }
  for (const auto& [name, bytes] : members) {
    // The buffer must live until zip_close: hand libzip a copy it frees itself.
    void* copy = std::malloc(bytes.size() + 1);
    std::memcpy(copy, bytes.data(), bytes.size());
    zip_source_t* source = zip_source_buffer(archive, copy, bytes.size(), 1);
    const zip_int64_t index =
        source == nullptr ? -1 : zip_file_add(archive, name.c_str(), source, ZIP_FL_OVERWRITE);
    if (index < 0) {
      if (source != nullptr) zip_source_free(source);
      ADD_FAILURE() << path << ": cannot add " << name << ": " << zip_strerror(archive);
      zip_discard(archive);
      return;
    }
    zip_set_file_compression(archive, index, compress ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0);
  }
  if (zip_close(archive) != 0) {
    ADD_FAILURE() << path << ": zip_close failed: " << zip_strerror(archive);
    zip_discard(archive);
  }
}

}  // namespace testing
}  // namespace sft
