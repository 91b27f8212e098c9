// sft synth: renders a synthetic dataset of a mesh in the report's setup: cameras on a Fibonacci
// sphere (or an orbit, --path orbit) looking at the object, one or more zoom levels, a
// camera-attached point light (or an environment probe), black background, masks from pixel
// coverage, and the ground truth (normalized mesh and material) under gt/. --ground adds a textured
// ground plane seen in the images only (src/io/synth_scene.h).
//
// Decisions (docs/cli.md "sft synth"): the mesh is centred on its bounding-box centre and scaled to
// a bounding-box diagonal of 1 (--no-normalize keeps it as is); --up-axis y rotates y-up meshes to
// the z-up world (x, y, z) -> (x, −z, y) as the Cycles dataset tool does; the camera distance puts
// the bounding sphere at --fill of the half-image at zoom 1; zoom z multiplies the focal length.
// The default light intensity gives a white Lambertian patch facing the camera at the object's
// centre a radiance of 0.5. The dataset is written to OUT.partial and renamed to OUT at the end.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "src/core/file_util.h"
#include "src/core/progress.h"
#include "src/geometry/material.h"
#include "src/geometry/mesh.h"
#include "src/image/image_io.h"
#include "src/io/dataset.h"
#include "src/io/scene_setup.h"
#include "src/io/synth_scene.h"
#include "src/render/camera_rig.h"
#include "src/render/render.h"

namespace sft {
namespace {
namespace fs = std::filesystem;

struct SynthOptions {
  std::string mesh;                        // input mesh path (OBJ, PLY, OFF).
  std::string out;                         // output dataset directory.
  std::string material;                    // material JSON file or inline JSON; "" = default.
  int cameras = 32;                        // cameras on the Fibonacci sphere, [1, 10000].
  std::vector<double> zooms = {1.0, 2.0};  // focal-length factors, one camera per zoom, > 0.
  int res = 128;                           // image width = height, pixels, [1, 16384].
  double fov_deg = 40.0;                   // field of view at zoom 1, degrees, (0, 179).
  double fill = 0.6;          // bounding-sphere radius / half image at zoom 1, (0, 10].
  std::string up_axis = "z";  // the mesh's up axis: "z" (as is) or "y" (rotated).
  bool normalize = true;      // centre the mesh and scale its bbox diagonal to 1.
  std::vector<double> light_offset = {0.15, 0.0, 0.0};  // point light in the camera frame.
  double light_intensity = 0.0;                         // W/sr, in (0, 1e30]; used when given.
  bool light_intensity_given = false;  // --light-intensity was given (else automatic).
  // World-frame direction the sun's light travels (x,y,z, any length); empty = no sun. A sun
  // replaces the point light (a directional light, docs/dataset.md).
  std::vector<double> sun;
  // Irradiance on a surface facing the sun, W/m², in (0, 1e30]; default 0.5·π (a white facing
  // patch then has radiance 0.5, as under the default flash).
  double sun_irradiance = 0.5 * M_PI;
  std::string envmap;                   // equirectangular EXR probe replacing the point light.
  double envmap_scale = 1.0;            // probe radiance scale, [0, 1e30].
  bool environment_background = false;  // camera rays that miss see the probe.
  RenderOptions render;                 // spp, bounces, seed, threads of the target renders.
  std::string effects = "all";          // enabled effects (Effects::Parse).
  // "flat" (face normals) or "smooth" (interpolated vertex normals); docs/cli.md, "Shading".
  std::string shading = "flat";
  bool overwrite = false;        // replace an existing, non-empty output directory.
  bool quiet = false;            // no progress line.
  bool ground = false;           // add a textured ground plane (rendered, not in gt/).
  GroundOptions ground_options;  // the plane's size and texture (src/io/synth_scene.h).
  std::string path = "sphere";   // camera path: "sphere" (Fibonacci) or "orbit".
  std::vector<double> elevation = {15.0, 40.0};  // orbit elevation range, degrees, [-89, 89].

  // Errors name the command-line flag and the value; NaN fails every range test. --spp,
  // --bounces and --threads are checked by RenderOptions::Check.
  bool Check(std::string* why) const {
    if (cameras < 1 || cameras > 10000) {
      return Fail(why, "--cameras: must be in [1, 10000], got " + std::to_string(cameras));
    }
    if (zooms.empty()) return Fail(why, "--zooms: needs at least one value");
    for (double z : zooms) {
      if (!(z > 0 && z <= 1000)) {
        return Fail(why, "--zooms: values must be in (0, 1000], got " + Text(z));
      }
    }
    if (res < 1 || res > 16384) {
      return Fail(why, "--res: must be in [1, 16384], got " + std::to_string(res));
    }
    if (!(fov_deg > 0 && fov_deg < 179)) {
      return Fail(why, "--fov: must be in (0, 179) degrees, got " + Text(fov_deg));
    }
    if (!(fill > 0 && fill <= 10)) {
      return Fail(why, "--fill: must be in (0, 10], got " + Text(fill));
    }
    if (up_axis != "y" && up_axis != "z") return Fail(why, "--up-axis: must be y or z");
    if (light_offset.size() != 3) return Fail(why, "--light-offset: needs 3 numbers x,y,z");
    for (double x : light_offset) {
      if (!std::isfinite(x)) {
        return Fail(why, "--light-offset: must be 3 finite numbers, got " + Text(x));
      }
    }
    if (light_intensity_given && !(light_intensity > 0 && light_intensity <= 1e30)) {
      return Fail(why,
                  "--light-intensity: must be in (0, 1e30] W/sr, got " + Text(light_intensity));
    }
    if (!(envmap_scale >= 0 && envmap_scale <= 1e30)) {
      return Fail(why, "--envmap-scale: must be in [0, 1e30], got " + Text(envmap_scale));
    }
    if (path != "sphere" && path != "orbit") return Fail(why, "--path: must be sphere or orbit");
    if (elevation.size() != 2 ||
        !(elevation[0] >= -89 && elevation[0] <= elevation[1] && elevation[1] <= 89)) {
      return Fail(why, "--elevation: needs lo,hi degrees with -89 <= lo <= hi <= 89");
    }
    if (ground && !ground_options.Check(why)) return false;
    if (!sun.empty()) {
      if (sun.size() != 3 || !std::isfinite(sun[0]) || !std::isfinite(sun[1]) ||
          !std::isfinite(sun[2]) || std::hypot(sun[0], sun[1], sun[2]) < 1e-12) {
        return Fail(why, "--sun: needs 3 finite numbers x,y,z, not all 0");
      }
      if (!envmap.empty()) return Fail(why, "--sun: give either --sun or --envmap, not both");
    }
    if (!(sun_irradiance > 0 && sun_irradiance <= 1e30)) {
      return Fail(why, "--sun-irradiance: must be in (0, 1e30] W/m², got " + Text(sun_irradiance));
    }
    if (environment_background && envmap.empty()) {
      return Fail(why, "--background-environment: needs --envmap");
    }
    return true;
  }

 private:
  static bool Fail(std::string* why, const std::string& message) {
    *why = message;
    return false;
  }
  static std::string Text(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%g", value);
    return buffer;
  }
};

// The output checks: OUT and OUT.partial are safe to write, OUT is empty unless --overwrite.
Status CheckSynthOutput(const SynthOptions& opts) {
  // --overwrite removes OUT: it must never hold the mesh, material or probe being read.
  const RunInputs inputs{{}, {opts.mesh, MaterialFile(opts.material), opts.envmap}};
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(opts.out, inputs, "--out"));
  SFT_RETURN_IF_ERROR(CheckOutputDirectory(opts.out + ".partial", inputs, "--out (OUT.partial)"));
  std::error_code ec;
  if (fs::exists(opts.out, ec) && !fs::is_empty(opts.out, ec) && !opts.overwrite) {
    return Status::Error(opts.out + ": output exists and is not empty (use --overwrite)");
  }
  return Status::Ok();
}

// The object: the mesh (z up, normalised unless --no-normalize) and its material.
Status LoadObject(const SynthOptions& opts, TriMesh* mesh, Material* material) {
  SFT_RETURN_IF_ERROR(ReadMesh(opts.mesh, mesh));
  if (opts.up_axis == "y") {
    for (auto vh : mesh->vertices()) {
      const auto p = mesh->point(vh);
      mesh->set_point(vh, TriMesh::Point(p[0], -p[2], p[1]));
    }
  }
  if (opts.normalize) {
    Eigen::Vector3d lo, hi;
    MeshBounds(*mesh, &lo, &hi);
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    const double diagonal = (hi - lo).norm();
    if (!(diagonal > 0)) return Status::Error(opts.mesh + ": mesh has zero extent");
    for (auto vh : mesh->vertices()) {
      const auto p = mesh->point(vh);
      mesh->set_point(vh,
                      TriMesh::Point((p[0] - centre.x()) / diagonal, (p[1] - centre.y()) / diagonal,
                                     (p[2] - centre.z()) / diagonal));
    }
  }
  return LoadMaterial(opts.material, *mesh, material);
}

// One pinhole camera per zoom, and the light: the camera-attached point light, a world-fixed
// sun (directional light), or the probe (copied to PARTIAL/probes/ as EXR).
Status AddCamerasAndLight(const SynthOptions& opts, double focal, double distance,
                          const std::string& partial, Dataset* dataset) {
  for (size_t z = 0; z < opts.zooms.size(); ++z) {
    Camera camera;
    camera.id = "zoom" + std::to_string(z);
    camera.model = CameraModel::kPinhole;
    camera.width = camera.height = opts.res;
    const double f = focal * opts.zooms[z];
    camera.params = {f, f, 0.5 * opts.res, 0.5 * opts.res};
    dataset->cameras.push_back(camera);
  }
  LightSpec light;
  if (!opts.sun.empty()) {
    light.id = "sun";
    light.type = LightType::kDirectional;
    light.frame = LightFrame::kWorld;
    light.direction = Eigen::Vector3d(opts.sun[0], opts.sun[1], opts.sun[2]).normalized();
    light.irradiance = Eigen::Vector3d::Constant(opts.sun_irradiance);
  } else if (opts.envmap.empty()) {
    light.id = "flash";
    light.type = LightType::kPoint;
    light.frame = LightFrame::kCamera;
    light.position =
        Eigen::Vector3d(opts.light_offset[0], opts.light_offset[1], opts.light_offset[2]);
    const double intensity =
        opts.light_intensity_given ? opts.light_intensity : 0.5 * M_PI * distance * distance;
    light.intensity = Eigen::Vector3d::Constant(intensity);
  } else {
    Image probe;
    SFT_RETURN_IF_ERROR(ReadImage(opts.envmap, &probe));
    const std::string probe_name = "probes/" + fs::path(opts.envmap).stem().string() + ".exr";
    SFT_RETURN_IF_ERROR(WriteExr(JoinPath(partial, probe_name), probe));
    light.id = "probe";
    light.type = LightType::kEnvironment;
    light.image = probe_name;
    light.scale = opts.envmap_scale;
    if (opts.environment_background) dataset->background = Background::kEnvironment;
  }
  dataset->lights.push_back(light);
  return Status::Ok();
}

// The views: per zoom, --cameras positions on the Fibonacci sphere or the orbit, looking at
// `target` with +z up. With --ground every camera must be above the plane at height `ground_z`.
Status AddViews(const SynthOptions& opts, const Eigen::Vector3d& target, double distance,
                double ground_z, Dataset* dataset) {
  const Eigen::Vector3d up(0, 0, 1);
  const std::vector<Eigen::Vector3d> orbit =
      OrbitPath(opts.cameras, target, distance, opts.elevation[0], opts.elevation[1]);
  int index = 0;
  for (size_t z = 0; z < opts.zooms.size(); ++z) {
    for (int k = 0; k < opts.cameras; ++k, ++index) {
      const Eigen::Vector3d centre =
          opts.path == "orbit"
              ? orbit[k]
              : Eigen::Vector3d(target + distance * FibonacciSphereDirection(k, opts.cameras));
      ViewSpec view;
      char name[32];
      std::snprintf(name, sizeof(name), "%03d", index);
      view.image = std::string("images/") + name + ".exr";
      view.mask = std::string("masks/") + name + ".png";
      view.camera_id = dataset->cameras[z].id;
      view.camera = static_cast<int>(z);
      view.light_ids = {dataset->lights[0].id};
      view.lights = {0};
      // Object-only masks assume the plane never hides the object: every camera above it.
      if (opts.ground && !(centre.z() > ground_z + 1e-6)) {
        return Status::Error("--ground: camera " + std::to_string(index) +
                             " is not above the ground plane (use --path orbit with a positive "
                             "--elevation range)");
      }
      view.cam_from_world = LookAt(centre, target, up);
      dataset->views.push_back(view);
    }
  }
  return Status::Ok();
}

// Renders every view to PARTIAL: the image (EXR) and the object's mask (PNG). With --ground the
// images show object + plane; masks come from a coverage pass of the object alone (the plane,
// below every camera, never hides the object: src/io/synth_scene.h).
Status RenderImages(const SynthOptions& opts, const RenderOptions& render, const TriMesh& mesh,
                    const Material& material, const Dataset& dataset, const std::string& partial) {
  DatasetViews views;
  SFT_RETURN_IF_ERROR(MakeDatasetViews(dataset, &views));
  TriMesh scene_mesh;
  Material scene_material;
  if (opts.ground) {
    SFT_RETURN_IF_ERROR(
        AddGroundPlane(mesh, material, opts.ground_options, &scene_mesh, &scene_material));
  }
  const RenderScene scene(opts.ground ? scene_mesh : mesh);
  std::unique_ptr<RenderScene> object_scene;
  if (opts.ground) object_scene = std::make_unique<RenderScene>(mesh);
  RenderOptions coverage = render;
  coverage.spp = std::min(render.spp, 16);
  coverage.bounces = 1;
  Progress progress("synth", static_cast<int64_t>(views.views.size()), !opts.quiet);
  for (size_t v = 0; v < views.views.size(); ++v) {
    Image image, object_image;
    RenderView(scene, opts.ground ? scene_material : material, views.views[v], render, &image);
    if (opts.ground) RenderView(*object_scene, material, views.views[v], coverage, &object_image);
    const Image& alpha = opts.ground ? object_image : image;
    Image mask(image.width, image.height, 1);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) mask.at(x, y) = alpha.at(x, y, 3) > 0.5f ? 1.f : 0.f;
    }
    SFT_RETURN_IF_ERROR(WriteExr(JoinPath(partial, dataset.views[v].image), image));
    SFT_RETURN_IF_ERROR(WritePng(JoinPath(partial, dataset.views[v].mask), mask, false));
    progress.Advance();
  }
  progress.Finish();
  return Status::Ok();
}

// The ground truth (gt/mesh.ply, gt/material.json), scene.json, and PARTIAL renamed to OUT.
Status FinishDataset(const SynthOptions& opts, const RenderOptions& render, const TriMesh& mesh,
                     const Material& material, Dataset* dataset, const std::string& partial) {
  SFT_RETURN_IF_ERROR(WriteMesh(JoinPath(partial, "gt/mesh.ply"), mesh));
  SFT_RETURN_IF_ERROR(SaveMaterial(JoinPath(partial, "gt/material.json"), material));
  dataset->gt_mesh = "gt/mesh.ply";
  dataset->ground_truth = {{"mesh", "gt/mesh.ply"},
                           {"material", "gt/material.json"},
                           {"renderer", "sft"},
                           {"samples", render.spp},
                           {"bounces", render.bounces},
                           {"seed", render.seed},
                           {"shading", ShadingName(render.shading)},
                           {"source_mesh", opts.mesh}};
  SFT_RETURN_IF_ERROR(WriteSceneJson(*dataset, partial));
  std::error_code ec;
  if (fs::exists(opts.out, ec)) fs::remove_all(opts.out, ec);
  fs::rename(partial, opts.out, ec);
  if (ec) {
    return Status::Error(opts.out + ": cannot move the finished dataset in place (" + ec.message() +
                         ")");
  }
  return Status::Ok();
}

Status RunSynth(const SynthOptions& opts) {
  std::string why;
  if (!opts.Check(&why)) return Status::Error(why);
  RenderOptions render = opts.render;
  if (!Effects::Parse(opts.effects, &render.effects, &why)) return Status::Error("--" + why);
  if (!ShadingFromName(opts.shading, &render.shading)) {
    return Status::Error("--shading: expected flat or smooth, got '" + opts.shading + "'");
  }
  if (!render.Check(&why)) return Status::Error("--" + why);
  SFT_RETURN_IF_ERROR(CheckSynthOutput(opts));

  TriMesh mesh;
  Material material;
  SFT_RETURN_IF_ERROR(LoadObject(opts, &mesh, &material));
  Eigen::Vector3d lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const Eigen::Vector3d target = 0.5 * (lo + hi);
  const double radius = 0.5 * (hi - lo).norm();
  const double focal = OrbitFocal(opts.res, opts.fov_deg);
  const double distance = OrbitDistance(radius, opts.fov_deg, opts.fill);

  const std::string partial = opts.out + ".partial";
  std::error_code ec;
  fs::remove_all(partial, ec);
  SFT_RETURN_IF_ERROR(MakeDirectories(partial));
  Dataset dataset;
  dataset.root = partial;
  SFT_RETURN_IF_ERROR(AddCamerasAndLight(opts, focal, distance, partial, &dataset));
  const Status views = AddViews(opts, target, distance, lo.z(), &dataset);
  if (!views.ok()) {
    fs::remove_all(partial, ec);
    return views;
  }
  if (opts.ground) {
    // The plane the object stands on, as importers record theirs: carving cuts the hull there.
    dataset.has_support_plane = true;
    dataset.support_normal = Eigen::Vector3d::UnitZ();
    dataset.support_point =
        Eigen::Vector3d(target.x(), target.y(), GroundHeight(lo, hi, opts.ground_options));
  }
  SFT_RETURN_IF_ERROR(RenderImages(opts, render, mesh, material, dataset, partial));
  return FinishDataset(opts, render, mesh, material, &dataset, partial);
}

}  // namespace

CommandRunner SetupSynthCommand(CLI::App* app) {
  auto opts = std::make_shared<SynthOptions>();
  opts->render.spp = 512;
  opts->render.bounces = 2;
  app->add_option("--mesh", opts->mesh, "Object mesh (OBJ, PLY, OFF)")->required();
  app->add_option("--out", opts->out, "Output dataset directory")->required();
  app->add_option("--material", opts->material, "Material JSON file or inline JSON");
  app->add_option("--cameras", opts->cameras, "Cameras on the Fibonacci sphere")
      ->capture_default_str();
  app->add_option("--zooms", opts->zooms, "Zoom levels (focal-length factors), comma-separated")
      ->delimiter(',')
      ->capture_default_str();
  app->add_option("--res", opts->res, "Image width and height in pixels")->capture_default_str();
  app->add_option("--fov", opts->fov_deg, "Field of view at zoom 1, degrees")
      ->capture_default_str();
  app->add_option("--fill", opts->fill,
                  "Bounding-sphere radius as a fraction of the half image at zoom 1")
      ->capture_default_str();
  app->add_option("--up-axis", opts->up_axis, "Mesh up axis: z (as is) or y (rotated to z)")
      ->capture_default_str();
  app->add_flag("!--no-normalize", opts->normalize,
                "Keep the mesh's coordinates (default: centre, bounding-box diagonal 1)");
  app->add_option("--light-offset", opts->light_offset,
                  "Point light position in the camera frame, x,y,z")
      ->delimiter(',')
      ->expected(3)
      ->capture_default_str();
  CLI::Option* light_intensity =
      app->add_option("--light-intensity", opts->light_intensity,
                      "Radiant intensity, W/sr (default: white facing patch at the centre = 0.5)");
  app->add_option("--sun", opts->sun,
                  "World-frame direction a sun's light travels, x,y,z (replaces the point light)")
      ->delimiter(',')
      ->expected(3);
  app->add_option("--sun-irradiance", opts->sun_irradiance,
                  "Sun irradiance on a facing surface, W/m^2 (default: white facing patch = 0.5)")
      ->capture_default_str();
  app->add_option("--envmap", opts->envmap,
                  "Equirectangular EXR probe to light the object instead of the point light");
  app->add_option("--envmap-scale", opts->envmap_scale, "Probe radiance scale")
      ->capture_default_str();
  app->add_flag("--background-environment", opts->environment_background,
                "Camera rays that miss see the probe (default: black background)");
  app->add_option("--spp", opts->render.spp, "Samples per pixel")->capture_default_str();
  app->add_option("--bounces", opts->render.bounces,
                  "Path segments: 1 = direct light only, 2 = one indirect bounce")
      ->capture_default_str();
  app->add_option("--effects", opts->effects, "Enabled effects (see sft render --help)")
      ->capture_default_str();
  app->add_option("--shading", opts->shading,
                  "flat (face normals) or smooth (interpolated vertex normals); recorded as "
                  "ground_truth.shading, which sft reconstruct follows")
      ->capture_default_str();
  app->add_option("--seed", opts->render.seed, "Sample seed")->capture_default_str();
  app->add_option("--threads", opts->render.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
  app->add_flag(
      "--ground", opts->ground,
      "Add a textured ground plane under the object (in the images, not in gt/ or masks)");
  app->add_option("--ground-size", opts->ground_options.half_size,
                  "Ground plane half side, in object bounding-box diagonals")
      ->capture_default_str();
  app->add_option("--ground-cells", opts->ground_options.cells, "Ground grid cells per side")
      ->capture_default_str();
  app->add_option("--ground-feature", opts->ground_options.feature,
                  "Finest ground-texture wavelength, in object diagonals")
      ->capture_default_str();
  app->add_option("--ground-floor", opts->ground_options.floor_half_size,
                  "Half side of a plain floor around the ground plane, in object diagonals (0 = "
                  "none); a floor many diagonals wide keeps the probe's light below the horizon "
                  "off the object");
  app->add_option(
         "--path", opts->path,
         "Camera path: sphere (Fibonacci sphere) or orbit (one turn, elevation oscillating "
         "twice between --elevation lo,hi; views in path order)")
      ->capture_default_str();
  app->add_option("--elevation", opts->elevation, "Orbit elevation range lo,hi in degrees")
      ->delimiter(',')
      ->expected(2)
      ->capture_default_str();
  app->add_flag("--overwrite", opts->overwrite, "Replace an existing output directory");
  app->add_flag("--quiet", opts->quiet, "No progress line");
  return [opts, light_intensity]() {
    opts->light_intensity_given = light_intensity->count() > 0;
    const Status status = RunSynth(*opts);
    return status.ok() ? 0 : PrintError("synth", status);
  };
}

}  // namespace sft
