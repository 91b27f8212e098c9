// The `sft-dataset/1` format (docs/dataset.md): a directory with scene.json, images/, masks/,
// probes/, gt/. This is a contract with other tools: unknown keys are preserved on round trips and
// the meaning of the documented keys never changes.
//
// Unknown keys are kept verbatim wherever other tools may put them: at the top level
// (Dataset::extra), inside each camera (Dataset::camera_extra), each light (LightSpec::extra),
// each view (ViewSpec::extra) and each view's `cam_from_world` (ViewSpec::cam_from_world_extra);
// `ground_truth` is kept whole (Dataset::ground_truth). WriteSceneJson writes them back after the
// documented keys, and a documented key always wins over a same-named extra. "Unknown" means not
// interpreted by this version: for a light, the keys of the other light type are unknown too
// (an environment light's "position" is kept as an extra).
//
// A read/write cycle reproduces scene.json exactly as JSON (key order and number formatting
// aside) except for these normalizations of documented keys: a non-unit quaternion is normalized;
// defaults are written out explicitly (point and directional light "frame": "world", environment
// light "world_from_env": identity and "scale": 1, view "lights": [], "background": "black"; an
// environment light's "frame": "world" is dropped, as files before that key had none); a grey
// point-light intensity or directional irradiance (one number) becomes [g, g, g]; a directional
// light's direction is scaled to unit length; a null "mask" or "ground_truth" is dropped; an
// integral float such as a width of 16.0 is written as 16.
#ifndef SFT_IO_DATASET_H_
#define SFT_IO_DATASET_H_

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"
#include "src/render/camera.h"

namespace sft {

enum class LightType { kPoint, kEnvironment, kDirectional };
enum class LightFrame { kWorld, kCamera };  // where a light is fixed (LightSpec::frame).
enum class Background { kBlack, kEnvironment };

// Largest camera accepted on read: at most 65536 pixels per side and 2^30 pixels (a 32768²
// image) in all. Far above any camera (the largest sensors have ~150 megapixels), and pixel
// indices stay within 32-bit integers. Whether a view that size fits into memory is checked
// where it is rendered (MakeDatasetViews).
constexpr int kMaxCameraSide = 65536;
constexpr int64_t kMaxCameraPixels = int64_t{1} << 30;

struct LightSpec {
  std::string id;
  LightType type = LightType::kPoint;
  // The frame the light is fixed in: the world, or each view's camera (it moves with the camera,
  // like a flash; for an environment, world_from_env then takes env directions to the camera
  // frame).
  LightFrame frame = LightFrame::kWorld;
  // Point lights.
  Eigen::Vector3d position = Eigen::Vector3d::Zero();   // in `frame`, scene units.
  Eigen::Vector3d intensity = Eigen::Vector3d::Zero();  // radiant intensity, W/sr, RGB.
  // Directional lights (a light at infinity, e.g. the sun). `direction` is the unit direction
  // the light travels (from the light towards the scene, as in Blender, Mitsuba and glTF), in
  // `frame`; normalized on read. `irradiance` is the irradiance on a surface facing the light,
  // W/m², RGB.
  Eigen::Vector3d direction = Eigen::Vector3d(0, 0, -1);
  Eigen::Vector3d irradiance = Eigen::Vector3d::Zero();
  // Environment lights.
  std::string image;  // relative to the dataset root: an equirectangular linear EXR.
  Eigen::Matrix3d world_from_env = Eigen::Matrix3d::Identity();
  double scale = 1.0;  // radiance = scale * texel value.
  // A ground plane the probe does not show (a world-frame environment only): when non-zero, the
  // unit world direction of "up"; directions d with d·ground_normal < 0 carry no radiance, as if an
  // infinite black floor lay under the object (docs/dataset.md). Zero = no ground.
  Eigen::Vector3d ground_normal = Eigen::Vector3d::Zero();
  // With ground_normal: a finite ground, a black disc of this radius (world units, > 0) centred at
  // `ground_point` in the plane through it, instead of the infinite floor: only the directions
  // that hit the disc from a shading point carry no radiance (a table top, past whose edge the
  // probe's light below the horizon still reaches the object). 0 = the infinite floor.
  double ground_radius = 0.0;
  Eigen::Vector3d ground_point = Eigen::Vector3d::Zero();  // the disc's centre, world frame.
  // An environment map held in memory instead of `image` (RGB, linear): the fitted environment of
  // unknown lighting (src/optim/fitted_environment.h). Never read from or written to scene.json.
  Image pixels;
  // Keys of this light's JSON object that this version does not interpret for its type, kept
  // verbatim (an object; null when there are none).
  nlohmann::json extra;
};

struct ViewSpec {
  std::string image;  // relative to the dataset root.
  std::string mask;   // relative; empty when the view has no mask.
  std::string camera_id;
  int camera = -1;  // index into Dataset::cameras, resolved by ReadDataset.
  std::vector<std::string> light_ids;
  std::vector<int> lights;  // indices into Dataset::lights, resolved by ReadDataset.
  Rigid3d cam_from_world;
  // Keys of the view's JSON object that this version does not interpret, kept verbatim (an
  // object; null when there are none).
  nlohmann::json extra;
  // The same for the keys of `cam_from_world` other than "rotation" and "translation".
  nlohmann::json cam_from_world_extra;
};

// A similarity transform y = scale * (rotation * x) + translation (docs/dataset.md
// "source_from_world": p_source = s·R·p + t).
struct Similarity3d {
  double scale = 1.0;  // > 0.
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  // Keys of the JSON object other than scale, rotation and translation, kept verbatim (or null).
  nlohmann::json extra;

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const {
    return scale * (rotation * x) + translation;
  }
};

struct Dataset {
  std::string root;  // the dataset directory (paths in the specs are relative to it).
  std::vector<Camera> cameras;
  // camera_extra[i]: keys of cameras[i]'s JSON object that this version does not interpret, kept
  // verbatim (an object, or null when there are none). Kept here because Camera is a render type.
  // Parallel to `cameras`, filled for every camera by ReadDataset; it may be shorter (or empty) in
  // a dataset built in code, and a missing entry means no extras. Code that reorders or removes
  // cameras must do the same here.
  std::vector<nlohmann::json> camera_extra;
  std::vector<LightSpec> lights;
  std::vector<ViewSpec> views;
  Background background = Background::kBlack;
  std::string gt_mesh;  // `ground_truth.mesh` (relative), empty when absent.
  // `ground_truth.shading`: how the images were rendered, "flat" or "smooth" (render.h's
  // Shading); empty when absent (real photographs: smooth surfaces).
  std::string gt_shading;
  nlohmann::json ground_truth;  // the whole `ground_truth` object as read (null when absent).
  // Optional keys written by importers (docs/dataset.md, docs/import.md); empty when absent.
  std::string sparse_points;           // "sparse_points": PLY point cloud (xyz, rgb), world frame.
  std::string initial_mesh;            // "initial_mesh": starting mesh, world frame.
  std::string dense_points;            // "dense_points": dense point cloud (e.g. COLMAP fused.ply).
  std::string image_encoding;          // "image_encoding": free text, where the pixels came from.
  std::string lighting;                // "lighting": free text, e.g. "unknown".
  bool has_source_from_world = false;  // "source_from_world" is present.
  Similarity3d source_from_world;      // maps this dataset's world into the import's frame.
  // "support_plane": the plane the object stands on (world frame), when the capture found one.
  bool has_support_plane = false;
  Eigen::Vector3d support_normal = Eigen::Vector3d::UnitZ();  // unit, towards the object.
  Eigen::Vector3d support_point = Eigen::Vector3d::Zero();    // a point of the plane.
  nlohmann::json extra;  // top-level keys this version does not interpret, kept verbatim.
};

// Reads and validates DIR/scene.json: format tag, camera models and parameter counts, positive
// sizes, quaternion length 4 (normalized on read; a zero quaternion is an error), translation
// length 3, every view's camera and lights exist, light types and fields, background value.
// Does not open images (see CheckDatasetFiles). Errors name the file and the JSON path, e.g.
// "data/x/scene.json: views[3].cam_from_world.rotation: expected 4 numbers, got 3".
Status ReadDataset(const std::string& dir, Dataset* dataset);
// The same from scene.json's contents held in memory (`dir` becomes Dataset::root and prefixes
// the messages); ReadDataset reads DIR/scene.json and calls this. Touches no file.
Status ParseSceneJson(std::string text, const std::string& dir, Dataset* dataset);

// Lights files (a "lights" array in scene.json's format): src/io/lights_file.h.

// Renderers need every view's lighting: an error naming the first view whose `lights` list is empty
// (unknown lighting, as importers write it; docs/dataset.md), else OK. Reading such a dataset is
// fine; commands that render it call this first.
Status CheckViewsHaveLights(const Dataset& dataset);

// Opens every view image, mask and light probe once and checks sizes against the cameras
// (an image whose size differs from its camera's is an error naming both sizes).
Status CheckDatasetFiles(const Dataset& dataset);

// The file or folder that `ground_truth.<key>` names, relative to the dataset's root, or "" when
// the key is absent or not a string; an error naming scene.json and the key when the path leaves
// the dataset (absolute, or with a ".." component).
Status GroundTruthPath(const Dataset& dataset, const std::string& key, std::string* relative);

// Writes DIR/scene.json atomically from `dataset` (root is ignored; paths are written as stored).
// Every extra (top level, camera, light, view, cam_from_world) is written back after the
// documented keys of its object; documented keys win over same-named extras. Extras that are not
// JSON objects are ignored. camera_extra entries beyond cameras.size() are ignored.
Status WriteSceneJson(const Dataset& dataset, const std::string& dir);

// Where a command writing one image per view puts view v's, relative to its output folder: the
// view's image path mirrored under "images/" (a leading "images/" component is not repeated) with
// `extension` (".exr"), so that per-camera subfolders stay apart: "images/cam1/000.png" ->
// "images/cam1/000.exr", "photos/a.jpg" -> "images/photos/a.exr". Views whose names would
// coincide (the same image twice, or "000.png" and "000.exr") get "_view<NNN>" before the
// extension, NNN the view index, so no output overwrites another. Paths are as read by
// ReadDataset (relative, no ".."), so the results never leave the output folder.
std::vector<std::string> ViewOutputPaths(const Dataset& dataset, const std::string& extension);

// Loads view `index`'s image as linear RGB (alpha dropped; 3 channels), checking its size.
Status LoadViewImage(const Dataset& dataset, int index, Image* rgb);
// Loads view `index`'s mask as a 1-channel image of 0/1 (> 127 = object). Error if no mask.
Status LoadViewMask(const Dataset& dataset, int index, Image* mask);
// Loads environment light `light_index`'s probe as linear RGB with negative texels clamped to 0.
Status LoadProbe(const Dataset& dataset, int light_index, Image* rgb);

}  // namespace sft

#endif  // SFT_IO_DATASET_H_
