// libFuzzer target: the point-cloud PLY reader (src/io/point_cloud_ply.h).
#include <cstddef>
#include <cstdint>
#include <string>

#include "src/io/point_cloud_ply.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sft::PointCloud cloud;
  (void)sft::ParsePointCloudPly(std::string(reinterpret_cast<const char*>(data), size),
                                "points.ply", &cloud);
  return 0;
}
