// sft init: an initial mesh for a dataset by visual-hull carving of its masks (docs/init.md).
//
//   sft init --dataset D [--out DIR] [--resolution 128] [--faces 10000] [--points P.ply]
//            [--overwrite] [--quiet]
//
// Writes DIR/mesh.ply. Without --out, DIR is D/init: this is the one command that adds to the
// dataset it reads. It then writes D/init/mesh.ply (atomically) and, when scene.json has no
// "initial_mesh" key, adds "initial_mesh": "init/mesh.ply" to it (atomically, every other key kept
// with its value and order); no other file of D is touched. With --out nothing is written into D.
// An existing mesh.ply is replaced only with --overwrite. A JSON summary goes to stdout.
//
// Sparse points: --points, else the file that scene.json's "sparse_points" names, else
// D/sparse/points3D.ply when it exists; they are counted against the hull
// (src/init/initial_mesh.h).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/core/memory.h"
#include "src/geometry/mesh.h"
#include "src/init/initial_mesh.h"
#include "src/init/stereo_mesh.h"
#include "src/io/dataset.h"
#include "src/io/point_cloud_ply.h"

namespace sft {
namespace {

namespace fs = std::filesystem;

constexpr char kInitialMeshKey[] = "initial_mesh";
constexpr char kDefaultMeshPath[] = "init/mesh.ply";
constexpr char kDefaultPointsPath[] = "sparse/points3D.ply";

struct InitCommandOptions {
  std::string dataset;      // the dataset (read; written only without --out).
  std::string out;          // output folder; "" = D/init.
  std::string points;       // sparse points PLY in the dataset's world frame; "" = default.
  InitialMeshOptions mesh;  // resolution, faces.
  bool overwrite = false;   // replace an existing mesh.ply.
  bool quiet = false;       // no progress line.
};

// The sparse point file to use ("" when there is none): --points, scene.json's "sparse_points",
// or D/sparse/points3D.ply if it exists.
Status FindPointsFile(const InitCommandOptions& opts, const nlohmann::ordered_json& scene,
                      std::string* path) {
  path->clear();
  if (!opts.points.empty()) {
    *path = opts.points;
    return Status::Ok();
  }
  auto it = scene.find("sparse_points");
  if (it != scene.end() && it->is_string()) {
    std::string why;
    const std::string relative = it->get<std::string>();
    if (!IsContainedRelativePath(relative, &why)) {
      return Status::Error(JoinPath(opts.dataset, "scene.json") + ": sparse_points: " + why);
    }
    *path = JoinPath(opts.dataset, relative);
    return Status::Ok();
  }
  const std::string fallback = JoinPath(opts.dataset, kDefaultPointsPath);
  if (FileExists(fallback)) *path = fallback;
  return Status::Ok();
}

// Adds "initial_mesh" to D/scene.json when absent (atomic rewrite, other keys and order kept, the
// indentation WriteSceneJson uses). Sets *added; *existing is the value already there, if any.
Status AddInitialMeshKey(const std::string& dataset, nlohmann::ordered_json scene, bool* added,
                         std::string* existing) {
  *added = false;
  auto it = scene.find(kInitialMeshKey);
  if (it != scene.end()) {
    *existing = it->is_string() ? it->get<std::string>() : it->dump();
    return Status::Ok();
  }
  scene[kInitialMeshKey] = kDefaultMeshPath;
  const std::string text =
      scene.dump(1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
  SFT_RETURN_IF_ERROR(WriteTextFile(JoinPath(dataset, "scene.json"), text));
  *added = true;
  return Status::Ok();
}

nlohmann::ordered_json Summary(const std::string& mesh_path, const std::string& points_path,
                               const InitialMeshReport& r) {
  const Eigen::Vector3d hi = r.box.lo + r.box.voxel_size * r.box.dims.cast<double>();
  return {
      {"mesh", mesh_path},
      {"faces", r.faces},
      {"vertices", r.vertices},
      {"carving_box",
       {{"lo", {r.box.lo.x(), r.box.lo.y(), r.box.lo.z()}}, {"hi", {hi.x(), hi.y(), hi.z()}}}},
      {"voxel_size", r.box.voxel_size},
      {"voxels", {r.box.dims.x(), r.box.dims.y(), r.box.dims.z()}},
      {"min_views", r.min_views},
      {"outlier_views", r.outlier_views},
      {"support_plane", r.support},
      {"support_contact", r.support_contact},
      {"inside_voxels", r.inside_voxels},
      {"extracted_triangles", r.extracted_triangles},
      {"components", r.cleanup.components},
      {"dropped_triangles", r.cleanup.dropped_triangles},
      {"split_vertices", r.cleanup.split_vertices},
      {"sparse_points", points_path},
      {"points", r.points},
      {"points_outside_hull", r.points_outside},
      {"points_outside_box", r.points_outside_box},
      {"points_inside_hull", r.points_inside},
      {"carve_seconds", r.carve_seconds},
      {"extract_seconds", r.extract_seconds},
      {"decimate_seconds", r.decimate_seconds},
      {"seconds", r.total_seconds},
  };
}

nlohmann::ordered_json StereoSummary(const StereoMeshReport& r) {
  return {
      {"pairs", r.stereo.pairs},
      {"views_without_pair", r.stereo.views_without_pair},
      {"matched_pixels", r.stereo.matched_pixels},
      {"points", r.stereo.points},
      {"poisson_points", r.surface.points},
      {"spacing", r.surface.spacing},
      {"trimmed_voxels", r.surface.trimmed_voxels},
      {"components_removed", r.surface.components_removed},
      {"load_seconds", r.load_seconds},
      {"stereo_seconds", r.stereo.seconds},
      {"surface_seconds", r.surface.total_seconds},
  };
}

Status RunInit(const InitCommandOptions& opts) {
  std::string why;
  if (!opts.mesh.Check(&why)) return Status::Error("--" + why);
  if (opts.dataset.empty()) return Status::Error("--dataset: required");
  const bool into_dataset = opts.out.empty();
  std::string mesh_path;
  if (into_dataset) {
    const std::string init_dir = JoinPath(opts.dataset, "init");
    std::error_code ec;
    if (fs::exists(init_dir, ec) && !fs::is_directory(init_dir, ec)) {
      return Status::Error(init_dir + ": exists and is not a directory");
    }
    mesh_path = JoinPath(opts.dataset, kDefaultMeshPath);
    if (!opts.points.empty() && fs::exists(opts.points, ec) && fs::exists(mesh_path, ec) &&
        fs::equivalent(opts.points, mesh_path, ec)) {
      return Status::Error("--points: is the output " + mesh_path);
    }
  } else {
    SFT_RETURN_IF_ERROR(CheckOutputDirectory(opts.out, {{opts.dataset}, {opts.points}}, "--out"));
    mesh_path = JoinPath(opts.out, "mesh.ply");
  }
  if (FileExists(mesh_path) && !opts.overwrite) {
    return Status::Error(mesh_path + ": exists (use --overwrite to replace it)");
  }
  Dataset dataset;
  SFT_RETURN_IF_ERROR(ReadDataset(opts.dataset, &dataset));
  const std::string scene_path = JoinPath(opts.dataset, "scene.json");
  std::string scene_text;
  SFT_RETURN_IF_ERROR(ReadTextFile(scene_path, &scene_text));
  StripUtf8Bom(&scene_text);
  const nlohmann::ordered_json scene = nlohmann::ordered_json::parse(scene_text, nullptr, false);
  if (!scene.is_object()) return Status::Error(scene_path + ": not a JSON object");

  int64_t view_pixels = 0;
  for (const ViewSpec& view : dataset.views) {
    const Camera& camera = dataset.cameras[view.camera];
    view_pixels += int64_t{camera.width} * camera.height;
  }
  if (!CheckMemoryBudget(EstimateCarvingBytes(view_pixels, opts.mesh.hull.resolution),
                         "carving at --resolution " + std::to_string(opts.mesh.hull.resolution),
                         &why)) {
    return Status::Error(why);
  }
  std::string points_path;
  SFT_RETURN_IF_ERROR(FindPointsFile(opts, scene, &points_path));
  PointCloud cloud;
  if (!points_path.empty()) SFT_RETURN_IF_ERROR(ReadPointCloudPly(points_path, &cloud));
  const std::vector<Eigen::Vector3d>& points = cloud.positions;

  std::vector<CarvingView> views;
  SFT_RETURN_IF_ERROR(LoadCarvingViews(dataset, &views));
  InitialMeshOptions mesh_options = opts.mesh;
  mesh_options.progress = !opts.quiet;
  UseDatasetSupport(dataset, &mesh_options.hull);
  TriMesh mesh;
  InitialMeshReport report;
  SFT_RETURN_IF_ERROR(MakeInitialMesh(views, mesh_options, points, &mesh, &report));
  StereoMeshReport stereo_report;
  if (mesh_options.stereo) {
    std::vector<int> all(dataset.views.size());
    for (size_t v = 0; v < all.size(); ++v) all[v] = static_cast<int>(v);
    SFT_RETURN_IF_ERROR(
        MakeStereoMesh(dataset, all, views, mesh, mesh_options, &mesh, &stereo_report));
  }
  if (!into_dataset) SFT_RETURN_IF_ERROR(MakeDirectories(opts.out));
  SFT_RETURN_IF_ERROR(WriteMesh(mesh_path, mesh));

  nlohmann::ordered_json summary = Summary(mesh_path, points_path, report);
  if (mesh_options.stereo) {
    summary["faces"] = static_cast<int>(mesh.n_faces());
    summary["vertices"] = static_cast<int>(mesh.n_vertices());
    summary["stereo"] = StereoSummary(stereo_report);
  }
  if (into_dataset) {
    bool added = false;
    std::string existing;
    SFT_RETURN_IF_ERROR(AddInitialMeshKey(opts.dataset, scene, &added, &existing));
    summary["scene_json"] = added ? "added initial_mesh" : "initial_mesh already set";
    if (!added && existing != kDefaultMeshPath) {
      std::fprintf(stderr,
                   "sft init: warning: %s already names %s as the initial mesh; left unchanged\n",
                   scene_path.c_str(), existing.c_str());
    }
  }
  if (report.points_outside > 0) {
    std::fprintf(stderr,
                 "sft init: warning: %d of %d sparse points lie outside the hull by more than a "
                 "voxel (outliers, or masks that cut off part of the object)\n",
                 report.points_outside, report.points);
  }
  std::fputs((summary.dump(1) + "\n").c_str(), stdout);
  return Status::Ok();
}

}  // namespace

CommandRunner SetupInitCommand(CLI::App* app) {
  auto opts = std::make_shared<InitCommandOptions>();
  app->add_option("--dataset", opts->dataset, "Dataset with a mask per view")->required();
  app->add_option("--out", opts->out,
                  "Output folder for mesh.ply (default: the dataset's init/ folder, and "
                  "scene.json gains \"initial_mesh\")");
  app->add_option("--resolution", opts->mesh.hull.resolution,
                  "Voxels along the longest side of the carving box, [" +
                      std::to_string(VisualHullOptions::kMinResolution) + ", " +
                      std::to_string(VisualHullOptions::kMaxResolution) + "]")
      ->capture_default_str();
  app->add_option("--faces", opts->mesh.faces,
                  "Faces of the output mesh (decimated), [" +
                      std::to_string(InitialMeshOptions::kMinFaces) + ", " +
                      std::to_string(InitialMeshOptions::kMaxFaces) + "]")
      ->capture_default_str();
  app->add_option("--outlier-views", opts->mesh.hull.outlier_views,
                  "Views whose 'outside' a point may overrule: a point is carved away only when "
                  "more than this many of the views that see it put it outside their masks (0: "
                  "the exact visual hull; 1-2 keep what one or two wrong masks cut away), [0, " +
                      std::to_string(VisualHullOptions::kMaxOutlierViews) + "]")
      ->capture_default_str()
      ->check(CLI::Range(0, VisualHullOptions::kMaxOutlierViews));
  app->add_option("--support-contact", opts->mesh.hull.support_contact,
                  "Height of the contact band above the dataset's support_plane (scene units; "
                  "datasets have a unit diagonal): a point in it is inside when the point above "
                  "it at the band's top is, which gives back feet or a base the masks cut off; 0: "
                  "none. Without a support_plane it is ignored, [0, 1]")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app->add_option("--points", opts->points,
                  "Sparse points (PLY, world frame) to check the hull against (default: "
                  "scene.json's sparse_points, else sparse/points3D.ply if present)");
  app->add_flag("--stereo", opts->mesh.stereo,
                "Rebuild the carved hull from stereo: dense points from each view and its nearest "
                "neighbours (semi-global matching), Poisson reconstruction, intersected with the "
                "hull; gives back concavities silhouettes cannot see (docs/init.md)");
  app->add_option("--stereo-max-angle", opts->mesh.stereo_options.max_angle_deg,
                  "Stereo: largest angle (degrees) between a pair's views, seen from the object, "
                  "(0, 90]")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 90.0));
  app->add_option("--stereo-consistency", opts->mesh.stereo_options.consistency_pixels,
                  "Stereo: depth tolerance between the pairs of a view, in pixels of disparity, "
                  "(0, 16]")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 16.0));
  app->add_option("--stereo-pairs", opts->mesh.stereo_options.pairs_per_view,
                  "Stereo: nearest views matched with each view (any two that agree keep a "
                  "depth), [2, 8]")
      ->capture_default_str()
      ->check(CLI::Range(2, 8));
  app->add_option("--stereo-scale", opts->mesh.stereo_options.image_scale_log2,
                  "Stereo: match at 2^-N of the images' resolution, [0, 4]")
      ->capture_default_str()
      ->check(CLI::Range(0, 4));
  app->add_flag("--overwrite", opts->overwrite, "Replace an existing mesh.ply");
  app->add_flag("--quiet", opts->quiet, "No progress line");
  return [opts]() {
    const Status status = RunInit(*opts);
    return status.ok() ? 0 : PrintError("init", status);
  };
}

}  // namespace sft
