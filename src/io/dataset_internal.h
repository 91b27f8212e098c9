// Shared between the scene.json reader (dataset.cc) and writer (dataset_write.cc) of
// src/io/dataset.h; not part of the API.
#ifndef SFT_IO_DATASET_INTERNAL_H_
#define SFT_IO_DATASET_INTERNAL_H_

#include <cstddef>
#include <string>

namespace sft {
namespace dataset_internal {

inline constexpr char kFormatTag[] = "sft-dataset/1";
inline constexpr char kSceneFile[] = "scene.json";

// "views[3]" from ("views", 3): the JSON path of an array element in error messages.
std::string IndexPath(const std::string& prefix, size_t i);

// "[json.exception.parse_error.101] parse error at ..." -> "parse error at ...".
std::string StripJsonExceptionId(const std::string& what);

// "640x480", for error messages.
std::string SizeText(int width, int height);

}  // namespace dataset_internal
}  // namespace sft

#endif  // SFT_IO_DATASET_INTERNAL_H_
