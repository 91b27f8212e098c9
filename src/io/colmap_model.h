// COLMAP sparse models (cameras, images, points3D) in COLMAP 3.x's text and binary formats, as
// written by `colmap mapper` and `colmap model_converter`. Pure parsing: this file depends on the
// core layer and Eigen only (no Embree, Ceres, OpenCV), so fuzz targets can link it alone; every
// format has a parser from an in-memory buffer.
//
// Formats (COLMAP's src/base/reconstruction.cc, facts only):
//   cameras.txt   CAMERA_ID MODEL WIDTH HEIGHT PARAMS...
//   images.txt    two lines per image: IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then
//                 X Y POINT3D_ID triples (POINT3D_ID -1 = none); the second line may be empty.
//   points3D.txt  POINT3D_ID X Y Z R G B ERROR (IMAGE_ID POINT2D_IDX)...
//   '#' starts a comment line; blank lines between records are skipped.
//   cameras.bin   u64 count; per camera: u32 id, i32 model_id, u64 width, u64 height,
//                 f64 params[n(model)].
//   images.bin    u64 count; per image: u32 id, f64 qvec[4] (w, x, y, z), f64 tvec[3], u32
//                 camera_id, NUL-terminated name, u64 num_points2D, then (f64 x, f64 y, u64
//                 point3D_id) each (2^64 − 1 = none).
//   points3D.bin  u64 count; per point: u64 id, f64 xyz[3], u8 rgb[3], f64 error, u64
//                 track_length, then (u32 image_id, u32 point2D_idx) each.
// All little-endian. Every count read from a binary file is checked against the bytes left in the
// file before anything is allocated. (qvec, tvec) is cam_from_world.
//
// The readers keep every COLMAP camera model (their parameter counts are needed to parse the
// binary format); which of them sft can render is decided by the importer.
#ifndef SFT_IO_COLMAP_MODEL_H_
#define SFT_IO_COLMAP_MODEL_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace sft {

struct ColmapCamera {
  uint32_t id = 0;
  std::string model;  // COLMAP's name, e.g. "PINHOLE", "OPENCV", "FULL_OPENCV".
  uint64_t width = 0;
  uint64_t height = 0;
  std::vector<double> params;  // COLMAP's order for the model.
};

struct ColmapImage {
  uint32_t id = 0;
  Eigen::Quaterniond cam_from_world_rotation = Eigen::Quaterniond::Identity();  // normalised.
  Eigen::Vector3d cam_from_world_translation = Eigen::Vector3d::Zero();
  uint32_t camera_id = 0;
  std::string name;                       // relative to the image folder, as COLMAP stores it.
  std::vector<Eigen::Vector2d> points2d;  // pixel coordinates (COLMAP's: centre of (0,0) at 0.5).
  std::vector<int64_t> point3d_ids;       // parallel to points2d; -1 = not triangulated.
};

struct ColmapTrackElement {
  uint32_t image_id = 0;
  uint32_t point2d_index = 0;
};

struct ColmapPoint3D {
  uint64_t id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::array<uint8_t, 3> rgb = {0, 0, 0};
  double error = 0;  // mean reprojection error, pixels (−1 when unknown).
  std::vector<ColmapTrackElement> track;
};

struct ColmapModel {
  std::vector<ColmapCamera> cameras;
  std::vector<ColmapImage> images;
  std::vector<ColmapPoint3D> points;
};

// COLMAP's model table: name <-> id and parameter count. False for an unknown name or id.
bool ColmapModelFromId(int model_id, std::string* name, int* num_params);
bool ColmapModelNumParams(const std::string& name, int* num_params);

// Parsers of one file's contents. `file` names the file in error messages ("DIR/cameras.txt:
// line 7: ..." for text, "DIR/cameras.bin: camera 3: ..." for binary). They append to `out`
// (which they clear first) and check each record on its own (known model, parameter count, finite
// numbers, non-zero quaternion, no duplicate ids); cross-file references are checked by
// CheckColmapModel.
Status ParseColmapCamerasText(const std::string& data, const std::string& file,
                              std::vector<ColmapCamera>* out);
Status ParseColmapImagesText(const std::string& data, const std::string& file,
                             std::vector<ColmapImage>* out);
Status ParseColmapPointsText(const std::string& data, const std::string& file,
                             std::vector<ColmapPoint3D>* out);
Status ParseColmapCamerasBinary(const std::string& data, const std::string& file,
                                std::vector<ColmapCamera>* out);
Status ParseColmapImagesBinary(const std::string& data, const std::string& file,
                               std::vector<ColmapImage>* out);
Status ParseColmapPointsBinary(const std::string& data, const std::string& file,
                               std::vector<ColmapPoint3D>* out);

// Cross-file consistency: every image's camera exists; every track element names an existing
// image and one of its 2D points; image names are non-empty. `dir` prefixes the messages.
Status CheckColmapModel(const ColmapModel& model, const std::string& dir);

// Reads DIR's model: the binary files when DIR has cameras.bin, images.bin and points3D.bin,
// else the text files (cameras.txt, images.txt, points3D.txt); an error names what is missing.
// `*format` (optional) receives "binary" or "text".
Status ReadColmapModel(const std::string& dir, ColmapModel* model, std::string* format = nullptr);

}  // namespace sft

#endif  // SFT_IO_COLMAP_MODEL_H_
