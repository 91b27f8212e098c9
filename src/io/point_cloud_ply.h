// Point clouds in PLY files (sparse points of an import, COLMAP's fused.ply): positions with
// optional normals and 8-bit colours. Pure parsing, core layer only (fuzzable alone, like
// colmap_model.h).
//
// Reading takes the "vertex" element of an ascii or binary_little_endian PLY whose vertex
// properties are scalars (char/uchar/short/ushort/int/uint/float/double or their int8...float64
// names); it needs x, y, z, takes nx, ny, nz and red, green, blue when all three are present, and
// ignores other properties and the elements after "vertex" (faces of a mesh are not read).
// Elements before "vertex" are not supported. Counts are checked against the file's size before
// anything is allocated.
#ifndef SFT_IO_POINT_CLOUD_PLY_H_
#define SFT_IO_POINT_CLOUD_PLY_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

struct PointCloud {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3d> normals;        // empty, or one per position.
  std::vector<std::array<uint8_t, 3>> colors;  // empty, or one per position (RGB).
};

// Parses PLY file contents; `file` names the file in error messages.
Status ParsePointCloudPly(const std::string& data, const std::string& file, PointCloud* cloud);
Status ReadPointCloudPly(const std::string& path, PointCloud* cloud);

// Writes binary little-endian PLY: double x, y, z; float nx, ny, nz and uchar red, green, blue
// when present. Atomic (temporary file + rename). Error when normals/colors have the wrong size.
Status WritePointCloudPly(const std::string& path, const PointCloud& cloud);

}  // namespace sft

#endif  // SFT_IO_POINT_CLOUD_PLY_H_
