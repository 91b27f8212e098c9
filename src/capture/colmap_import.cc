#include "src/capture/colmap_import.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "src/capture/auto_masks.h"
#include "src/capture/import_files.h"
#include "src/capture/probe_alignment.h"
#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/colmap_model.h"
#include "src/io/dataset.h"
#include "src/io/point_cloud_ply.h"

namespace sft {
namespace {

// The support disc's radius: this quantile of its points' distances from its centre (a few stray
// points on the plane's far side of the room do not make a table a floor).
constexpr double kSupportDiscQuantile = 0.99;

namespace fs = std::filesystem;

// Camera "c<ID>" for every COLMAP camera that a registered image uses.
Status ConvertCameras(const ColmapModel& model, Dataset* dataset,
                      std::map<uint32_t, int>* camera_index) {
  std::set<uint32_t> used;
  for (const ColmapImage& image : model.images) used.insert(image.camera_id);
  for (const ColmapCamera& source : model.cameras) {
    if (used.count(source.id) == 0) continue;
    const std::string name = "camera " + std::to_string(source.id);
    Camera camera;
    camera.id = "c" + std::to_string(source.id);
    if (!CameraModelFromName(source.model, &camera.model)) {
      return Status::Error(name + ": camera model " + source.model +
                           " is not supported by sft (supported: SIMPLE_PINHOLE, PINHOLE, "
                           "SIMPLE_RADIAL, RADIAL, OPENCV)");
    }
    if (source.width > static_cast<uint64_t>(kMaxCameraSide) ||
        source.height > static_cast<uint64_t>(kMaxCameraSide) ||
        static_cast<int64_t>(source.width * source.height) > kMaxCameraPixels) {
      return Status::Error(name + ": size " + std::to_string(source.width) + "x" +
                           std::to_string(source.height) + " is larger than sft accepts");
    }
    camera.width = static_cast<int>(source.width);
    camera.height = static_cast<int>(source.height);
    camera.params = source.params;
    std::string why;
    if (!camera.Check(&why)) return Status::Error(name + ": " + why);
    (*camera_index)[source.id] = static_cast<int>(dataset->cameras.size());
    dataset->cameras.push_back(camera);
  }
  return Status::Ok();
}

// Copies or converts one image into `root`/`out_name`; `*encoding` describes the source.
Status ImportImage(const std::string& source, const Camera& camera, const std::string& root,
                   const std::string& out_name, std::string* encoding) {
  cv::Mat mat;
  SFT_RETURN_IF_ERROR(ReadImageAsStored(source, cv::IMREAD_UNCHANGED, &mat));
  if (mat.cols != camera.width || mat.rows != camera.height) {
    return Status::Error(source + ": image is " + std::to_string(mat.cols) + "x" +
                         std::to_string(mat.rows) + " but its camera " + camera.id + " is " +
                         std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  return StoreImportedImage(source, mat, root, out_name, encoding);
}

// Reads the mask of image `name` (FindMaskFile); writes it to `root`/`out_name` as 8-bit 0/255
// and returns its bits.
Status ImportMask(const std::string& masks, const std::string& name, const Camera& camera,
                  const std::string& root, const std::string& out_name, MaskBits* bits) {
  cv::Mat binary;
  SFT_RETURN_IF_ERROR(ReadMaskFile(masks, name, camera.width, camera.height, &binary));
  bits->width = binary.cols;
  bits->height = binary.rows;
  bits->inside.assign(binary.datastart, binary.dataend);
  return WritePngMat(JoinPath(root, out_name), binary);
}

// Loads an equirectangular probe as linear RGB: EXR as stored, Radiance HDR as decoded, 8/16-bit
// formats decoded from sRGB.
Status LoadProbeImage(const std::string& path, Image* rgb) {
  const std::string ext = FileExtension(path);
  if (ext == "exr") {
    Image image;
    SFT_RETURN_IF_ERROR(ReadImage(path, &image));
    *rgb = ToRgb(image);
    return Status::Ok();
  }
  cv::Mat mat;
  SFT_RETURN_IF_ERROR(ReadImageAsStored(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_COLOR, &mat));
  const int depth = mat.depth();
  if (depth != CV_8U && depth != CV_16U && depth != CV_32F) {
    return Status::Error(path + ": unsupported probe pixel type");
  }
  const bool linear = depth == CV_32F;
  const double max = depth == CV_8U ? 255.0 : depth == CV_16U ? 65535.0 : 1.0;
  cv::Mat values;
  mat.convertTo(values, CV_32FC3, 1.0 / max);
  *rgb = Image(values.cols, values.rows, 3);
  for (int y = 0; y < values.rows; ++y) {
    const cv::Vec3f* row = values.ptr<cv::Vec3f>(y);
    for (int x = 0; x < values.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = row[x][2 - c];  // OpenCV's BGR.
        rgb->at(x, y, c) = linear ? std::max(v, 0.0f) : SrgbToLinear(v);
      }
    }
  }
  return Status::Ok();
}

// Dense results beside the model: the first folder among MODEL, MODEL/.., MODEL/../.. (each also
// with a dense/ subfolder) that holds fused.ply or meshed-poisson.ply / meshed-delaunay.ply.
void FindDense(const std::string& model, std::string* mesh, std::string* points) {
  mesh->clear();
  points->clear();
  fs::path dir = fs::path(model);
  for (int up = 0; up < 3 && mesh->empty() && points->empty(); ++up) {
    for (const fs::path& d : {dir, dir / "dense"}) {
      for (const char* name : {"meshed-poisson.ply", "meshed-delaunay.ply"}) {
        if (mesh->empty() && FileExists((d / name).string())) *mesh = (d / name).string();
      }
      if (points->empty() && FileExists((d / "fused.ply").string())) {
        *points = (d / "fused.ply").string();
      }
    }
    dir = dir / "..";
  }
}

Status ImportDense(const std::string& mesh_path, const std::string& points_path,
                   const Similarity3d& source_from_world, const std::string& root,
                   Dataset* dataset) {
  const Similarity3d& s = source_from_world;
  auto to_world = [&s](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(s.rotation.conjugate() * (p - s.translation) / s.scale);
  };
  if (!mesh_path.empty()) {
    TriMesh mesh;
    SFT_RETURN_IF_ERROR(ReadMesh(mesh_path, &mesh));
    for (auto vh : mesh.vertices()) {
      const auto p = mesh.point(vh);
      const Eigen::Vector3d q = to_world(Eigen::Vector3d(p[0], p[1], p[2]));
      mesh.set_point(vh, TriMesh::Point(q.x(), q.y(), q.z()));
    }
    dataset->initial_mesh = "init/mesh.ply";
    SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(root, dataset->initial_mesh), mesh));
  }
  if (!points_path.empty()) {
    PointCloud cloud;
    SFT_RETURN_IF_ERROR(ReadPointCloudPly(points_path, &cloud));
    for (Eigen::Vector3d& p : cloud.positions) p = to_world(p);
    for (Eigen::Vector3d& n : cloud.normals) n = s.rotation.conjugate() * n;
    dataset->dense_points = "init/fused.ply";
    SFT_RETURN_IF_ERROR(WritePointCloudPly(JoinPath(root, dataset->dense_points), cloud));
  }
  return Status::Ok();
}

// Where image `name` goes: images/NAME with extension .png (EXR stays .exr); "_<id>" is added
// before the extension when two images would coincide.
std::string ImageOutputName(const ColmapImage& image, std::set<std::string>* taken) {
  const std::string ext = FileExtension(image.name) == "exr" ? ".exr" : ".png";
  std::string out = "images/" + WithoutExtension(image.name) + ext;
  if (!taken->insert(WithoutExtension(out)).second) {
    out = "images/" + WithoutExtension(image.name) + "_" + std::to_string(image.id) + ext;
    taken->insert(WithoutExtension(out));
  }
  return out;
}

// Copies every registered image (and its mask) into `root`, appending one view per image to
// `dataset` (poses still in the model's frame) and filling `observing` for the normalisation.
Status ImportViews(const ColmapImportOptions& opts, const ColmapModel& model,
                   const std::string& root, const std::map<uint32_t, int>& camera_index,
                   Dataset* dataset, std::vector<MaskBits>* masks,
                   std::unordered_map<uint32_t, ObservingView>* observing,
                   std::vector<std::string>* encodings) {
  std::set<std::string> taken;
  Progress progress("import", static_cast<int64_t>(model.images.size()), !opts.quiet);
  for (size_t i = 0; i < model.images.size(); ++i) {
    const ColmapImage& image = model.images[i];
    std::string why;
    if (!IsContainedRelativePath(image.name, &why)) {
      return Status::Error(opts.model + ": image " + std::to_string(image.id) + ": name \"" +
                           image.name + "\": " + why);
    }
    ViewSpec view;
    view.camera = camera_index.at(image.camera_id);
    const Camera& camera = dataset->cameras[view.camera];
    view.camera_id = camera.id;
    view.image = ImageOutputName(image, &taken);
    std::string encoding;
    SFT_RETURN_IF_ERROR(
        ImportImage(JoinPath(opts.images, image.name), camera, root, view.image, &encoding));
    if (std::find(encodings->begin(), encodings->end(), encoding) == encodings->end()) {
      encodings->push_back(encoding);
    }
    ObservingView& obs = (*observing)[image.id];
    obs.camera = camera;
    obs.cam_from_world.rotation = image.cam_from_world_rotation;
    obs.cam_from_world.translation = image.cam_from_world_translation;
    if (opts.HasMaskFolder()) {
      view.mask = "masks/" + WithoutExtension(view.image.substr(7)) + ".png";
      SFT_RETURN_IF_ERROR(
          ImportMask(opts.masks, image.name, camera, root, view.mask, &(*masks)[i]));
      obs.mask = &(*masks)[i];
    }
    view.cam_from_world = obs.cam_from_world;
    dataset->views.push_back(view);
    progress.Advance();
  }
  progress.Finish();

  return Status::Ok();
}

// --masks auto and the probe's alignment, on the written dataset (both need the normalised
// poses); rewrites scene.json when either ran.
Status AutoMasksAndProbe(const ColmapImportOptions& opts,
                         const std::vector<Eigen::Vector3d>& sparse, const SupportPlane& plane,
                         Dataset* dataset, ColmapImportReport* report) {
  if (opts.masks == "auto") {
    AutoMaskOptions mask_options = opts.auto_masks;
    mask_options.quiet = mask_options.quiet || opts.quiet;
    SFT_RETURN_IF_ERROR(WriteAutoMasks(dataset, sparse, &plane, mask_options));
    report->auto_masks = static_cast<int>(dataset->views.size());
  }
  if (!opts.probe.empty() && opts.align_probe) {
    ProbeAlignmentOptions align = opts.alignment;
    align.quiet = align.quiet || opts.quiet;
    const Status status = AlignProbe(*dataset, 0, align, &report->alignment);
    if (!status.ok()) {
      return Status::Error(status.message() + " (--no-align-probe imports the probe unaligned)");
    }
    dataset->lights[0].world_from_env = report->alignment.world_from_env;
    dataset->lighting = AlignedProbeLighting(report->alignment);
    report->probe_aligned = true;
  }
  if (opts.masks != "auto" && !report->probe_aligned) return Status::Ok();
  return WriteSceneJson(*dataset, dataset->root);
}

// The probe as the environment light of every view (aligned later), or "lighting": "unknown".
Status AddProbeLight(const ColmapImportOptions& opts, const std::string& root, Dataset* dataset) {
  if (!opts.probe.empty()) {
    Image probe;
    SFT_RETURN_IF_ERROR(LoadProbeImage(opts.probe, &probe));
    LightSpec light;
    light.id = "probe";
    light.type = LightType::kEnvironment;
    light.image = "probes/" + fs::path(opts.probe).stem().string() + ".exr";
    SFT_RETURN_IF_ERROR(WriteExr(JoinPath(root, light.image), probe));
    dataset->lights.push_back(light);
    for (ViewSpec& view : dataset->views) {
      view.lights = {0};
      view.light_ids = {light.id};
    }
    dataset->background = Background::kEnvironment;
    dataset->lighting = "probe not yet aligned (world_from_env = identity)";
  } else {
    dataset->lighting = "unknown";
  }
  return Status::Ok();
}

Status ImportInto(const ColmapImportOptions& opts, const std::string& root,
                  ColmapImportReport* report) {
  ColmapModel model;
  SFT_RETURN_IF_ERROR(ReadColmapModel(opts.model, &model, &report->format));
  if (model.images.empty()) return Status::Error(opts.model + ": the model has no images");
  std::sort(model.images.begin(), model.images.end(),
            [](const ColmapImage& a, const ColmapImage& b) { return a.id < b.id; });
  Dataset dataset;
  dataset.root = root;
  std::map<uint32_t, int> camera_index;
  SFT_RETURN_IF_ERROR(ConvertCameras(model, &dataset, &camera_index).Prefixed(opts.model));

  // Images and masks, with the views in the model's frame for the normalisation.
  std::vector<MaskBits> masks(!opts.HasMaskFolder() ? 0 : model.images.size());
  std::unordered_map<uint32_t, ObservingView> observing;
  std::vector<std::string> encodings;
  SFT_RETURN_IF_ERROR(
      ImportViews(opts, model, root, camera_index, &dataset, &masks, &observing, &encodings));

  NormalizationResult& norm = report->normalization;
  SFT_RETURN_IF_ERROR(
      ComputeNormalization(model, observing, opts.normalization, &norm).Prefixed(opts.model));
  masks.clear();
  // p_source = d * p_world + c: the world is the model's frame centred on the object's box and
  // scaled to a unit diagonal. A camera's translation becomes (t + R c) / d.
  Similarity3d& s = dataset.source_from_world;
  s.scale = norm.diagonal;
  s.translation = norm.centre;
  dataset.has_source_from_world = true;
  for (ViewSpec& view : dataset.views) {
    Rigid3d& pose = view.cam_from_world;
    pose.translation = (pose.translation + (pose.rotation * norm.centre)) / norm.diagonal;
  }

  // The sparse points in the normalised world; those not on or beyond the support plane seed
  // --masks auto.
  PointCloud sparse;
  std::vector<Eigen::Vector3d> seeds;
  for (const ColmapPoint3D& point : model.points) {
    sparse.positions.push_back((point.xyz - norm.centre) / norm.diagonal);
    sparse.colors.push_back(point.rgb);
    if (!norm.plane.OffObject(point.xyz)) seeds.push_back(sparse.positions.back());
  }
  dataset.sparse_points = "sparse/points3D.ply";
  SFT_RETURN_IF_ERROR(WritePointCloudPly(JoinPath(root, dataset.sparse_points), sparse));

  if (opts.import_dense) {
    FindDense(opts.model, &report->dense_mesh, &report->dense_points);
    SFT_RETURN_IF_ERROR(ImportDense(report->dense_mesh, report->dense_points, s, root, &dataset));
  }

  SFT_RETURN_IF_ERROR(AddProbeLight(opts, root, &dataset));
  // The support plane in the normalised world (n·p_source + offset with p_source = d·p + c); its
  // point is the world origin (the object's box centre) dropped onto it. `sft init` and
  // reconstruct's carve cut the hull there (src/init/visual_hull.h).
  SupportPlane world_plane = norm.plane;
  world_plane.offset = (norm.plane.normal.dot(norm.centre) + norm.plane.offset) / norm.diagonal;
  world_plane.band = norm.plane.band / norm.diagonal;
  if (norm.plane.found) {
    dataset.has_support_plane = true;
    dataset.support_normal = world_plane.normal;
    dataset.support_point = -world_plane.offset * world_plane.normal;
  }
  // --probe-ground: the support plane's normal (a direction: the normalisation has no rotation).
  const bool probe_ground = opts.normalization.plane.hides_probe && !opts.probe.empty();
  if (probe_ground && norm.plane.found) {
    LightSpec& probe = dataset.lights[0];
    probe.ground_normal = norm.plane.normal;
    // The support as a disc around the support point: past a table's edge the probe still lights
    // the object from below the horizon.
    Eigen::Vector3d centre;
    double radius = 0;
    if (FindSupportDisc(world_plane, sparse.positions, Eigen::Vector3d::Zero(),
                        kSupportDiscQuantile, &centre, &radius)) {
      probe.ground_point = centre;
      probe.ground_radius = radius;
      report->probe_ground_radius = radius;
    }
  }
  report->probe_ground_requested = probe_ground;
  report->probe_ground = probe_ground && norm.plane.found;

  std::string encoding;
  for (const std::string& e : encodings) encoding += (encoding.empty() ? "" : "; ") + e;
  dataset.image_encoding = encoding;
  nlohmann::json normalization = {{"method", norm.method},
                                  {"points_total", norm.points_total},
                                  {"points_used", norm.points_used}};
  if (norm.plane.found) normalization["support_plane_points"] = norm.plane.off_object;
  if (probe_ground) normalization["probe_ground"] = norm.plane.found;
  dataset.extra["import"] = {{"from", "colmap"},
                             {"model", opts.model},
                             {"model_format", report->format},
                             {"normalization", normalization}};
  report->cameras = static_cast<int>(dataset.cameras.size());
  report->views = static_cast<int>(dataset.views.size());
  SFT_RETURN_IF_ERROR(WriteSceneJson(dataset, root));
  Dataset check;
  SFT_RETURN_IF_ERROR(ReadDataset(root, &check));
  return AutoMasksAndProbe(opts, seeds, world_plane, &check, report);
}

}  // namespace

bool ColmapImportOptions::Check(std::string* why) const {
  if (model.empty())
    *why = "--model: required";
  else if (images.empty())
    *why = "--images: required";
  else if (out.empty())
    *why = "--out: required";
  else if (!normalization.Check(why))
    return false;
  else if (!alignment.Check(why))
    return false;
  else if (!auto_masks.Check(why))
    return false;
  else
    return true;
  return false;
}

Status ImportColmap(const ColmapImportOptions& opts, ColmapImportReport* report) {
  const auto start = std::chrono::steady_clock::now();
  *report = ColmapImportReport();
  std::string why;
  if (!opts.Check(&why)) return Status::Error(why);
  std::error_code ec;
  for (const auto& [flag, dir] : {std::pair<const char*, std::string>{"--model", opts.model},
                                  {"--images", opts.images},
                                  {"--masks", opts.HasMaskFolder() ? opts.masks : ""}}) {
    if (!dir.empty() && !fs::is_directory(dir, ec)) {
      return Status::Error(std::string(flag) + ": " + dir + ": folder not found");
    }
  }
  if (!opts.probe.empty() && !FileExists(opts.probe)) {
    return Status::Error("--probe: " + opts.probe + ": file not found");
  }
  std::string dense_mesh, dense_points;
  if (opts.import_dense) FindDense(opts.model, &dense_mesh, &dense_points);
  const RunInputs inputs{{opts.model, opts.images, opts.HasMaskFolder() ? opts.masks : ""},
                         {opts.probe, dense_mesh, dense_points}};
  const Status status = BuildDatasetFolder(
      opts.out, inputs, opts.overwrite,
      [&](const std::string& partial) { return ImportInto(opts, partial, report); });
  report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return status;
}

}  // namespace sft
